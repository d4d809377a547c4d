"""Problem instances: a domain's problem, its parsed PDDL (for validation), its known lengths.

Two sources here: PDDL files (``from_files`` / ``from_text``) and the embedded example
(``example``). The domain whose rules plan a problem is recognised from the PDDL domain by its
structure (`task.domains.match.match_domain`: a hand-written domain up to renaming, else the
generic STRIPS lift) or forced with ``rules``. A renamed domain's problem is read through the
renaming (`task.domains.match.to_reference`) and carries it (``Problem.renaming``), so plans
and atoms come back in the user's names; a near miss is planned by the lift and the instance's
``note`` says why. Benchmark suites built from these (PlanBench, IPC folders, seeded random
problems) live in `tamp.bench.suites`. Every instance keeps the parsed PDDL problem so plans
are checked by `task.symbolic.validate` against the PDDL itself, independently of the
planner's crisp replay.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task import data
from task.deadline import NO_DEADLINE, Deadline
from task.domains import GENERIC, get_domain, names
from task.domains.match import Match, NearMiss, Renaming, match_domain, to_reference
from task.errors import PDDLError, ProblemError, one_of
from task.problem import Problem
from task.symbolic import pddl_io


@dataclass(frozen=True)
class Instance:
    """One benchmark problem. ``optimal``: the optimal plan length in PDDL actions (None:
    unknown); ``reference``: the length of a reference plan that need not be optimal;
    ``note``: one line on how the domain was recognised when it is worth saying (a near miss
    of a hand-written domain, planned by the generic lift instead)."""

    name: str
    problem: Problem
    pddl: PDDLProblem
    optimal: int | None = None
    reference: int | None = None
    note: str | None = None

    @property
    def size(self) -> int:
        """The problem's size in its domain's units (blocks, packages, boxes, atoms)."""
        return get_domain(self.problem.domain).size(self.problem)

    @property
    def blocks(self) -> int:
        """Entities of a relational problem (blocks, for Blocksworld)."""
        return self.problem.n


@dataclass(frozen=True)
class Rules:
    """The domain rules that plan a PDDL domain's problems: registered domain ``name``, the
    ``renaming`` from its PDDL names to the user's (None: its own names), and ``note``, why a
    near miss of a hand-written domain goes to the generic lift (None otherwise)."""

    name: str
    renaming: Renaming | None = None
    note: str | None = None


def _wrong_rules(domain: Domain, rules: str, why: str) -> PDDLError:
    actions = ", ".join(sorted(str(a.name).lower() for a in domain.actions))
    match = re.search(r"\(\s*domain\s+([^\s()]+)", get_domain(rules).pddl_domain_text(), re.I)
    wanted = f" {match.group(1).lower()!r}" if match else ""
    return PDDLError(
        f"domain {str(domain.name)!r} (actions {actions}) is not the {rules} domain"
        f"{wanted}{why}; use --domain-rules {GENERIC} to plan it with the generic STRIPS lift"
    )


def choose_rules(domain: Domain, rules: str | None = None) -> Rules:
    """The `Rules` of ``domain``: ``rules`` if given (checked: a hand-written domain must match
    the PDDL domain up to renaming), else the hand-written domain it matches, else the lift."""
    if rules is not None and rules not in names():
        raise ProblemError(f"--domain-rules: unknown domain rules {one_of(rules, names())}")
    if rules == GENERIC:
        return Rules(GENERIC)
    found = match_domain(domain, None if rules is None else (rules,))
    if isinstance(found, Match):
        return Rules(found.rules, None if found.renaming.identity else found.renaming)
    if rules is not None:
        why = f" ({found.reason})" if isinstance(found, NearMiss) else ""
        raise _wrong_rules(domain, rules, why)
    if isinstance(found, NearMiss):
        return Rules(GENERIC, note=f"{found.reason}: planned with the generic STRIPS lift")
    return Rules(GENERIC)


def rules_for(domain: Domain, rules: str | None = None) -> str:
    """The name of the domain rules that plan ``domain``'s problems (`choose_rules`)."""
    return choose_rules(domain, rules).name


def from_text(
    domain: Domain,
    text: str,
    source: str,
    name: str | None = None,
    optimal: int | None = None,
    rules: str | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> Instance:
    """Parse problem text of ``domain``; errors name ``source``. ``rules``: see `choose_rules`.
    (A reference plan's length, `Instance.reference`, is the suite's to add.)
    ``deadline``: a command's; the generic lift's grounding stops at it (`TimeLimitReached`)."""
    parsed = pddl_io.parse_problem(text, source, domain)
    chosen = choose_rules(domain, rules)
    order = pddl_io.object_order(text)
    try:
        if chosen.renaming is None:
            problem = get_domain(chosen.name).from_pddl(domain, parsed, order, deadline)
        else:
            found = Match(chosen.name, chosen.renaming)
            ref_domain, ref_problem, ref_order = to_reference(found, domain, parsed, order)
            problem = get_domain(chosen.name).from_pddl(
                ref_domain, ref_problem, ref_order, deadline
            )
            problem = replace(problem, renaming=chosen.renaming)
    except (PDDLError, ProblemError) as exc:
        said = str(exc) if chosen.renaming is None else chosen.renaming.speak(str(exc))
        raise type(exc)(f"{source}: {said}") from None
    return Instance(name or problem.name, problem, parsed, optimal, note=chosen.note)


def from_files(
    domain_path: str | Path,
    problem_path: str | Path,
    rules: str | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> tuple[Domain, Instance]:
    """Load a domain file and a problem file (``rules``: see `rules_for`; ``deadline``: see
    `from_text`)."""
    domain = pddl_io.load_domain(domain_path)
    text = pddl_io.read_text(problem_path)
    return domain, from_text(domain, text, str(problem_path), rules=rules, deadline=deadline)


def example() -> tuple[Domain, Instance]:
    """The embedded 5-block example (`task.data`) and its domain."""
    text = data.read_text(data.EXAMPLE_FILE)
    return data.domain(), from_text(data.domain(), text, data.source(data.EXAMPLE_FILE))
