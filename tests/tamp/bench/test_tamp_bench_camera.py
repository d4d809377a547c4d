"""``tamp bench tamp --observe camera``: episodes observed by the camera sensor
(`tamp.camera.scene_poses.ScenePoses`), its pose errors recorded (tamp.bench.geo)."""

from __future__ import annotations

import csv
import json

import pytest

from tamp.bench.geo import run as bench
from tamp.cli import main
from task.errors import TampError


def _row(observe: str, mean: float | None, most: float | None, unseen: str = "") -> dict:
    return {
        "problem": "blocked",
        "planner": "motion-aware",
        "sim": "pybullet",
        "observe": observe,
        "pose_mm_mean": mean,
        "pose_mm_max": most,
        "yaw_deg_max": None if mean is None else 0.5,
        "unseen": unseen,
    }


def test_the_camera_summary_takes_the_camera_rows_only():
    rows = [
        _row("camera", 1.0, 4.0, "a:2;b:1"),
        _row("camera", 3.0, 9.0),
        _row("state", None, None),
    ]
    got = bench.camera_summary(rows)
    assert got == {"pose_mm_mean": 2.0, "pose_mm_max": 9.0, "yaw_deg_max": 0.5, "unseen_looks": 3}
    assert bench.camera_summary(rows[2:]) == {}


def test_items_carry_the_pose_sensor():
    todo = bench.items(("blocked",), 2, ("soft",), ("pybullet",), 0, observe="camera")
    assert {i.observe for i in todo} == {"camera"}
    assert {i.observe for i in bench.items(("blocked",), 1, ("soft",), ("pybullet",), 0)} == {
        "state"
    }


def test_an_unknown_observation_is_refused_naming_the_valid_ones():
    from tamp.geo.config import GeoEpisodeConfig
    from tamp.geo.episode import run_geo_episode
    from tamp.world.canonical import generate

    made = generate("blocked", 0)
    with pytest.raises(TampError, match="state, camera"):
        run_geo_episode(made.scene, made.goal, GeoEpisodeConfig("soft", observation="lidar"))


@pytest.mark.sim
@pytest.mark.slow
def test_a_camera_episode_reaches_the_goal_and_records_its_pose_errors(tmp_path):
    """blocked variant 0 by ours in PyBullet, every pose from the cameras (about 20 s)."""
    out = tmp_path / "out"
    argv = ["bench", "tamp", "--problems", "blocked", "--n", "1", "--sim", "pybullet"]
    argv += ["--planner", "motion-aware", "--observe", "camera", "--out", str(out)]
    assert main([*argv, "--no-progress"]) == 0
    body = json.loads((out / "results.json").read_text())
    assert body["config"]["observe"] == "camera"
    (row,) = list(csv.DictReader((out / "episodes.csv").open()))
    assert row["observe"] == "camera" and row["reached_goal"] == "True"
    assert float(row["pose_mm_mean"]) < 3.0 and float(row["pose_mm_max"]) < 10.0
    assert body["camera"]["pose_mm_max"] == pytest.approx(float(row["pose_mm_max"]), abs=1e-3)
