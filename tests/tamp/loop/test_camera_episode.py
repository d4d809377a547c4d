"""The rule, enforced: in a camera episode nothing robot-side reads simulator ground truth.

The episode locks ``sim.truth``; any read outside a grant raises `GroundTruthLeak` and ends the
test. Afterwards the only answered reads must be the scorer's. One short 3-block episode per
simulator: the robot picks and places where the depth camera sees the blocks. Then what the
camera does when a block is hidden: the arm goes home to look again, and a block it still cannot
see fails the move as ``unobservable``."""

from __future__ import annotations

import numpy as np
import pytest

from motion.trajectory import straight_segment
from perception.errors import PerceptionError
from robots.panda import PANDA
from tamp.loop import Episode, EpisodeStatus, LoopConfig
from tamp.loop.execute import ExecTools, execute_move
from tamp.loop.observe import HOME_TOL
from tamp.loop.sensors import CameraPoses
from tamp.outcome import Failure
from tamp.sim import SIMULATORS, GroundTruthLeak
from task.problem import TABLE, Move, Problem

THREE = Problem(
    "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
)


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_camera_episode_reads_ground_truth_only_to_score(sim_name):
    episode = Episode(THREE, LoopConfig(sim=sim_name, observe="camera"), seed=0)
    truth = episode.sim.truth
    assert truth.locked
    report = episode.run()
    assert report.status is EpisodeStatus.GOAL_REACHED, report.reason
    assert report.reached_goal and all(m.ok for m in report.moves), report.moves
    assert truth.purposes() == {"scoring"}
    assert {caller for _, caller in truth.reads} == {"tamp.loop.score.Scorer.state"}


@pytest.mark.sim
def test_a_hidden_block_sends_the_arm_home_and_one_still_hidden_is_unobservable():
    """Also: a pose sensor that read ground truth in a running episode would raise."""
    episode = Episode(THREE, LoopConfig(observe="camera"), seed=0)
    sim, eyes, home = episode.sim, episode.eyes, np.asarray(PANDA.q_home)
    try:
        eyes.sensor = sim.truth.block_poses  # a robot-side pose sensor that cheats
        with pytest.raises(GroundTruthLeak, match="only scores episodes"):
            eyes.poses()
        sim.run(straight_segment(sim.arm_q(), home + 0.2, sim.dt), "open")  # away from home
        camera, looks = CameraPoses(sim, THREE.entities, LoopConfig().scene), []

        def hidden_once() -> dict:
            looks.append(sim.arm_q())
            if len(looks) == 1:
                raise PerceptionError("block(s) b not found in the image")
            return camera()

        eyes.sensor, shown = hidden_once, []
        assert set(eyes.poses(show=shown.append)) == {"a", "b", "c"}
        assert shown == ["home to look again"] and np.abs(looks[1] - home).max() < HOME_TOL

        def hidden() -> dict:
            raise PerceptionError("block(s) b not found in the image")

        eyes.sensor = hidden
        done = execute_move(sim, Move("b", TABLE), eyes.poses, ExecTools(episode.solver))
        assert done.failure is Failure.UNOBSERVABLE and "b not found" in done.evidence["seen"]
    finally:
        sim.close()
