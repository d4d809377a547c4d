"""The lift's complete fallback and plan shortening: helpful actions, the lazy greedy search
(`task.symbolic.lazy_search.lazy_greedy`), cycle cutting and action elimination
(`task.symbolic.shorten`), and the lift planning through them by default."""

from __future__ import annotations

import pytest

from task.config import PlannerConfig
from task.domains import get_domain
from task.domains.strips import gripper_problem, problem_from_text
from task.errors import TampError
from task.planner import plan
from task.problem import Action, Move
from task.symbolic import relaxed
from task.symbolic.generate import random_problem
from task.symbolic.lazy_search import SearchStatus, lazy_greedy
from task.symbolic.search import optimal_moves
from task.symbolic.shorten import cut_cycles, eliminate, shorten
from task.symbolic.validate import validate

LIFT = get_domain("strips")
BW = get_domain("blocksworld")
# one unit of fuel, two goal atoms that each burn it: the relaxation reaches both, no plan does
FUEL = """(define (domain fuel) (:requirements :strips)
  (:predicates (fuel) (q ?x))
  (:action burn :parameters (?x) :precondition (fuel) :effect (and (q ?x) (not (fuel)))))"""
FUEL_PROBLEM = """(define (problem fuel2) (:domain fuel) (:objects o1 o2)
  (:init (fuel)) (:goal (and (q o1) (q o2))))"""


def _valid(problem, moves) -> None:
    check = validate(problem.data.pddl_domain, problem.data.pddl_problem, list(moves))
    assert check.valid, check.reason


def test_helpful_actions_apply_and_belong_to_the_relaxed_plan():
    for seed in range(3):
        problem = gripper_problem(4, seed)
        state = LIFT.initial_state(problem)
        chosen = {problem.data.actions[j] for j in relaxed.relaxed_plan(problem.data, state)}
        helpful = LIFT.helpful(problem, state)
        assert helpful, "a solvable non-goal state has a helpful action"
        assert helpful <= chosen
        assert helpful <= set(LIFT.legal_moves(problem, state))
        assert len(chosen) == LIFT.estimate(problem, state)


@pytest.mark.parametrize("n_balls", [3, 12, 30])
def test_greedy_solves_gripper_far_beyond_the_windows(n_balls):
    problem = gripper_problem(n_balls, 0)
    found = lazy_greedy(LIFT, problem, LIFT.initial_state(problem))
    assert found.status is SearchStatus.SOLVED
    _valid(problem, found.moves)


def test_greedy_says_unsolvable_when_the_relaxation_cannot():
    problem = problem_from_text(FUEL, FUEL_PROBLEM, "fuel")
    assert LIFT.estimate(problem, LIFT.initial_state(problem)) == 2  # relaxed: solvable
    found = lazy_greedy(LIFT, problem, LIFT.initial_state(problem))
    assert found.status is SearchStatus.UNSOLVABLE
    assert found.moves == ()


def test_greedy_stops_at_its_budget():
    problem = gripper_problem(6, 1)
    found = lazy_greedy(LIFT, problem, LIFT.initial_state(problem), max_nodes=1)
    assert found.status is SearchStatus.BUDGET
    assert "budget" in found.reason


def test_greedy_plans_around_moves_ruled_out():
    """Every pick with the left gripper is ruled out: the plan uses the right one only."""
    problem = gripper_problem(4, 2)

    def no_left(state, move) -> bool:
        return not (move.name == "pick" and move.args[-1] == "left")

    found = lazy_greedy(LIFT, problem, LIFT.initial_state(problem), no_left)
    assert found.status is SearchStatus.SOLVED and found.ruled_out > 0
    assert all(no_left(None, m) for m in found.moves)
    _valid(problem, found.moves)


def test_greedy_works_over_a_hand_written_domain_too():
    """Any domain with an estimate: Sokoban's (hand-written) is enough."""
    sokoban = get_domain("sokoban")
    problem = next(iter(sokoban.samples(0)))
    found = lazy_greedy(sokoban, problem, sokoban.initial_state(problem))
    assert found.status is SearchStatus.SOLVED
    assert sokoban.is_goal(problem, _replay(sokoban, problem, found.moves))


def _replay(domain, problem, moves):
    state = domain.initial_state(problem)
    for move in moves:
        state = domain.apply_move(problem, state, move)
    return state


def test_shorten_cuts_a_cycle_and_a_redundant_pair():
    problem = random_problem(4, 0)
    best = list(optimal_moves(problem))
    first = best[0]
    back = Move(first.entity, BW.initial_state(problem)[problem.entities.index(first.entity)])
    detour = [first, back, *best]  # a move and its undoing: a cycle
    assert cut_cycles(BW, problem, detour) == tuple(best)
    assert eliminate(BW, problem, detour) == tuple(best)
    assert shorten(BW, problem, best) == tuple(best)  # nothing to take out of a shortest plan


def test_elimination_drops_a_pick_and_drop_that_serve_nothing():
    problem = gripper_problem(3, 0)
    found = lazy_greedy(LIFT, problem, LIFT.initial_state(problem))
    state = LIFT.initial_state(problem)
    room = next(a[1] for a in state if a[0] == "at-robby")
    ball = next(a[1] for a in state if a[0] == "at" and a[2] == room)
    idle = [Action("pick", (ball, room, "left")), Action("drop", (ball, room, "left"))]
    padded = [*idle, *found.moves]
    _valid(problem, padded)
    short = shorten(LIFT, problem, padded)
    assert len(short) <= len(found.moves)
    _valid(problem, short)


def test_the_lift_falls_back_and_shortens_by_default():
    """One cheap window cannot move 10 balls; the lift's defaults search on from there."""
    problem = gripper_problem(10, 0)
    config = PlannerConfig.for_domain("strips", restarts=2, iters=5, max_windows=1)
    result = plan(problem, config, seed=0)
    assert result.solved
    assert result.stats["fallback"]["status"] == "solved"
    _valid(problem, LIFT.to_actions(problem, result.plan.moves))


def test_unknown_fallback_search_lists_the_options():
    with pytest.raises(TampError, match="astar") as info:
        PlannerConfig(fallback_search="dfs")
    assert "greedy" in str(info.value) and "\n" not in str(info.value)


def test_under_a_time_limit_the_windows_leave_the_search_its_share():
    """Windows slow enough to spend any limit on 30 balls: with the lift's share (half) the
    greedy search still gets the other half and solves it; a share outside (0, 1] is refused."""
    problem = gripper_problem(30, 0)
    slow = PlannerConfig.for_domain("strips", restarts=2, iters=2000, time_limit_s=6.0)
    assert slow.window_share == 0.5
    result = plan(problem, slow, seed=0)
    assert result.solved, result.stats
    assert result.stats["fallback"]["trigger"] == "time_limit"
    _valid(problem, LIFT.to_actions(problem, result.plan.moves))
    with pytest.raises(TampError, match="window_share") as info:
        PlannerConfig(window_share=0.0)
    assert "\n" not in str(info.value)
