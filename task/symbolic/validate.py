"""Crisp plan validation over the generic STRIPS semantics (a VAL-like validator).

A plan is valid when every action is applicable in turn and the final state satisfies the goal.
The result is a value (`Validation`), not an exception; misuse (an unknown action or object,
a wrong arity) still raises `ProblemError` before anything is simulated, naming the plan file
and line when the plan came from a file.

A plan may also be relational blocksworld moves (``move(a -> b)``, what ``tamp run --plan``
takes): each move is checked as the 4-op actions it stands for in the state it is applied in
(`move_actions`), and ``step`` then counts moves.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.errors import PDDLError, ProblemError, one_of
from task.problem import TABLE, Action, Move
from task.symbolic import pddl_io, strips
from task.symbolic.pddl_io import PlanLine

FOUR_OPS = ("pick-up", "put-down", "stack", "unstack")  # what a move is made of


class ValidationStatus(enum.Enum):
    VALID = "valid"
    INEXECUTABLE = "inexecutable"  # some action's precondition fails
    NON_GOAL_REACHING = "non_goal_reaching"  # every action applies but the goal does not hold


@dataclass(frozen=True)
class Validation:
    """The outcome of validating one plan.

    ``step`` is the 1-based index of the first inapplicable action or move (None otherwise);
    ``failed`` holds the unmet precondition atoms or the unreached goal atoms, e.g. ``"(on a b)"``.
    """

    status: ValidationStatus
    step: int | None
    reason: str
    failed: tuple[str, ...]
    length: int

    @property
    def valid(self) -> bool:
        return self.status is ValidationStatus.VALID


def move_actions(move: Move, state: strips.State) -> tuple[Action, Action]:
    """The 4-op actions ``move(x -> y)`` stands for in ``state``: ``(unstack x s)`` when
    ``(on x s)`` holds, else ``(pick-up x)``; then ``(put-down x)`` onto the table, else
    ``(stack x y)`` (the pairing `task.domains.blocksworld.moves_to_actions` writes)."""
    x, y = move.entity, move.target
    below = sorted(atom[2] for atom in state if atom[0] == "on" and atom[1] == x)
    pick = Action("unstack", (x, below[0])) if below else Action("pick-up", (x,))
    put = Action("put-down", (x,)) if y == TABLE else Action("stack", (x, y))
    return pick, put


def _check(domain: Domain, problem: PDDLProblem, step: Action | Move) -> None:
    """ProblemError (before anything is simulated) for an unknown action, object or arity; a
    move needs the 4-op blocksworld actions and known blocks."""
    if isinstance(step, Action):
        strips.ground(domain, problem, step)
        return
    names = {str(a.name).lower() for a in domain.actions}
    if not set(FOUR_OPS) <= names:
        raise ProblemError(
            f"{step}: a blocksworld move needs the 4-op actions ({', '.join(FOUR_OPS)}); "
            f"domain {domain.name} has {', '.join(sorted(names))}"
        )
    blocks = strips.objects(domain, problem)
    for name in (step.entity, step.target):
        if name != TABLE and name not in blocks:
            raise ProblemError(f"{step}: unknown block {one_of(name, (*blocks, TABLE))}")
    strips.ground(domain, problem, Action("pick-up", (step.entity,)))
    if step.target != TABLE:
        strips.ground(domain, problem, Action("stack", (step.entity, step.target)))


def _refuse_derived(domain: Domain) -> None:
    """PDDLError when ``domain`` declares derived predicates: the validator has no axioms, so
    a goal or precondition over one would be judged as if it never held."""
    if domain.derived_predicates:
        first = sorted(str(d.predicate) for d in domain.derived_predicates)[0]
        raise PDDLError(
            f"domain {domain.name}: derived predicate {first} is not supported "
            "(validate checks STRIPS actions without axioms)"
        )


def validate(domain: Domain, problem: PDDLProblem, plan: Iterable[Action | Move]) -> Validation:
    """Simulate ``plan`` (actions, or blocksworld moves) from the initial state and check the
    goal at the end; a domain with derived predicates is refused (PDDLError)."""
    _refuse_derived(domain)
    steps = tuple(plan)
    for step in steps:
        _check(domain, problem, step)
    return _simulate(domain, problem, steps)


def validate_lines(
    domain: Domain, problem: PDDLProblem, lines: Iterable[PlanLine], source: str = "<plan>"
) -> Validation:
    """`validate` the entries of a plan file; misuse names ``source`` and the line."""
    _refuse_derived(domain)
    entries = tuple(lines)
    for entry in entries:
        try:
            _check(domain, problem, entry.step)
        except ProblemError as exc:
            raise ProblemError(f"{source}: line {entry.lineno}: {exc}") from None
    return _simulate(domain, problem, tuple(e.step for e in entries))


def _simulate(domain: Domain, problem: PDDLProblem, plan: tuple[Action | Move, ...]) -> Validation:
    goal = strips.goal_atoms(problem)
    state = strips.initial_state(problem)
    for step, entry in enumerate(plan, start=1):
        actions = move_actions(entry, state) if isinstance(entry, Move) else (entry,)
        for action in actions:
            ga = strips.ground(domain, problem, action)
            unmet = strips.unmet(state, ga)
            if unmet:
                noun = "precondition" if len(unmet) == 1 else "preconditions"
                verb = "does" if len(unmet) == 1 else "do"
                what = str(action).lower()
                if isinstance(entry, Move):
                    what = f"{entry} as {what}"
                return Validation(
                    ValidationStatus.INEXECUTABLE,
                    step,
                    f"step {step} {what}: {noun} {', '.join(unmet)} {verb} not hold",
                    unmet,
                    len(plan),
                )
            state = strips.apply(state, ga)
    missing = tuple(strips.atom_str(a) for a in goal if a not in state)
    if missing:
        return Validation(
            ValidationStatus.NON_GOAL_REACHING,
            None,
            f"goal atoms not reached: {', '.join(missing)}",
            missing,
            len(plan),
        )
    kind = "moves" if plan and isinstance(plan[0], Move) else "actions"
    return Validation(
        ValidationStatus.VALID, None, f"valid plan of {len(plan)} {kind}", (), len(plan)
    )


def validate_files(
    domain_path: str | Path, problem_path: str | Path, plan_path: str | Path
) -> Validation:
    """`validate` a plan file (actions or moves, `pddl_io.parse_plan_lines`) against a domain
    and a problem file; misuse names the plan file and line."""
    domain = pddl_io.load_domain(domain_path)
    problem = pddl_io.load_problem(problem_path, domain)
    return validate_lines(domain, problem, pddl_io.read_plan_lines(plan_path), str(plan_path))
