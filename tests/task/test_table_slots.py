"""Table slots as the paper's K base slots: capacity one, goals on any slot, moves name slots."""

from __future__ import annotations

import pytest

from task.config import PlannerConfig
from task.domains import blocksworld as bw
from task.errors import ProblemError
from task.planner import plan_batch
from task.problem import TABLE, Action, Move, Problem
from task.symbolic.generate import random_problem

SLOTS = ("s0", "s1", "s2")


def _problem() -> Problem:
    # a on b (b on the table), c on the table; goal: b on c, a on the table
    plain = Problem(
        "p", "blocksworld", ("a", "b", "c"), ("b", TABLE, TABLE), (("b", "c"), ("a", TABLE))
    )
    return bw.with_slots(plain, SLOTS)


def test_with_slots_puts_each_tower_on_its_own_slot():
    p = _problem()
    assert p.init == ("b", "s0", "s1") and p.fixed == SLOTS and bw.slotted(p)
    assert not bw.slotted(random_problem(3, 0))
    bases = bw.with_slots(
        p.__class__(**{**p.__dict__, "fixed": (TABLE,), "init": ("b", TABLE, TABLE)}),
        SLOTS,
        {"b": "s2", "c": "s0"},
    )
    assert bases.init == ("b", "s2", "s0")


@pytest.mark.parametrize(
    "slots, bases, words",
    [
        (("s0",), None, "2 towers need"),
        (("s0", "a"), None, "must be distinct, new"),
        (("s0", "s0"), None, "must be distinct"),
        (SLOTS, {"b": "s0", "c": "s0"}, "own slots"),
        (SLOTS, {"b": "s9", "c": "s0"}, "own slots"),
    ],
)
def test_with_slots_rejects_too_few_or_bad_slots(slots, bases, words):
    plain = Problem("p", "blocksworld", ("a", "b", "c"), ("b", TABLE, TABLE), ())
    with pytest.raises(ProblemError, match=words):
        bw.with_slots(plain, slots, bases)


def test_a_slot_holds_one_block_and_a_table_goal_means_any_slot():
    p = _problem()
    state = bw.initial_state(p)
    assert bw.check_move(p, state, Move("a", "s1")) == "target s1 is not clear (c is on it)"
    assert bw.check_move(p, state, Move("a", "s2")) is None
    with pytest.raises(ProblemError, match="unknown block 'table'"):  # the table is its slots
        bw.check_move(p, state, Move("a", TABLE))
    state = bw.apply_move(p, state, Move("a", "s2"))
    assert bw.unsatisfied_goals(p, state) == (("b", "c"),)  # a on s2 is "a on the table"
    state = bw.apply_move(p, state, Move("b", "c"))
    assert bw.is_goal(p, state) and bw.is_clear(p, state, "s0")
    legal = [Move("a", "b"), Move("b", "a"), Move("b", "s0")]  # a on s2 stays off s0
    assert bw.legal_moves(p, state) == legal
    assert bw.check_move(p, state, Move("a", "s0")) == "a is already on the table"


def test_slot_moves_are_4op_put_downs_and_pick_ups():
    p = _problem()
    moves = (Move("a", "s2"), Move("b", "c"), Move("a", "b"), Move("a", "s0"))
    assert bw.moves_to_actions(p, moves) == (
        Action("unstack", ("a", "b")),
        Action("put-down", ("a",)),
        Action("pick-up", ("b",)),
        Action("stack", ("b", "c")),
        Action("pick-up", ("a",)),
        Action("stack", ("a", "b")),
        Action("unstack", ("a", "b")),
        Action("put-down", ("a",)),
    )
    assert "(ontable b)" in bw.to_pddl(p) and "s0" not in bw.to_pddl(p)
    assert ("ontable", "c") in bw.to_atoms(p, bw.initial_state(p))
    with pytest.raises(ProblemError, match="give moves, not actions"):
        bw.actions_to_moves(p, (Action("pick-up", ("c",)), Action("put-down", ("c",))))


def _towers(problem: Problem, states) -> int:
    return max(sum(s in problem.fixed for s in state) for state in states)


def _states(problem: Problem, moves):
    state, out = bw.initial_state(problem), []
    out.append(state)
    for move in moves:
        state = bw.apply_move(problem, state, move)
        out.append(state)
    return out


def test_the_planner_keeps_within_the_slots_an_unlimited_plan_exceeds():
    """Random 7-block problems on max(init towers, goal towers) + 1 slots: every plan is
    found, uses at most that many table places and names the slots; the same problems planned
    on an unlimited table need more places at least once (so the slots bind)."""
    plain = [random_problem(7, seed) for seed in (3, 4, 5)]
    slotted = []
    for p in plain:
        goal_towers = sum(1 for x in p.entities if (x, TABLE) in p.goal)
        k = max(sum(s == TABLE for s in p.init), goal_towers) + 1
        slotted.append(bw.with_slots(p, tuple(f"slot{j}" for j in range(k))))
    config = PlannerConfig()
    free = plan_batch(plain, config, seed=0)
    tight = plan_batch(slotted, config, seed=0)
    exceeded = 0
    for p, s, r_free, r_tight in zip(plain, slotted, free, tight, strict=True):
        assert r_tight.solved, (p.name, r_tight.stats)
        assert _towers(s, _states(s, r_tight.plan.moves)) <= len(s.fixed)
        assert all(m.target != TABLE for m in r_tight.plan.moves)
        assert r_free.solved
        exceeded += _towers(p, _states(p, r_free.plan.moves)) > len(s.fixed)
        assert len(r_tight.plan) <= 2 * len(r_free.plan) + 2
    assert exceeded >= 1


def test_the_lower_bound_counts_a_block_off_its_goal_slot_and_not_one_on_any_slot():
    """A goal naming one slot (the geometric planner's region cells) needs a move while the
    block stands on another, and one of any other block standing on that slot; a goal of the
    table is met on any other slot."""
    from dataclasses import replace

    from task.symbolic.search import moves_lower_bound

    p = _problem()  # init: a on b, b on s0, c on s1
    assert moves_lower_bound(p, p.init) == 2  # b must move (onto c), so a must move off it
    cell = replace(p, goal=(("c", "s2"), ("a", TABLE)))  # c wants s2, a anywhere on the table
    assert moves_lower_bound(cell, cell.init) == 2  # c is on s1; a is on b, not on a slot
    moved = bw.apply_move(cell, cell.init, Move("a", "s2"))
    # a on s2 meets its table goal, but c's goal names s2: a must leave it, c must get there
    assert moves_lower_bound(cell, moved) == 2
    there = replace(cell, goal=(("c", "s1"), ("a", TABLE)))  # c already on its slot
    assert moves_lower_bound(there, moved) == 0
