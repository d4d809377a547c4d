"""Test helper: judge a planner's moves with the crisp PDDL validator, not the decoder's checks.

The problem goes out as PDDL text (`task.domains.blocksworld.to_pddl`), is parsed back against the
embedded 4-operator domain, and the moves are replayed by `tamp.bench.planning.replay` (the
benchmarks' own check: an illegal move is translated as it stands, not refused by the domain's
``check_move``); `task.symbolic.validate` is the only judge of legality and of the goal.
"""

from __future__ import annotations

from collections.abc import Sequence

from tamp.bench.planning import replay
from task import data
from task.domains import blocksworld
from task.instances import from_text
from task.problem import Move, Problem
from task.symbolic import validate


def validate_moves(problem: Problem, moves: Sequence[Move]) -> validate.Validation:
    """The PDDL validator's verdict on ``moves`` from the problem's initial state."""
    domain = data.domain()
    instance = from_text(domain, blocksworld.to_pddl(problem), problem.name)
    return replay(domain, instance, moves)


def assert_valid(problem: Problem, moves: Sequence[Move]) -> validate.Validation:
    """Assert the PDDL validator accepts ``moves`` as a goal-reaching plan; return its verdict."""
    verdict = validate_moves(problem, moves)
    assert verdict.valid, f"{problem.name}: {verdict.reason} ({[str(m) for m in moves]})"
    assert verdict.length == 2 * len(moves)
    return verdict
