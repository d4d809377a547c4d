"""A window's part of a big Blocksworld problem cut to what the window's moves can reach
(`unfinished` with ``depth``): checked state by state against the uncut part over every plan
of at most ``depth`` goal-or-table moves, and the STAY prior of such a part's rows."""

import math
from dataclasses import replace

import pytest
import torch

from task.config import PlannerConfig
from task.domains import get_domain
from task.domains.base import STAY_PRIOR, window_part
from task.domains.blocksworld import (
    PEDESTAL,
    apply_move,
    check_move,
    encode,
    in_position,
    is_goal,
    safe_moves,
    unfinished,
)
from task.optimize import initial_logits
from task.problem import TABLE, Move, PlanStatus, Problem
from task.symbolic.generate import random_problem


def _moves(problem: Problem, state) -> set[Move]:
    """The legal moves onto a block's goal block or the table (a part's moves)."""
    goal = dict(problem.goal)
    out = set()
    for x in problem.entities:
        for y in {goal.get(x, TABLE), TABLE}:
            if check_move(problem, state, Move(x, y)) is None:
                out.add(Move(x, y))
    return out


def _tall(seed: int) -> Problem:
    """A random 10-block problem from a state with towers of four or more blocks."""
    for k in range(200):
        p = random_problem(10, 1000 * seed + k)
        state = p.init
        for move in safe_moves(p, state):
            state = apply_move(p, state, move)
        heights = [sum(1 for _ in _below(p, state, top)) for top in _tops(p, state)]
        if not is_goal(p, state) and max(heights) >= 4:
            return replace(p, init=state)
    raise AssertionError("no tall problem")


def _tops(problem: Problem, state):
    return [x for x in problem.entities if x not in set(state)]


def _below(problem: Problem, state, x):
    while x != TABLE:
        yield x
        x = state[problem.entities.index(x)]


@pytest.mark.parametrize("depth", [1, 2, 3])
@pytest.mark.parametrize("seed", range(8))
def test_the_cut_part_reads_every_reachable_state_as_the_part_does(seed, depth):
    problem = _tall(seed)
    part, _ = unfinished(problem, problem.init)
    cut, near = unfinished(part, part.init, depth)
    assert cut.n == len(near) + sum(x.startswith("_") for x in cut.entities)
    kept = [part.entities[j] for j in near]
    assert tuple(cut.entities[: len(near)]) == tuple(kept)
    roots = {x for j, x in enumerate(kept) if cut.init[j] != part.init[near[j]]}
    frontier = [(part.init, cut.init)]
    for step in range(depth + 1):
        after = []
        for whole, mine in frontier:
            placed, cut_placed = in_position(part, whole), in_position(cut, mine)
            for j, x in enumerate(kept):
                assert (x in placed) == (x in cut_placed), (step, x)
                if x not in roots:
                    assert whole[near[j]] == mine[j], (step, x)
            assert is_goal(part, whole) == is_goal(cut, mine)
            if step < depth:  # the window's moves: the same
                legal = _moves(part, whole)
                assert legal == _moves(cut, mine), step
                for move in legal:
                    after.append((apply_move(part, whole, move), apply_move(cut, mine, move)))
        frontier = after


def test_a_tower_is_cut_below_the_blocks_a_window_can_reach():
    # one tower e on d on c on b on a on the table, goals a on e, b on a; depth 2: e and d
    # can move, c is the root (not in position: it stands on a pedestal), b and a are dropped;
    # f (free) on the table
    p = Problem(
        "t",
        "blocksworld",
        ("a", "b", "c", "d", "e", "f"),
        (TABLE, "a", "b", "c", "d", TABLE),
        (("a", "e"), ("b", "a"), ("d", "b"), ("e", "f")),
    )
    cut, near = unfinished(p, p.init, 2)
    pedestal = PEDESTAL.format(0)
    assert cut.entities == ("c", "d", "e", "f", pedestal) and near == (2, 3, 4, 5)
    assert cut.init == (pedestal, "c", "d", TABLE, TABLE)
    # d's goal block b is dropped: its goal becomes the pedestal, never met within 2 moves
    assert dict(cut.goal) == {"c": TABLE, "d": pedestal, "e": "f"}
    assert unfinished(p, p.init, 4)[0].n == p.n  # nothing below the reach: the part as is


def test_a_free_block_on_a_block_a_dropped_one_wants_must_go_to_the_table():
    # d (free) on c on b on a; a must stand on c. Depth 1: d moves, c is the root, a and b
    # are dropped; d is in position nowhere but the table (a comes onto c one day)
    p = Problem("t", "blocksworld", ("a", "b", "c", "d"), (TABLE, "a", "b", "c"), (("a", "c"),))
    cut, near = unfinished(p, p.init, 1)
    assert near == (2, 3) and dict(cut.goal)["d"] == TABLE
    assert "d" not in in_position(cut, cut.init) and "d" not in in_position(p, p.init)


