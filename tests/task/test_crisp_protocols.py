"""The two crisp protocols of planning from beliefs (true / perceived) and the planner without
its crisp check: what the returned plans look like to the PDDL validator."""

from __future__ import annotations

from dataclasses import replace

import pytest
import torch

from tamp.camera.states import complete_goal
from task import data
from task.config import PlannerConfig
from task.decode import DecodeRule, WindowStart, decode_best, decode_row
from task.domains.blocksworld import DOMAIN as BW
from task.domains.blocksworld_pddl import to_pddl
from task.errors import TampError
from task.instances import from_text
from task.planner import plan, plan_batch
from task.problem import TABLE, Move, PlanStatus, Problem
from task.symbolic.generate import random_problem
from task.symbolic.validate import ValidationStatus, validate

# truth: b sits on a; goal: a on c. Read as "every block on the table", move(a -> c) looks legal
# and reaches the goal in one move; in the world a is covered, so it is illegal.
PROBLEM = Problem("misread", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"),))
MISREAD = (TABLE, TABLE, TABLE)
CONFIG = PlannerConfig(iters=30, restarts=4, max_windows=2)


def _onehot(state) -> torch.Tensor:
    cols = [*PROBLEM.entities, TABLE]
    F = torch.zeros(PROBLEM.n, PROBLEM.n + 1)
    for x, s in enumerate(state):
        F[x, cols.index(s)] = 1.0
    return F


class _Beliefs:
    """One window's beliefs: F0 read as ``seen``; ``crisp`` None keeps the paper's protocol."""

    lr = 0.1

    def __init__(self, seen, crisp: bool) -> None:
        self.F0, self.goal = _onehot(seen)[None], _onehot(("c", TABLE, TABLE))[None]
        self.crisp_states = [seen] if crisp else None

    def compute(self):
        return self.F0, self.goal, torch.zeros(1)

    def parameters(self):
        return []


def _validate(moves):
    """The 4-op translation of ``moves`` (illegal ones as they stand), replayed from the PDDL."""
    inst = from_text(data.domain(), to_pddl(PROBLEM), "misread")
    assert inst.problem == PROBLEM
    return validate(data.domain(), inst.pddl, BW.to_actions(PROBLEM, moves, strict=False))


def test_perceived_protocol_returns_the_inexecutable_move_and_validate_names_it():
    result = plan(PROBLEM, CONFIG, seed=0, beliefs=lambda i, s: _Beliefs(MISREAD, crisp=True))
    assert result.status is PlanStatus.INVALID
    assert result.plan.moves == (Move("a", "c"),)  # decoded against the misread state
    assert "a is not clear" in result.stats["illegal"]
    assert result.stats["misread_windows"] == 1 and result.stats["windows"] == 1
    check = _validate(result.plan.moves)
    assert check.status is ValidationStatus.INEXECUTABLE and check.step == 1
    assert check.failed == ("(clear a)",)


def test_true_protocol_with_the_same_misread_decodes_only_legal_moves():
    result = plan(PROBLEM, CONFIG, seed=0, beliefs=lambda i, s: _Beliefs(MISREAD, crisp=False))
    assert result.status is PlanStatus.NO_PLAN and "illegal" not in result.stats
    assert result.stats["misread_windows"] == 0  # decoded against the true state
    assert _validate(result.plan.moves).status is not ValidationStatus.INEXECUTABLE


def test_perceived_protocol_with_a_right_reading_plans_like_the_true_one():
    def right(i, states):
        return _Beliefs(states[0], crisp=True)  # reads the world exactly

    result = plan(PROBLEM, PlannerConfig(iters=30, restarts=4), seed=0, beliefs=right)
    assert result.solved and result.stats["misread_windows"] == 0
    assert _validate(result.plan.moves).valid


class _Reader:
    """Beliefs that read every state right: soft F0 and goal one-hot, crisp states optional."""

    def __init__(self, problems, crisp: bool) -> None:
        self.problems, self.crisp, self.calls = problems, crisp, 0

    def __call__(self, indices, states):
        self.calls += 1
        ps = [self.problems[i] for i in indices]
        window = _Beliefs(MISREAD, self.crisp)
        window.F0 = BW.encode(ps, states, torch.float32).F0
        window.goal = BW.encode(ps, [complete_goal(p) for p in ps], torch.float32).F0
        window.crisp_states = list(states) if self.crisp else None
        return window


def test_a_perfect_reading_gives_exactly_the_true_protocols_plans():
    problems = [random_problem(4, s) for s in range(4)]
    problems = [
        replace(p, goal=tuple(zip(p.entities, complete_goal(p), strict=True))) for p in problems
    ]
    config = PlannerConfig(iters=30, restarts=4)
    true = plan_batch(problems, config, seed=1, beliefs=_Reader(problems, crisp=False))
    reader = _Reader(problems, crisp=True)
    perceived = plan_batch(problems, config, seed=1, beliefs=reader)
    assert [r.plan for r in perceived] == [r.plan for r in true]
    assert [r.status for r in perceived] == [r.status for r in true] == [PlanStatus.SOLVED] * 4
    assert [r.stats["windows"] for r in perceived] == [r.stats["windows"] for r in true]
    assert reader.calls > max(r.stats["windows"] for r in true)  # the confirming looks


def test_perceived_goal_test_is_on_the_perceived_state():
    # the image already shows the goal (c under a): the robot stops with nothing done
    seen = ("c", TABLE, TABLE)
    result = plan(PROBLEM, CONFIG, seed=0, beliefs=lambda i, s: _Beliefs(seen, crisp=True))
    assert result.solved and result.plan.moves == ()
    assert _validate(()).status is ValidationStatus.NON_GOAL_REACHING


def test_beliefs_with_the_wrong_number_of_crisp_states_are_refused():
    class Two(_Beliefs):
        def __init__(self) -> None:
            super().__init__(MISREAD, crisp=True)
            self.crisp_states = [MISREAD, MISREAD]

    with pytest.raises(TampError, match="2 crisp states for 1 problems"):
        plan(PROBLEM, CONFIG, beliefs=lambda i, s: Two())


def test_without_the_crisp_check_the_strongest_illegal_move_is_kept():
    # the true protocol, soft beliefs that make move(a -> c) the strongest gate
    config = replace(CONFIG, crisp_check=False)
    result = plan(PROBLEM, config, seed=0, beliefs=lambda i, s: _Beliefs(MISREAD, crisp=False))
    assert result.status is PlanStatus.INVALID and result.plan.moves[-1] == Move("a", "c")
    check = _validate(result.plan.moves)
    assert check.status is ValidationStatus.INEXECUTABLE and check.step == 2 * len(result.plan) - 1
    # with the check (the default) the same window decodes nothing illegal
    kept = plan(PROBLEM, CONFIG, seed=0, beliefs=lambda i, s: _Beliefs(MISREAD, crisp=False))
    assert Move("a", "c") not in kept.plan.moves


def test_decode_row_keeps_the_illegal_move_only_without_the_check():
    state = BW.initial_state(PROBLEM)  # b on a
    gates = torch.zeros(2, 3, 4)  # (T, N, Y)
    gates[0, 0, 2] = 0.9  # a -> c: illegal, a is covered
    gates[1, 1, 3] = 0.9  # b -> table: legal, but after it
    checked = decode_row(BW, WindowStart(PROBLEM, state), gates, 0.0, DecodeRule(0.3))
    assert checked.moves == () and checked.illegal is None
    kept = decode_row(BW, WindowStart(PROBLEM, state), gates, 0.0, DecodeRule(0.3, check=False))
    assert kept.moves == (Move("a", "c"),) and not kept.complete
    assert kept.illegal == "a is not clear (b is on it)"


def test_without_the_check_restarts_are_ranked_by_the_soft_objective_alone():
    state = BW.initial_state(PROBLEM)
    gates = torch.zeros(2, 2, 3, 4)  # (R, T, N, Y): restart 0 legal, restart 1 illegal
    gates[0, 0, 1, 3] = 0.9  # b -> table
    gates[0, 1, 0, 2] = 0.9  # a -> c: the goal
    gates[1, 0, 0, 2] = 0.9  # a -> c at once: illegal
    losses = torch.tensor([1.0, 0.5])
    best = decode_best(BW, [WindowStart(PROBLEM, state)], gates, losses, DecodeRule(0.3, 2))[0]
    assert best.reached and len(best.moves) == 2
    raw = decode_best(
        BW, [WindowStart(PROBLEM, state)], gates, losses, DecodeRule(0.3, 2, check=False)
    )[0]
    assert raw.moves == (Move("a", "c"),) and raw.illegal is not None


def test_strict_translation_still_refuses_an_illegal_move():
    from task.errors import ProblemError

    with pytest.raises(ProblemError, match="illegal"):
        BW.to_actions(PROBLEM, (Move("a", "c"),))
    actions = BW.to_actions(PROBLEM, (Move("a", "c"),), strict=False)
    assert [str(a) for a in actions] == ["(pick-up a)", "(stack a c)"]
