"""Blocksworld's safe moves: every constructive move starts some shortest plan (checked by A*
on small problems with full, partial and table goals), and the planner takes them without a
window from `PlannerConfig.safe_from` blocks, with plans as short as the windows' alone."""

from dataclasses import replace

import pytest
import torch

from task.config import PlannerConfig
from task.domains import blocksworld
from task.domains.blocksworld import (
    GOAL_OR_TABLE,
    apply_move,
    check_move,
    constructive_moves,
    encode,
    in_position,
    is_goal,
    safe_moves,
    unfinished,
)
from task.problem import TABLE, Move, PlanStatus, Problem
from task.symbolic.generate import random_problem
from task.symbolic.search import optimal_moves


def _optimum(problem: Problem, state) -> int:
    found = optimal_moves(replace(problem, init=tuple(state)))
    assert found is not None
    return len(found)


def _problems():
    for seed in range(12):
        yield random_problem(5, seed)
        yield random_problem(6, 100 + seed, n_goal_atoms=2)
        full = random_problem(5, 200 + seed)
        # the table named by the goal: every block the goal leaves free goes to the table
        named = {x for x, _ in full.goal}
        table = tuple((x, TABLE) for x in full.entities if x not in named)
        yield replace(full, goal=full.goal + table)


def test_in_position_follows_the_definition():
    p = Problem("t", "blocksworld", ("a", "b", "c", "d"), ("b", TABLE, "d", TABLE), (("a", "b"),))
    # a on b (its goal) on the table: both placed; c (free) on d (free, unwanted): placed
    assert in_position(p, p.init) == {"a", "b", "c", "d"}
    wanted = replace(p, goal=(("a", "b"), ("b", "d")))
    # b must stand on d: b is not placed, nor a on it; c must leave d (d is wanted)
    assert in_position(wanted, wanted.init) == {"d"}


@pytest.mark.parametrize("problem", list(_problems()), ids=lambda p: p.name)
def test_every_constructive_move_starts_a_shortest_plan(problem):
    state, checked = tuple(problem.init), 0
    while not is_goal(problem, state):
        moves = constructive_moves(problem, state)
        if not moves:
            break
        best = _optimum(problem, state)
        for move in moves:
            assert _optimum(problem, apply_move(problem, state, move)) == best - 1, move
            checked += 1
        state = apply_move(problem, state, moves[0])
    assert checked or not constructive_moves(problem, problem.init)


def test_finished_towers_leave_the_problem():
    # a on b on the table is finished (b wants a, a wants nothing); c must go onto d, which
    # is in position but still waits for c: d stays, and so does e (free) resting on c
    p = Problem(
        "t",
        "blocksworld",
        ("a", "b", "c", "d", "e"),
        ("b", TABLE, TABLE, TABLE, "c"),
        (("a", "b"), ("c", "d")),
    )
    rest, keep = unfinished(p, p.init)
    assert rest.entities == ("c", "d", "e") and keep == (2, 3, 4)
    assert rest.init == (TABLE, TABLE, "c") and rest.goal == (("c", "d"),)
    again, kept = unfinished(rest, rest.init)  # nothing more is finished
    assert again.entities == rest.entities and kept == (0, 1, 2)
    assert again.data == GOAL_OR_TABLE  # its windows move blocks onto goal blocks or the table
    # a segment in position keeps only its top, standing on the table: f on g on h (all
    # in position), i must come onto f; g and h leave, f stays with the table as its goal
    tower = Problem(
        "u",
        "blocksworld",
        ("f", "g", "h", "i"),
        ("g", "h", TABLE, TABLE),
        (("f", "g"), ("g", "h"), ("i", "f")),
    )
    rest, keep = unfinished(tower, tower.init)
    assert rest.entities == ("f", "i") and keep == (0, 3)
    assert rest.init == (TABLE, TABLE) and rest.goal == (("f", TABLE), ("i", "f"))


@pytest.mark.parametrize("problem", list(_problems())[:18], ids=lambda p: p.name)
def test_the_unfinished_part_has_the_same_optimum(problem):
    state = tuple(problem.init)
    for move in safe_moves(problem, state)[:3]:  # a few towers finished along the way
        state = apply_move(problem, state, move)
        part = unfinished(problem, state)
        if part is None or is_goal(problem, state):
            continue
        rest, keep = part
        assert set(rest.init) <= {*rest.entities, TABLE} and len(keep) == rest.n
        assert _optimum(rest, rest.init) == _optimum(problem, state)


