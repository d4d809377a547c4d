"""Test helper: judge a planner's moves with the crisp PDDL validator, not the decoder's checks.

The problem goes out as PDDL text (`task.domains.blocksworld.to_pddl`), is parsed back against the
embedded 4-operator domain, and the moves become 4-op actions through the domain's ``to_actions``
(``strict=False``: an illegal move is translated as it stands, not refused by the domain's own
``check_move``); `task.symbolic.validate` then simulates those actions over the STRIPS semantics
and is the only judge of legality and of the goal.
"""

from __future__ import annotations

from collections.abc import Sequence

from task import data
from task.domains import blocksworld, get_domain
from task.problem import Move, Problem
from task.symbolic import pddl_io, validate


def validate_moves(problem: Problem, moves: Sequence[Move]) -> validate.Validation:
    """The PDDL validator's verdict on ``moves`` from the problem's initial state."""
    domain = data.domain()
    pddl_problem = pddl_io.parse_problem(blocksworld.to_pddl(problem), domain=domain)
    actions = get_domain(problem.domain).to_actions(problem, moves, strict=False)
    return validate.validate(domain, pddl_problem, actions)


def assert_valid(problem: Problem, moves: Sequence[Move]) -> validate.Validation:
    """Assert the PDDL validator accepts ``moves`` as a goal-reaching plan; return its verdict."""
    verdict = validate_moves(problem, moves)
    assert verdict.valid, f"{problem.name}: {verdict.reason} ({[str(m) for m in moves]})"
    assert verdict.length == 2 * len(moves)
    return verdict
