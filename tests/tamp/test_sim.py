"""Both simulators: one pick-and-place (friction and weld grasps), an unreachable block, renders
that look alike, and ``tamp run`` writing its video. Each takes seconds. Whole episodes of the
closed loop are tested in ``tests/tamp/loop/test_episode.py``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motion.ik import IKSolver
from tamp.cli import main
from tamp.loop.execute import Failure, execute_move
from tamp.scene import Pose, layout, read_state
from tamp.sim import SIMULATORS, make_simulator
from task.problem import TABLE, Move

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_one_pick_and_place_stacks_the_block(sim_name, solver):
    entities = ("a", "b")
    with make_simulator(sim_name, entities, layout(entities, (TABLE, TABLE), seed=2)) as sim:
        done = execute_move(sim, solver, Move("a", "b"), sim.truth.block_poses)
        assert done.ok, done.evidence
        assert read_state(entities, sim.truth.block_poses()).state == ("b", TABLE)
        assert done.sim_time_s > 1.0 and done.ik_time_s > 0.0


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_weld_grasp_mode_also_stacks_the_block(sim_name, solver):
    entities = ("a", "b")
    poses = layout(entities, (TABLE, TABLE), seed=4)
    with make_simulator(sim_name, entities, poses, grasp="weld") as sim:
        done = execute_move(sim, solver, Move("a", "b"), sim.truth.block_poses)
        assert done.ok, done.evidence
        assert read_state(entities, sim.truth.block_poses()).state == ("b", TABLE)


def test_an_unreachable_block_is_an_ik_infeasible_failure(solver):
    entities = ("a",)
    with make_simulator("pybullet", entities, {"a": Pose((1.4, 0.0, 0.025))}) as sim:
        done = execute_move(sim, solver, Move("a", TABLE), sim.truth.block_poses)
    assert not done.ok and done.failure is Failure.IK_INFEASIBLE
    assert done.evidence["waypoint"] == "pre_grasp"


def test_renders_look_alike_in_both_simulators():
    entities = ("a", "b")
    poses = layout(entities, (TABLE, "a"), seed=1)
    images = []
    for name in SIMULATORS:
        with make_simulator(name, entities, poses) as sim:
            images.append(sim.render())
    centres = []
    for img in images:
        assert img.shape == (240, 320, 3) and img.dtype == np.uint8
        red = (img[..., 0] > 120) & (img[..., 1] < 80) & (img[..., 2] < 80)  # block a
        assert red.sum() > 10
        centres.append(np.argwhere(red).mean(axis=0))
    # the same camera model in both: block a lands at about the same pixel
    assert np.linalg.norm(centres[0] - centres[1]) < 25


def test_tamp_run_writes_video_and_report(tmp_path):
    code = main(["run", "--sim", "pybullet", "--seed", "0", "--out", str(tmp_path), "--json"])
    report = json.loads((tmp_path / "report.json").read_text())
    assert code == (0 if report["reached_goal"] else 1)
    assert report["status"] == "goal_reached" and report["config"]["sim"] == "pybullet"
    assert (tmp_path / "episode.mp4").stat().st_size > 10_000
