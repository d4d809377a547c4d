"""Both simulators: one pick-and-place (friction and weld grasps; the weld holds what is between
the fingers), an unreachable block, renders that look alike, video frames (their size, a second
world posed from a snapshot, one frame clock across runs) and ``tamp run`` writing its video.
Each takes seconds. Whole episodes of the closed loop are tested in
``tests/tamp/loop/test_episode.py``."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from motion.ik import IKSolver
from motion.trajectory import JointTrajectory
from robots.panda import PANDA
from tamp.cli import main
from tamp.cli.run import FRAME_PERIOD
from tamp.loop.execute import ExecTools, execute_move
from tamp.outcome import Failure
from tamp.scene import Pose, layout
from tamp.sim import SIMULATORS, make_simulator
from tamp.world.convert.from_poses import read_state
from task.errors import TampError
from task.problem import TABLE, Move

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_one_pick_and_place_stacks_the_block(sim_name, solver):
    entities = ("a", "b")
    with make_simulator(sim_name, entities, layout(entities, (TABLE, TABLE), seed=2)) as sim:
        done = execute_move(sim, Move("a", "b"), sim.truth.block_poses, ExecTools(solver))
        assert done.ok, done.evidence
        assert read_state(entities, sim.truth.block_poses()).state == ("b", TABLE)
        assert done.sim_time_s > 1.0 and done.ik_time_s > 0.0


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_weld_grasp_mode_also_stacks_the_block(sim_name, solver):
    entities = ("a", "b")
    poses = layout(entities, (TABLE, TABLE), seed=4)
    with make_simulator(sim_name, entities, poses, grasp="weld") as sim:
        done = execute_move(sim, Move("a", "b"), sim.truth.block_poses, ExecTools(solver))
        assert done.ok, done.evidence
        assert read_state(entities, sim.truth.block_poses()).state == ("b", TABLE)


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_the_weld_holds_the_block_between_the_fingers_not_the_one_the_move_names(sim_name, solver):
    """The robot is told a is where b is (a misread): it closes on b, and the weld holds b,
    what is between its fingers; a, named by the move, stays where it is."""
    entities = ("a", "b", "c")
    poses = layout(entities, (TABLE, TABLE, TABLE), seed=0, slots=[0, 4, 7])
    with make_simulator(sim_name, entities, poses, grasp="weld") as sim:

        def misread():
            true = sim.truth.block_poses()
            return {**true, "a": true["b"], "b": true["a"]}

        done = execute_move(sim, Move("a", "c"), misread, ExecTools(solver))
        after = sim.truth.block_poses()
        assert done.ok, done.evidence
        assert np.linalg.norm(np.subtract(after["a"].xyz, poses["a"].xyz)) < 0.005
        assert read_state(entities, after).state == (TABLE, "c", TABLE)


def test_an_unreachable_block_is_an_ik_infeasible_failure(solver):
    entities = ("a",)
    with make_simulator("pybullet", entities, {"a": Pose((1.4, 0.0, 0.025))}) as sim:
        done = execute_move(sim, Move("a", TABLE), sim.truth.block_poses, ExecTools(solver))
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
    capture = cv2.VideoCapture(str(tmp_path / "episode.mp4"))
    frames = []
    while (read := capture.read())[0]:
        frames.append(read[1])
    capture.release()
    assert frames[0].shape == (480, 640, 3)
    # one frame every FRAME_PERIOD simulated seconds, on one clock over the whole episode
    assert abs(len(frames) - report["sim_time_s"] / FRAME_PERIOD) <= 2
    assert all(f[40:].std() > 10 for f in frames[:: len(frames) // 5])  # a scene, not blank


def _red(img: np.ndarray) -> np.ndarray:
    """Pixels (H, W) of the red block."""
    return (img[..., 0] > 120) & (img[..., 1] < 80) & (img[..., 2] < 80)


@pytest.mark.parametrize("sim_name", SIMULATORS)
@pytest.mark.parametrize("video", [False, True])
def test_video_frames_are_640x480_and_show_the_scene(sim_name, video):
    entities = ("a", "b")
    poses = layout(entities, (TABLE, "a"), seed=1)
    with make_simulator(sim_name, entities, poses, video=video) as sim:
        frame = sim.render_video()
        small = None if video else sim.render()
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8
    assert frame.std() > 10  # not blank
    if small is not None:  # the same view, twice the size each way
        assert small.shape == (240, 320, 3)
        ratio = _red(frame).sum() / _red(small).sum()
        assert 3 < ratio < 5
        centre, centre_small = np.argwhere(_red(frame)).mean(0), np.argwhere(_red(small)).mean(0)
        assert np.linalg.norm(centre - 2 * centre_small) < 6
    else:
        assert _red(frame).sum() > 400


def test_a_pybullet_world_made_for_videos_renders_no_camera_images():
    sim = make_simulator("pybullet", ("a",), {"a": Pose((0.5, 0.0, 0.025))}, video=True)
    with sim, pytest.raises(TampError, match="video"):
        sim.render()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_second_world_posed_from_a_snapshot_renders_the_same_image(sim_name):
    entities = ("a", "b")
    poses = layout(entities, (TABLE, "a"), seed=1)
    elsewhere = layout(entities, (TABLE, TABLE), seed=5)
    reach = np.asarray(PANDA.q_home) + np.array([0.4, 0.3, 0.0, 0.2, 0.0, 0.0, 0.0])
    with make_simulator(sim_name, entities, poses) as sim:
        sim.run(JointTrajectory.hold(reach, 0.3, sim.dt), "closed")
        sim.set_block_pose("b", Pose((0.45, 0.2, 0.025), 0.4))
        with make_simulator(sim_name, entities, elsewhere) as copy:
            before = copy.render()
            copy.show(sim.truth.snapshot())
            np.testing.assert_allclose(
                copy.truth.snapshot().joints, sim.truth.snapshot().joints, atol=1e-9
            )
            shown, original = copy.render().astype(int), sim.render().astype(int)
    assert np.abs(before - original).mean() > 1  # the arm and the blocks moved (2.3, 5.6)
    assert np.abs(shown - original).mean() < 0.5  # 0.0 in both when written


def test_frames_keep_one_clock_across_runs():
    times = []
    with make_simulator("pybullet", ("a",), {"a": Pose((0.5, 0.0, 0.025))}) as sim:
        sim.frame_period = 0.1
        for _ in range(3):  # three short runs of 0.15 s
            sim.run(
                JointTrajectory.hold(PANDA.q_home, 0.15, sim.dt),
                "open",
                on_frame=lambda s: times.append(s.time),
            )
    np.testing.assert_allclose(np.diff(times), 0.1, atol=1.5 * sim.physics_dt)
    assert len(times) == 5  # 0.45 s: frames at 0.0, 0.1, 0.2, 0.3, 0.4 (plus a step)
