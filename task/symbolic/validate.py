"""Crisp plan validation over the generic STRIPS semantics (a VAL-like validator).

A plan is valid when every action is applicable in turn and the final state satisfies the goal.
The result is a value (`Validation`), not an exception; misuse (an unknown action or object,
a wrong arity) still raises `ProblemError` before anything is simulated.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.problem import Action
from task.symbolic import pddl_io, strips


class ValidationStatus(enum.Enum):
    VALID = "valid"
    INEXECUTABLE = "inexecutable"  # some action's precondition fails
    NON_GOAL_REACHING = "non_goal_reaching"  # every action applies but the goal does not hold


@dataclass(frozen=True)
class Validation:
    """The outcome of validating one plan.

    ``step`` is the 1-based index of the first inapplicable action (None otherwise);
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


def validate(domain: Domain, problem: PDDLProblem, actions: Iterable[Action]) -> Validation:
    """Simulate ``actions`` from the initial state and check the goal at the end."""
    plan = tuple(actions)
    grounded = [strips.ground(domain, problem, a) for a in plan]
    goal = strips.goal_atoms(problem)
    state = strips.initial_state(problem)
    for step, (action, ga) in enumerate(zip(plan, grounded, strict=True), start=1):
        unmet = strips.unmet(state, ga)
        if unmet:
            noun = "precondition" if len(unmet) == 1 else "preconditions"
            verb = "does" if len(unmet) == 1 else "do"
            return Validation(
                ValidationStatus.INEXECUTABLE,
                step,
                f"step {step} {str(action).lower()}: {noun} {', '.join(unmet)} {verb} not hold",
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
    return Validation(
        ValidationStatus.VALID, None, f"valid plan of {len(plan)} actions", (), len(plan)
    )


def validate_files(
    domain_path: str | Path, problem_path: str | Path, plan_path: str | Path
) -> Validation:
    """`validate` a plan file against a domain and a problem file."""
    domain = pddl_io.load_domain(domain_path)
    problem = pddl_io.load_problem(problem_path, domain)
    return validate(domain, problem, pddl_io.read_plan(plan_path))
