"""Plain data that crosses package boundaries: problems, moves, plans and planner results.

No tensors here. A problem is relational: N movable *entities* (blocks) each rest on one
*support* drawn from the targets = entities + fixed targets (K=1: the table). Other domains
read the same fields their own way (their file says how) and keep what they need beyond them
(static facts, a grounding) in ``data``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from task.errors import ProblemError, one_of

TABLE = "table"


@dataclass(frozen=True)
class Move:
    """The relational action ``move(entity -> target)``."""

    entity: str
    target: str

    def __str__(self) -> str:
        return f"move({self.entity} -> {self.target})"


@dataclass(frozen=True)
class Action:
    """A ground PDDL action, e.g. ``Action("unstack", ("a", "b"))`` -> ``(unstack a b)``."""

    name: str
    args: tuple[str, ...] = ()

    def __str__(self) -> str:
        return "(" + " ".join((self.name, *self.args)) + ")"


@dataclass(frozen=True)
class Problem:
    """A relational planning problem.

    ``init`` gives the support of every entity, in ``entities`` order; ``goal`` is a partial
    conjunction of ``(entity, support)`` atoms (``support == "table"`` means on the table).
    """

    name: str
    domain: str
    entities: tuple[str, ...]
    init: tuple[str, ...]
    goal: tuple[tuple[str, str], ...]
    fixed: tuple[str, ...] = (TABLE,)
    data: object = field(default=None, compare=False, repr=False)  # domain-owned, crisp
    # the user's PDDL names when the domain matched a hand-written one up to renaming
    # (`task.domains.match.Renaming`; None: the domain's own names)
    renaming: object = field(default=None, compare=False, repr=False)

    @property
    def targets(self) -> tuple[str, ...]:
        """The Y = N + K support targets: entities first, then the fixed targets."""
        return self.entities + self.fixed

    @property
    def n(self) -> int:
        return len(self.entities)

    def index(self, name: str) -> int:
        """Column of ``name`` among the targets; raises ProblemError naming the valid ones."""
        try:
            return self.targets.index(name)
        except ValueError:
            raise ProblemError(f"unknown block {one_of(name, self.targets)}") from None


class PlanStatus(enum.Enum):
    SOLVED = "solved"
    NO_PLAN = "no_plan"  # the window budget ran out before the goal was reached
    UNSOLVABLE = "unsolvable"  # the fallback search exhausted every state reachable with the
    # moves allowed: no plan exists within these choices (``stats["fallback"]`` says how many)
    INVALID = "invalid"  # a planned move is illegal in the true state (perceived protocol or
    # no crisp check; the plan ends with that move, ``stats["illegal"]`` says why)


@dataclass(frozen=True)
class Plan:
    """A sequence of relational moves (no tensors)."""

    moves: tuple[Move, ...] = ()

    def __len__(self) -> int:
        return len(self.moves)

    def __iter__(self):
        return iter(self.moves)


@dataclass(frozen=True)
class PlanResult:
    """What the planner returns for one problem."""

    status: PlanStatus
    plan: Plan
    problem: Problem
    validation: object | None = None  # task.symbolic.validate.Validation of the 4-op plan
    stats: dict = field(default_factory=dict)

    @property
    def solved(self) -> bool:
        return self.status is PlanStatus.SOLVED
