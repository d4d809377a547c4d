"""The named scenes (`tamp.obstacles`): their boxes in the scene model and in both simulators,
the clearance an overhead shelf leaves, and the arm's contacts scored in the simulator."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from motion.ik import IKSolver, top_down_pose
from motion.trajectory import straight_segment
from robots.panda import PANDA
from tamp.obstacles import SCENES, Obstacle, ceiling, with_scene
from tamp.scene import SceneConfig, SceneError, free_slots, layout
from tamp.sim import SIMULATORS, make_simulator
from task.errors import TampError
from task.problem import TABLE

SHELF, CLUTTER = with_scene(SceneConfig(), "shelf"), with_scene(SceneConfig(), "clutter")


def test_the_named_scenes_and_an_unknown_name():
    assert set(SCENES) == {"tabletop", "shelf", "clutter", "cramped"}
    assert with_scene(SceneConfig(), "tabletop") == replace(SceneConfig(), name="tabletop")
    with pytest.raises(TampError, match=r"unknown scene 'attic' \(valid: tabletop, shelf"):
        with_scene(SceneConfig(), "attic")
    with pytest.raises(TampError, match="half extents"):
        Obstacle("flat", (0.5, 0.0, 0.1), (0.1, 0.1, 0.0))


def test_a_shelf_lowers_the_ceiling_and_the_capacity_of_the_slots_under_it():
    under, open_ = (0.56, 0.32), (0.40, -0.32)
    assert math.isfinite(ceiling(under, SHELF.obstacles))
    assert math.isinf(ceiling(open_, SHELF.obstacles))
    assert 0 < SHELF.capacity(under) < SHELF.max_height == SHELF.capacity(open_)
    # posts stand on the table: they are not overhead and leave every slot its capacity
    assert {CLUTTER.capacity(s) for s in CLUTTER.slots} == {CLUTTER.max_height}


def test_layout_keeps_a_tower_out_of_slots_too_low_for_it():
    entities = tuple("abcdef")
    state = (TABLE, "a", "b", "c", "d", "e")  # one tower of six: one more than under the shelf
    assert max(SHELF.capacity(s) for s in SHELF.slots if s[1] == 0.32) == 5
    for seed in range(30):
        poses = layout(entities, state, SHELF, seed)
        assert SHELF.capacity(poses["a"].xy) >= 6
    with pytest.raises(SceneError, match="no slot of scene 'shelf' has room"):
        layout(entities, state, replace(SHELF, slot_ys=(0.32,)), 0)


def test_free_slots_put_slots_under_the_shelf_last_among_equally_free_ones():
    ranked = free_slots({}, (0.5, 0.3, 0.0), SHELF)
    assert len(ranked) == len(SHELF.slots)
    limited = [SHELF.capacity(s) < SHELF.max_height for s in ranked]
    assert limited == sorted(limited)  # every unlimited slot before every limited one


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_both_simulators_build_the_obstacles_and_score_the_arm_hitting_one(sim_name):
    entities, state = ("a", "b"), (TABLE, TABLE)
    poses = layout(entities, state, CLUTTER, seed=0, slots=[0, 9])
    with make_simulator(sim_name, entities, poses, CLUTTER) as sim:
        home = np.asarray(PANDA.q_home)
        sim.run(straight_segment(home, home, sim.dt), "open")
        assert sim.touched == {}  # at rest, the arm touches nothing
        post = CLUTTER.obstacles[2].centre  # post_2 at (0.48, 0.08)
        into = IKSolver().solve(top_down_pose((post[0], post[1], 0.1), 0.0)[None], home).q[0]
        sim.run(straight_segment(home, into, sim.dt), "open")
        assert "post_2" in sim.touched
