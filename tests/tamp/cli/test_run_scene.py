"""``tamp run --scene FILE.json --goal GOAL``: the episode starts where the scene file puts the
objects, from the state read from their geometry, and reaches the goal; what the loop cannot
run yet is a one-line usage error before any work."""

from __future__ import annotations

import json

import pytest

from tamp.cli import main
from tests.tamp.world.test_load import TRAY, cube, scene


def tower_file(tmp_path):
    """a on b (a tower of two), c alone on the table."""
    data = scene(
        cube("a", 0.4, -0.16, 0.075), cube("b", 0.4, -0.16, 0.025), cube("c", 0.4, 0.16, 0.025)
    )
    path = tmp_path / "tower.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.sim
def test_a_scene_file_s_tower_is_read_from_its_geometry_and_the_goal_reached(tmp_path, capsys):
    path, out = tower_file(tmp_path), tmp_path / "out"
    argv = ["run", "--scene", str(path), "--goal", "(on b c)", "--out", str(out), "--no-video"]
    assert main(argv) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["reached_goal"] and report["replans"] == 0
    # b is under a in the file: a must go first (from a laid-out state of three single
    # blocks, one move would do)
    assert report["plans"] == [["move(a -> table)", "move(b -> c)"]]
    config = report["config"]
    assert config["scene_file"] == str(path) and config["goal"] == "(and (on b c))"
    assert config["scene"] == "test" and config["problem"] is None


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--goal", "(in a tray)"], "regions are not planning targets yet"),
        (["--goal", "(on a zz)"], "unknown object 'zz'"),
        (["--goal", "(on a b)", "--observe", "camera"], "--observe camera with a scene file"),
        ([], "needs --goal"),
    ],
)
def test_what_a_scene_file_run_cannot_do_is_refused_in_one_line(tmp_path, capsys, extra, expected):
    data = scene(cube("a", 0.4, -0.16, 0.025), cube("b", 0.4, 0.16, 0.025), regions=[TRAY])
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    assert main(["run", "--scene", str(path), *extra, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err, err
    assert not (tmp_path / "out").exists()  # refused before any work


def test_a_cylinder_in_the_scene_is_refused_naming_it(tmp_path, capsys):
    can = {
        "name": "can",
        "kind": "cylinder",
        "size": [0.05, 0.06],
        "colour": "red",
        "pose": {"xyz": [0.4, 0.0, 0.03]},
    }
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene(cube("a", 0.4, 0.16, 0.025), can)))
    assert main(["run", "--scene", str(path), "--goal", "(on a can)"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "objects[1] (can): a cylinder" in err, err


@pytest.mark.sim
def test_the_episode_starts_where_the_scene_file_puts_the_objects(tmp_path):
    """Not at a `tamp.scene.layout` of the state read: at the file's poses (c off the grid)."""
    from tamp.loop import Episode, LoopConfig
    from tamp.world.blocks import scene_task

    data = scene(
        cube("a", 0.45, -0.1, 0.075, yaw=0.3),
        cube("b", 0.45, -0.1, 0.025),
        cube("c", 0.5, 0.2, 0.025),
    )
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    task = scene_task(path, "(on b c)")
    episode = Episode(task.problem, LoopConfig(scene=task.config), poses=dict(task.poses))
    try:
        seen = episode.eyes.poses()
    finally:
        episode.close()
    for name, pose in task.poses:
        assert seen[name].xyz == pytest.approx(pose.xyz, abs=0.003), name