def test_no_safe_moves_on_a_slotted_table():
    from task.domains.blocksworld import with_slots

    p = with_slots(random_problem(5, 3), ("s0", "s1", "s2", "s3", "s4"))
    assert constructive_moves(p, p.init) == []
    assert unfinished(p, p.init) is None


def test_a_free_block_off_its_place_goes_to_the_table():
    p = Problem("t", "blocksworld", ("a", "b", "c"), ("b", "c", TABLE), (("c", "a"),))
    # c must go onto a: b (free) must leave c, a must leave b; a goes first (only clear block)
    assert safe_moves(p, p.init) == (Move("a", TABLE), Move("b", TABLE), Move("c", "a"))


def test_the_planner_takes_them_without_windows():
    problem = random_problem(8, 7)
    on = PlannerConfig.for_domain(
        "blocksworld", safe_from=1, improve_s=0.0, max_windows=60, restarts=8, iters=30
    )
    off = replace(on, safe_from=None)
    from task.planner import plan

    with_safe, without = plan(problem, on, seed=0), plan(problem, off, seed=0)
    assert with_safe.status is PlanStatus.SOLVED
    state = problem.init
    for move in with_safe.plan.moves:
        state = apply_move(problem, state, move)
    assert is_goal(problem, state)
    assert with_safe.stats["safe_moves"] > 0
    assert with_safe.stats["windows"] <= without.stats["windows"]
    assert "safe_moves" not in without.stats


def test_safe_from_is_checked():
    from task.errors import TampError

    with pytest.raises(TampError, match="safe_from must be >= 1"):
        PlannerConfig(safe_from=0)


def _goal_or_table_optimum(problem: Problem) -> int:
    """Breadth-first search over moves onto a block's goal block or the table only."""
    goal = dict(problem.goal)
    frontier, seen, depth = [tuple(problem.init)], {tuple(problem.init)}, 0
    while frontier:
        if any(is_goal(problem, s) for s in frontier):
            return depth
        step = []
        for state in frontier:
            for x in problem.entities:
                for y in {goal.get(x, TABLE), TABLE}:
                    if check_move(problem, state, Move(x, y)) is None:
                        nxt = apply_move(problem, state, Move(x, y))
                        if nxt not in seen:
                            seen.add(nxt)
                            step.append(nxt)
        frontier, depth = step, depth + 1
    raise AssertionError("no plan of goal-or-table moves")


@pytest.mark.parametrize("problem", list(_problems())[:18], ids=lambda p: p.name)
def test_moves_onto_the_goal_block_or_the_table_keep_a_shortest_plan(problem):
    assert _goal_or_table_optimum(problem) == _optimum(problem, problem.init)


def test_the_window_part_narrows_its_moves_to_goal_block_or_table():
    problem = random_problem(6, 5)
    part, _ = unfinished(problem, problem.init)
    whole, narrow = encode([problem], [problem.init]), encode([part], [part.init])
    goal = dict(part.goal)
    n = narrow.n
    for x, name in enumerate(part.entities):
        allowed = {n} | (
            {part.entities.index(goal[name])} if goal.get(name, TABLE) != TABLE else set()
        )
        moves = set(torch.nonzero(narrow.action_mask[0, x, :-1]).flatten().tolist())
        assert moves <= allowed and n in moves
    assert whole.action_mask.sum() > narrow.action_mask.sum()


SLOTS = ("s0", "s1", "s2", "s3", "s4", "s5")


@pytest.mark.parametrize("seed", range(6))
def test_helpful_moves_are_legal_and_only_onto_the_goal_block_or_the_table(seed):
    """`blocksworld.helpful` (the greedy fallback's preferred moves): legal, each a block not in
    position onto its in-position goal block or the table (a slot on a slotted table), and
    every constructive move among them."""
    slotted = blocksworld.with_slots(random_problem(5, seed), SLOTS)
    for problem in (random_problem(7, seed), slotted):
        state = blocksworld.initial_state(problem)
        placed, goal = blocksworld.in_position(problem, state), dict(problem.goal)
        helpful = blocksworld.helpful(problem, state)
        assert helpful <= set(blocksworld.legal_moves(problem, state))
        table = set(problem.fixed) if blocksworld.slotted(problem) else {TABLE}
        for move in helpful:
            assert move.entity not in placed
            assert move.target in table or (
                move.target == goal.get(move.entity) and move.target in placed
            )
        every = {  # every legal move of that kind is among them
            m
            for m in blocksworld.legal_moves(problem, state)
            if m.entity not in placed
            and (m.target in table or (m.target == goal.get(m.entity) and m.target in placed))
        }
        assert helpful == every
        if not blocksworld.slotted(problem):
            assert set(blocksworld.constructive_moves(problem, state)) <= helpful
