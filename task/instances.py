"""Problem instances: a domain's problem, its parsed PDDL (for validation), its known lengths.

Two sources here: PDDL files (``from_files`` / ``from_text``) and the embedded example
(``example``). The domain whose rules plan a problem is recognised from the PDDL domain
(`task.domains.recognise`: a hand-written domain file, else the generic STRIPS lift) or forced
with ``rules``. Benchmark suites built from these (PlanBench, IPC folders, seeded random
problems) live in `tamp.bench.suites`. Every instance keeps the parsed PDDL problem so plans
are checked by `task.symbolic.validate` against the PDDL itself, independently of the
planner's crisp replay.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task import data
from task.domains import GENERIC, get_domain, names, recognise
from task.errors import PDDLError, ProblemError, one_of
from task.problem import Problem
from task.symbolic import pddl_io


@dataclass(frozen=True)
class Instance:
    """One benchmark problem. ``optimal``: the optimal plan length in PDDL actions (None:
    unknown); ``reference``: the length of a reference plan that need not be optimal."""

    name: str
    problem: Problem
    pddl: PDDLProblem
    optimal: int | None = None
    reference: int | None = None

    @property
    def size(self) -> int:
        """The problem's size in its domain's units (blocks, packages, boxes, atoms)."""
        return get_domain(self.problem.domain).size(self.problem)

    @property
    def blocks(self) -> int:
        """Entities of a relational problem (blocks, for Blocksworld)."""
        return self.problem.n


def rules_for(domain: Domain, rules: str | None = None) -> str:
    """The domain rules that plan ``domain``'s problems: ``rules`` if given (checked: a
    hand-written domain must match the PDDL domain), else the recognised ones."""
    if rules is None:
        return recognise(domain)
    if rules not in names():
        raise ProblemError(f"--domain-rules: unknown domain rules {one_of(rules, names())}")
    if rules != GENERIC and not get_domain(rules).matches(domain):
        actions = ", ".join(sorted(str(a.name).lower() for a in domain.actions))
        match = re.search(r"\(\s*domain\s+([^\s()]+)", get_domain(rules).pddl_domain_text(), re.I)
        wanted = f" {match.group(1).lower()!r}" if match else ""
        raise PDDLError(
            f"domain {str(domain.name)!r} (actions {actions}) is not the {rules} domain"
            f"{wanted}; use --domain-rules {GENERIC} to plan it with the generic STRIPS lift"
        )
    return rules


def from_text(
    domain: Domain,
    text: str,
    source: str,
    name: str | None = None,
    optimal: int | None = None,
    rules: str | None = None,
    reference: int | None = None,
) -> Instance:
    """Parse problem text of ``domain``; errors name ``source``. ``rules``: see `rules_for`."""
    parsed = pddl_io.parse_problem(text, source, domain)
    chosen = get_domain(rules_for(domain, rules))
    try:
        problem = chosen.from_pddl(domain, parsed, pddl_io.object_order(text))
    except (PDDLError, ProblemError) as exc:
        raise type(exc)(f"{source}: {exc}") from None
    return Instance(name or problem.name, problem, parsed, optimal, reference)


def from_files(
    domain_path: str | Path, problem_path: str | Path, rules: str | None = None
) -> tuple[Domain, Instance]:
    """Load a domain file and a problem file (``rules``: see `rules_for`)."""
    domain = pddl_io.load_domain(domain_path)
    text = pddl_io.read_text(problem_path)
    return domain, from_text(domain, text, str(problem_path), rules=rules)


def example() -> tuple[Domain, Instance]:
    """The embedded 5-block example (`task.data`) and its domain."""
    text = data.read_text(data.EXAMPLE_FILE)
    return data.domain(), from_text(data.domain(), text, data.source(data.EXAMPLE_FILE))
