"""The anytime improvement (`PlannerConfig.improve_s`, `task.symbolic.lazy_search.improve`):
A* bounded by the plan in hand finds a shortest plan, never returns a longer or invalid one, and
off leaves the plans as they were."""

from __future__ import annotations

from dataclasses import replace

import pytest

from task.config import PlannerConfig
from task.domains import get_domain
from task.errors import TampError
from task.planner import plan, plan_batch
from task.problem import Move
from task.symbolic.generate import random_problem
from task.symbolic.lazy_search import SearchStatus, improve, lazy_best_first
from task.symbolic.search import optimal_moves
from tests.pddl_check import assert_valid

BW = get_domain("blocksworld")
CHEAP = PlannerConfig(restarts=2, iters=15, max_windows=10)  # quick and often not shortest
ON = replace(CHEAP, improve_s=30.0)


def detour(problem) -> tuple[Move, ...]:
    """A valid plan two moves longer than the optimum: the first clear block is moved away
    and back before the optimal plan."""
    state = BW.initial_state(problem)
    first = BW.legal_moves(problem, state)[0]
    back = Move(first.entity, state[problem.index(first.entity)])
    return (first, back, *optimal_moves(problem))


@pytest.mark.parametrize("seed", range(4))
def test_the_improvement_finds_the_optimum_below_a_longer_plan(seed):
    problem = random_problem(6, seed)
    longer = detour(problem)
    assert_valid(problem, longer)
    better, stats = improve(BW, problem, longer, ON.improve_nodes, ON.improve_s)
    assert len(better) == len(optimal_moves(problem)) == len(longer) - 2
    assert_valid(problem, better)
    assert stats["improved_from"] == len(longer) and stats["moves"] == len(better)
    assert stats["proved_optimal"] and stats["status"] == "solved"


def test_an_optimal_plan_is_kept_and_proved_so():
    """A plan as short as the optimum: nothing shorter exists (the search exhausts, or the
    bound at the start already equals the length), so the plan is kept and called optimal."""
    for seed in range(4):
        problem = random_problem(6, seed)
        best = optimal_moves(problem)
        kept, stats = improve(BW, problem, best, ON.improve_nodes, ON.improve_s)
        assert kept == best and stats["improved_from"] is None
        assert stats["proved_optimal"] and stats["status"] in ("unsolvable", "bound")


def test_out_of_budget_the_plan_is_unchanged_and_not_called_optimal():
    problem = random_problem(8, 3)
    longer = detour(problem)
    kept, stats = improve(BW, problem, longer, 1, ON.improve_s)
    assert kept == longer and stats["status"] == "budget"
    assert not stats["proved_optimal"] and stats["improved_from"] is None
    kept, stats = improve(
        BW, problem, longer, ON.improve_nodes, ON.improve_s, deadline=0.0
    )  # a time limit long past
    assert kept == longer and stats["status"] == "budget"


@pytest.mark.parametrize("n", [4, 5, 6])
def test_the_bounded_search_finds_only_shorter_plans(n):
    for seed in range(3):
        problem = random_problem(n, seed)
        start, best = BW.initial_state(problem), len(optimal_moves(problem))
        found = lazy_best_first(BW, problem, start, below=best + 1)
        assert found.status is SearchStatus.SOLVED and len(found.moves) == best
        none = lazy_best_first(BW, problem, start, below=best)
        assert none.status is SearchStatus.UNSOLVABLE and f"fewer than {best}" in none.reason


def test_on_never_longer_nor_invalid_and_off_unchanged():
    """The same problems and seed with the improvement off and on: the windows plan alike,
    so the plan off is the plan the improvement started from; on is never longer, always
    valid, optimal where it says so, and shorter on some of these problems."""
    problems = [random_problem(n, seed) for n in (6, 7) for seed in range(3)]
    off = plan_batch(problems, CHEAP, seed=1)
    on = plan_batch(problems, ON, seed=1)
    shorter = 0
    for problem, a, b in zip(problems, off, on, strict=True):
        assert a.solved and b.solved
        assert "improve" not in a.stats
        assert_valid(problem, b.plan.moves)
        stats = b.stats["improve"]
        assert stats["improved_from"] in (None, len(a.plan))
        if stats["improved_from"] is None:
            assert b.plan == a.plan
        assert len(b.plan) <= len(a.plan)
        if stats["proved_optimal"]:
            assert len(b.plan) == len(optimal_moves(problem))
        shorter += len(b.plan) < len(a.plan)
    assert shorter > 0  # the cheap windows left something to improve


def test_off_by_default_and_bad_settings_refused():
    problem = random_problem(5, 0)
    assert "improve" not in plan(problem, CHEAP).stats
    with pytest.raises(TampError, match="improve_up_to"):
        PlannerConfig(improve_up_to=0)
    with pytest.raises(TampError, match="improve_s"):
        PlannerConfig(improve_s=-1.0)
    with pytest.raises(TampError, match="improve_nodes"):
        PlannerConfig(improve_nodes=0)


def test_blocksworld_improves_its_plans_up_to_its_size_cap():
    """On by the domain's defaults (`PlannerConfig.for_domain`) up to ``improve_up_to`` blocks:
    a 6-block plan is handed to the improvement, a bigger one is not."""
    blocks = replace(PlannerConfig.for_domain("blocksworld"), restarts=2, iters=15, max_windows=10)
    problem = random_problem(6, 1)
    done = plan(problem, blocks)
    assert done.solved and done.stats["improve"]["proved_optimal"]
    assert len(done.plan.moves) == len(optimal_moves(problem))
    capped = plan(problem, replace(blocks, improve_up_to=5))
    assert "improve" not in capped.stats


def test_the_improve_option_lifts_the_domain_s_size_cap():
    """``--improve`` takes effect at any size: the domain's cap belongs to its default."""
    from tamp.cli import build_parser
    from tamp.cli.options import planner_config

    parser = build_parser()
    default = planner_config(parser.parse_args(["plan", "d.pddl", "p.pddl"]), "blocksworld")
    assert (default.improve_s, default.improve_up_to) == (30.0, 15)
    given = planner_config(parser.parse_args(["plan", "d", "p", "--improve", "5"]), "blocksworld")
    assert (given.improve_s, given.improve_up_to) == (5.0, None)
