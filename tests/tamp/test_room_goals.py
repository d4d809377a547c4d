"""A goal tower's base moved to where the whole tower has room (`tamp.slots.room_goals`): on
the ``shelf`` scene a slot under the board takes towers of five, so a goal tower of six on a
base standing there must start elsewhere, and the planner is told so."""

from __future__ import annotations

import dataclasses
import itertools

import pytest

from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.arm.arm import Arm
from tamp.obstacles import with_scene
from tamp.scene import SceneConfig, layout
from tamp.slots import plan_on_places, room_goals, slotted
from task.config import PlannerConfig
from task.domains import blocksworld as bw
from task.problem import TABLE, Problem

SHELF = with_scene(SceneConfig(), "shelf")
NAMES = tuple("abcdef")
SIX = Problem("six", "blocksworld", NAMES, (TABLE,) * 6, tuple(itertools.pairwise(NAMES)))


def _room(problem: Problem, scene: SceneConfig, slots: list[int]) -> dict[str, str]:
    poses = layout(problem.entities, problem.init, scene, seed=0, slots=slots)
    current, at = slotted(problem, problem.init, poses, scene)
    return room_goals(current, at, scene)


def test_the_shelf_slots_take_five_and_the_others_seven():
    room = [SHELF.capacity(xy) for xy in SHELF.slots]
    assert room == [7, 7, 5, 5, 5, 7, 7, 5, 5, 5]


def test_a_base_under_the_board_is_sent_to_the_nearest_empty_slot_with_room():
    # a..f single blocks, f (the goal tower's base) under the board at slot 3
    assert _room(SIX, SHELF, [2, 4, 7, 8, 9, 3]) == {"f": "slot1"}  # (0.4, -0.16), the nearest
    assert _room(SIX, SHELF, [2, 4, 7, 8, 9, 0]) == {}  # f already has room for six
    five = dataclasses.replace(SIX, goal=SIX.goal[:4])  # a on ... on e: five, room under it
    assert _room(five, SHELF, [2, 4, 7, 8, 9, 3]) == {}
    open_table = with_scene(SceneConfig(), "tabletop")
    assert _room(SIX, open_table, [2, 4, 7, 8, 9, 3]) == {}  # no board: every slot takes it


def test_a_place_holding_a_base_that_stays_is_never_chosen_and_the_least_covered_is():
    names = (*NAMES, "g", "h")
    init = (TABLE,) * 6 + ("h", TABLE)  # g on h
    problem = Problem("eight", "blocksworld", names, init, (*SIX.goal, ("g", "h")))
    # h, the base of the goal tower g-h (it fits), stands on slot 1, the nearest place with
    # room to f at slot 3: the next nearest is chosen
    assert _room(problem, SHELF, [2, 4, 7, 8, 9, 3, 1]) == {"f": "slot6"}
    # g on h in no goal: their slot is the planner's to clear, but an empty one comes first
    loose = dataclasses.replace(problem, goal=SIX.goal)
    # a on slot 1 (the nearest), g-h on slot 6 (the next): the empty slot 0 is chosen
    assert _room(loose, SHELF, [1, 4, 7, 8, 9, 3, 6]) == {"f": "slot0"}


def test_blocks_left_below_a_base_the_goal_leaves_free_count_against_its_room():
    # f on g at slot 0 (room 7): the tower a..f on g is seven, it fits; on two blocks, eight
    names = (*NAMES, "g")
    one = Problem("seven", "blocksworld", names, (TABLE,) * 5 + ("g", TABLE), SIX.goal)
    assert _room(one, SHELF, [2, 4, 7, 8, 9, 0]) == {}
    names2 = (*names, "h")
    init2 = (TABLE,) * 5 + ("g", "h", TABLE)
    two = Problem("eight", "blocksworld", names2, init2, SIX.goal)
    assert _room(two, SHELF, [2, 4, 7, 8, 9, 0]) == {"f": "slot1"}
    # f on the table by its goal: it leaves g, so it needs a place of its own with room
    on_table = dataclasses.replace(one, goal=(*SIX.goal, ("f", TABLE)))
    assert _room(on_table, SHELF, [2, 4, 7, 8, 9, 0]) == {"f": "slot1"}
    at_home = dataclasses.replace(SIX, goal=(*SIX.goal, ("f", TABLE)))  # f on slot 0 already
    assert _room(at_home, SHELF, [2, 4, 7, 8, 9, 0]) == {}


@pytest.mark.sim
def test_the_planner_moves_the_base_out_from_under_the_board_before_building():
    """The six-block tower whose base stands under the board: the plan takes the base to the
    chosen place (over another block: a place is no move's start and end at once) and builds
    the tower there, never more than five blocks under the board."""
    solver = IKSolver()
    poses = layout(SIX.entities, SIX.init, SHELF, seed=0, slots=[2, 4, 7, 8, 9, 3])
    config = dataclasses.replace(PlannerConfig(), lambda_motion=0.05)
    result = plan_on_places(SIX, poses, SHELF, Arm(solver, PANDA.q_home), config, seed=0)
    assert result.solved and result.stats["room_goals"] == {"f": SHELF.slots[1]}
    state = SIX.init
    for move in result.plan:
        state = bw.apply_move(SIX, state, move)
    assert bw.is_goal(SIX, state)
    last = [m for m in result.plan if m.entity == "f" and m.target == TABLE][-1]
    assert last.at == SHELF.slots[1]
