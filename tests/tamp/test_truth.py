"""Simulator ground truth only scores episodes: the `GroundTruth` lock (poses, states and the
snapshots videos are drawn from), the finger sensors and the weld that cannot tell what they
touch, and who in the code may reach the truth at all. No simulator runs here;
`tests/tamp/loop/test_camera_episode.py` runs locked episodes."""

from __future__ import annotations

import ast
import dataclasses
import inspect
from pathlib import Path

import numpy as np
import pytest

from tamp.scene import Pose
from tamp.sim.base import GripperReading, Simulator
from tamp.sim.truth import GRANTS, RULE, GroundTruth, GroundTruthLeak, Snapshot
from tamp.world.convert.from_poses import read_state
from task.problem import TABLE

ROOT = Path(__file__).resolve().parents[2]
POSES = {"a": Pose((0.4, 0.0, 0.025)), "b": Pose((0.4, 0.0, 0.075))}
SNAPSHOT = Snapshot(np.zeros(9), np.array([[0.4, 0.0, 0.025]]), np.array([[1.0, 0, 0, 0]]))


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
    with pytest.raises(GroundTruthLeak, match=r"\(block_poses\)"):
        read_state(("a", "b"), truth.block_poses())


def test_reads_inside_a_grant_are_answered_and_counted_by_grant_and_caller():
    truth = GroundTruth(lambda: dict(POSES))
    truth.lock()
    with truth.scoring():
        assert read_state(("a", "b"), truth.block_poses()).state == (TABLE, "a")
    with truth.experimenter():
        assert truth.block_poses()["a"] == POSES["a"]
    with truth.oracle():
        robot_side_read(truth)
    assert truth.purposes() == {"scoring", "experimenter", "oracle"}
    caller = f"{__name__}.robot_side_read"
    assert truth.reads[("oracle", caller)] == 1
    with pytest.raises(GroundTruthLeak):  # the grant ended with its block
        truth.block_poses()


def test_a_snapshot_is_ground_truth_answered_only_under_a_grant():
    truth = GroundTruth(lambda: dict(POSES), lambda: SNAPSHOT)
    assert truth.snapshot() is SNAPSHOT  # unlocked: answered
    truth.lock()
    with pytest.raises(GroundTruthLeak, match=r"\(snapshot\)"):
        truth.snapshot()
    with truth.recording():
        assert truth.snapshot() is SNAPSHOT
    assert truth.purposes() == {"unlocked", "recording"} and "recording" in GRANTS


def test_the_finger_sensors_and_the_weld_take_and_give_no_block():
    """A fingertip sensor cannot tell what it touches: ``gripper()`` names no block, and its
    reading holds the opening and the two finger forces only. The weld attaches what is between
    the fingers: ``attach()`` is told no block and says only whether it held one, and the
    executor never names one to it."""
    from tamp.sim.mujoco_sim import MuJoCoSim
    from tamp.sim.pybullet_sim import PyBulletSim

    for cls in (Simulator, PyBulletSim, MuJoCoSim):
        assert list(inspect.signature(cls.gripper).parameters) == ["self"], cls
        assert list(inspect.signature(cls.attach).parameters) == ["self"], cls
        assert inspect.signature(cls.attach).return_annotation in (bool, "bool"), cls
    reading = [(f.name, f.type) for f in dataclasses.fields(GripperReading)]
    assert reading == [("width", "float"), ("left_force", "float"), ("right_force", "float")]
    calls = [  # wherever the executors' code asks for the weld (`tamp.sim.base.lost_hold`)
        node
        for path in (ROOT / "tamp").rglob("*.py")
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "attach"
    ]
    assert calls and all(not c.args and not c.keywords for c in calls)


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


def _granted(path: Path, attribute: str) -> list[str]:
    """The calls of ``x.<attribute>(...)`` in ``path`` that no ``with ...<grant>():`` block
    around them grants, as ``line N``."""
    tree = ast.parse(path.read_text())
    inside = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.With) and any(
            getattr(getattr(i.context_expr, "func", None), "attr", "") in GRANTS for i in node.items
        ):
            inside |= {id(n) for n in ast.walk(node)}
    return [
        f"line {node.lineno}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and getattr(node.func, "attr", "") == attribute
        and id(node) not in inside
    ]


def test_only_the_simulators_reach_the_raw_poses_and_only_named_loop_modules_the_truth():
    sims = {"tamp/sim/base.py", "tamp/sim/pybullet_sim.py", "tamp/sim/mujoco_sim.py"}
    assert _uses("_block_poses", "tamp") <= sims
    assert _uses("_snapshot", "tamp") <= sims
    # in the simulator room: the truth itself, and the experimenter's nudge (an injected fault)
    assert _uses("block_poses", "tamp/sim") <= {"tamp/sim/truth.py", "tamp/sim/faults.py"}
    # a snapshot (the true block poses) is read by the video and the Rerun recording alone,
    # inside their recording grant
    assert _uses("snapshot", "tamp") <= {"tamp/sim/truth.py", "tamp/video.py", "tamp/rerun_log.py"}
    assert _granted(ROOT / "tamp/video.py", "snapshot") == []
    assert _granted(ROOT / "tamp/rerun_log.py", "snapshot") == []
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
        reach = _uses("truth", room) | _uses("block_poses", room) | _uses("snapshot", room)
        assert not reach, room