def test_visited_states_a_window_cannot_reach_are_left_out():
    domain = get_domain("blocksworld")
    p = Problem(
        "t",
        "blocksworld",
        ("a", "b", "c", "d", "e"),
        (TABLE, "a", "b", "c", TABLE),
        (("a", "e"), ("e", "d")),
    )
    before = ("e", "a", "b", "c", TABLE)  # a stood on e: a is dropped at depth 1 now
    again = (TABLE, "a", "b", TABLE, "d")  # the same low blocks, d and e swapped up top
    part, state, seen = window_part(domain, p, p.init, {p.init, before, again}, 1)
    assert state == part.init and part.init in seen
    assert len(seen) == 2  # ``before`` moved a, which no window of 1 move does


def test_a_cut_part_starts_its_windows_staying_more():
    problem = random_problem(12, 3)
    part, _ = unfinished(problem, problem.init)
    batch = encode([part], [part.init]).repeat(4)
    assert torch.allclose(batch.static[STAY_PRIOR], torch.full((4,), math.log(part.n)))
    config = PlannerConfig(init_noise=0.5)
    logits = initial_logits(batch, 3, config, torch.Generator().manual_seed(0))
    offset = logits[..., -1].mean() - logits[..., :-1].mean()
    assert offset.item() == pytest.approx(config.tau * math.log(part.n), abs=0.1)
    assert STAY_PRIOR not in encode([problem], [problem.init]).static  # a whole problem: none


def test_the_planner_solves_tall_towers_through_cut_windows():
    from task.planner import plan
    from task.symbolic.search import optimal_moves

    problem = random_problem(12, 171)  # after its safe moves, a tower too tall for a window
    state = problem.init
    for move in safe_moves(problem, state):
        state = apply_move(problem, state, move)
    assert unfinished(problem, state, 5)[0].n < unfinished(problem, state)[0].n
    config = PlannerConfig.for_domain(
        "blocksworld", safe_from=1, restarts=8, iters=30, max_windows=40, improve_s=0.0
    )
    result = plan(problem, config, seed=0)
    assert result.status is PlanStatus.SOLVED
    state = problem.init
    for move in result.plan.moves:
        assert check_move(problem, state, move) is None
        state = apply_move(problem, state, move)
    assert is_goal(problem, state)
    assert len(result.plan) <= len(optimal_moves(problem)) + 2


def test_the_windows_over_a_part_have_their_own_settings():
    from task.errors import TampError

    config = PlannerConfig.for_domain("blocksworld")
    parts = config.for_parts()
    assert dict(config.part_window) == {"horizon": 5, "lookahead": 8, "restarts": 8, "iters": 20}
    assert (parts.horizon, parts.lookahead, parts.restarts, parts.iters) == (5, 8, 8, 20)
    assert parts.part_window == () and parts.time_limit_s == config.time_limit_s
    # an option the user gives holds in those windows too
    given = PlannerConfig.for_domain("blocksworld", horizon=4, iters=50)
    assert (given.for_parts().horizon, given.for_parts().iters) == (4, 50)
    assert given.for_parts().restarts == 8
    with pytest.raises(TampError, match="part_window: unknown setting 'tau_end'"):
        PlannerConfig(part_window=(("tau_end", 0.1),))
    with pytest.raises(TampError, match="horizon must be >= 1, got 0"):
        PlannerConfig(part_window=(("horizon", 0),))


def test_a_big_problem_plans_its_windows_with_the_part_settings(monkeypatch):
    import task.planner.windows as windows
    from task.planner import plan_batch

    seen = []
    window = windows.run_window

    def spy(context, starts, *args):
        config = context.config
        seen.append((tuple(s.problem.n for s in starts), config.horizon, config.iters))
        return window(context, starts, *args)

    monkeypatch.setattr(windows, "run_window", spy)
    small, big = random_problem(5, 2), random_problem(12, 171)
    config = PlannerConfig.for_domain(
        "blocksworld", safe_from=10, improve_s=0.0, part_window=(("horizon", 4), ("iters", 7))
    )
    results = plan_batch([small, big], replace(config, restarts=4, max_windows=30))
    assert all(r.status is PlanStatus.SOLVED for r in results)
    settings = {(h, i) for _, h, i in seen}
    assert (4, 7) in settings and (config.horizon, config.iters) in settings
    assert all(len(sizes) == 1 for sizes, _, _ in seen)  # one window per settings
