"""Simulator ground truth only scores episodes: the `GroundTruth` lock, the finger sensors that
cannot tell what they touch, and who in the code may reach the truth at all. No simulator
runs here; `tests/tamp/loop/test_camera_episode.py` runs locked episodes."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

from tamp.scene import Pose
from tamp.sim.base import Simulator
from tamp.sim.truth import RULE, GroundTruth, GroundTruthLeak
from task.problem import TABLE

ROOT = Path(__file__).resolve().parents[2]
POSES = {"a": Pose((0.4, 0.0, 0.025)), "b": Pose((0.4, 0.0, 0.075))}


def robot_side_read(truth: GroundTruth) -> dict[str, Pose]:
    return truth.block_poses()


def test_a_locked_read_raises_naming_the_rule_and_the_caller():
    truth = GroundTruth(lambda: dict(POSES))
    assert robot_side_read(truth) == POSES  # unlocked: answered
    truth.lock()
    with pytest.raises(GroundTruthLeak) as err:
        robot_side_read(truth)
    message = str(err.value)
    assert RULE in message and "only scores episodes" in message
    assert "test_truth.robot_side_read" in message and "(block_poses)" in message
    with pytest.raises(GroundTruthLeak, match=r"\(state\)"):
        truth.state(("a", "b"))


def test_reads_inside_a_grant_are_answered_and_counted_by_grant_and_caller():
    truth = GroundTruth(lambda: dict(POSES))
    truth.lock()
    with truth.scoring():
        assert truth.state(("a", "b")) == (TABLE, "a")
    with truth.experimenter():
        assert truth.block_poses()["a"] == POSES["a"]
    with truth.oracle():
        robot_side_read(truth)
    assert truth.purposes() == {"scoring", "experimenter", "oracle"}
    caller = f"{__name__}.robot_side_read"
    assert truth.reads[("oracle", caller)] == 1
    with pytest.raises(GroundTruthLeak):  # the grant ended with its block
        truth.block_poses()


def test_the_finger_sensors_take_no_block():
    """A fingertip sensor cannot tell what it touches: ``gripper()`` names no block."""
    from tamp.sim.mujoco_sim import MuJoCoSim
    from tamp.sim.pybullet_sim import PyBulletSim

    for cls in (Simulator, PyBulletSim, MuJoCoSim):
        assert list(inspect.signature(cls.gripper).parameters) == ["self"], cls


def _uses(attribute: str, folder: str) -> set[str]:
    """Modules under ``folder`` whose code (not docstrings) reaches ``x.<attribute>``."""
    return {
        str(p.relative_to(ROOT))
        for p in (ROOT / folder).rglob("*.py")
        if any(
            isinstance(node, ast.Attribute) and node.attr == attribute
            for node in ast.walk(ast.parse(p.read_text()))
        )
    }


def test_only_the_simulators_reach_the_raw_poses_and_only_named_loop_modules_the_truth():
    sims = {"tamp/sim/base.py", "tamp/sim/pybullet_sim.py", "tamp/sim/mujoco_sim.py"}
    assert _uses("_block_poses", "tamp") <= sims
    assert _uses("block_poses", "tamp/sim") <= {"tamp/sim/truth.py"}
    # in the loop: the scorer, the nudge (experimenter), the state-mode mocap oracle and the
    # per-step verdicts of a given plan (scoring: what the report says, never what the robot does)
    assert _uses("truth", "tamp/loop") <= {
        "tamp/loop/episode.py",
        "tamp/loop/score.py",
        "tamp/loop/recover.py",
        "tamp/loop/sensors.py",
        "tamp/loop/given.py",
    }
    for room in ("tamp/camera", "tamp/bench", "tamp/cli", "motion", "perception"):
        assert not _uses("truth", room) | _uses("block_poses", room), room
