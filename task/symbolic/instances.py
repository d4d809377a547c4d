"""Problem instances: a relational problem, its parsed PDDL (for validation), its optimum.

Two sources here: PDDL files (``from_files`` / ``from_text``) and the embedded example
(``example``). Benchmark suites built from these (PlanBench, seeded random problems) live in
`tamp.bench.suites`. Every instance keeps the parsed PDDL problem so plans are checked by
`task.symbolic.validate` against the PDDL itself, independently of the planner's crisp replay.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task import data
from task.domains import blocksworld
from task.errors import PDDLError
from task.problem import Problem
from task.symbolic import pddl_io


@dataclass(frozen=True)
class Instance:
    """One benchmark problem. ``optimal`` is the optimal 4-op plan length (None: unknown)."""

    name: str
    problem: Problem
    pddl: PDDLProblem
    optimal: int | None = None

    @property
    def blocks(self) -> int:
        return self.problem.n


def from_text(
    domain: Domain, text: str, source: str, name: str | None = None, optimal: int | None = None
) -> Instance:
    """Parse blocksworld problem text; errors name ``source``."""
    parsed = pddl_io.parse_problem(text, source, domain)
    try:
        problem = blocksworld.from_pddl(domain, parsed, pddl_io.object_order(text))
    except PDDLError as exc:
        raise PDDLError(f"{source}: {exc}") from None
    return Instance(name or problem.name, problem, parsed, optimal)


def from_files(domain_path: str | Path, problem_path: str | Path) -> tuple[Domain, Instance]:
    """Load a domain file and a problem file."""
    domain = pddl_io.load_domain(domain_path)
    return domain, from_text(domain, pddl_io.read_text(problem_path), str(problem_path))


def example() -> tuple[Domain, Instance]:
    """The embedded 5-block example (`task.data`) and its domain."""
    text = data.read_text(data.EXAMPLE_FILE)
    return data.domain(), from_text(data.domain(), text, data.source(data.EXAMPLE_FILE))
