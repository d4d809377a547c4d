"""``tamp run --scene FILE.json --goal GOAL``: the episode starts where the scene file puts the
objects, from the state read from their geometry, and reaches the goal. A scene the Blocksworld
loop can run runs there; one it cannot (regions as targets, other shapes), a canonical problem by
its name, or any scene with ``--geo-planner`` runs as the geometric TAMP episode; what neither
can run is a one-line usage error before any work."""

from __future__ import annotations

import json

import pytest

from tamp.cli import build_parser, main
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
    assert report["status"] == "goal_reached"  # as the geometric episode spells it
    # b is under a in the file: a must go first (from a laid-out state of three single
    # blocks, one move would do)
    assert report["plans"] == [["move(a -> table)", "move(b -> c)"]]
    config = report["config"]
    assert config["scene_file"] == str(path) and config["goal"] == "(and (on b c))"
    assert config["scene"] == "test" and config["problem"] is None


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--goal", "(on a zz)"], "unknown object 'zz'"),
        (["--goal", "(in a zz)"], "unknown region 'zz'"),
        (["--goal", "(in a tray)", "--horizon", "2"], "--horizon: the Blocksworld loop's"),
        (["--goal", "(in a tray)", "--collision", "off"], "without them the moves it plans"),
        (["--goal", "(in a tray)", "--plan", "x"], "--plan with a scene file"),
        (
            ["--goal", "(on a b)", "--geo-planner", "soft", "--motion-aware"],
            "--motion-aware: the Blocksworld loop's",
        ),
        (["--goal", "(in a tray)", "--motion-aware"], "--motion-aware: the Blocksworld loop's"),
        (
            ["--goal", "(in a tray)", "--motion-aware", "--placements", "0.02"],
            "picks each place by",
        ),
        (["--goal", "(in a tray)", "--crisp", "true"], "these objects are observed as poses"),
        (["p.pddl"], "PROBLEM.pddl with --scene"),
        (
            ["--goal", "(on a b)", "--observe", "camera"],
            "--observe camera with a Blocksworld scene file",
        ),
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


@pytest.mark.parametrize(
    ("scene_name", "goal", "expected"),
    [
        ("tower", "(and (on a c) (on b c))", "a and b are both on c"),  # the Blocksworld loop's
        ("tower", "(and (on a b) (on b a))", "cycle a on b on a"),
        ("tray", "(and (on a b) (on b a))", "cycle a on b on a"),
        ("tray", "(and (in a tray) (on a b))", "a has two supports: b, region tray"),  # geometric
    ],
)
def test_a_scene_goal_no_plan_can_reach_is_unsolvable_before_planning(
    tmp_path, capsys, scene_name, goal, expected
):
    """As ``tamp plan`` says of the same goal as PDDL: the static check fires before any
    planning or simulation, so nothing is written under --out."""
    out = tmp_path / "out"
    assert main(["run", "--scene", scene_name, "--goal", goal, "--out", str(out)]) == 1
    text = capsys.readouterr().out.strip()
    assert text == f"unsolvable: {expected}", text
    assert not out.exists()
    assert main(["run", "--scene", scene_name, "--goal", goal, "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["status"] == "unsolvable" and report["reason"] == expected
    assert report["reached_goal"] is False


def recorded(argv):
    """What ``tamp run ARGV`` records as its config (its refusals raise), without running it."""
    args = build_parser().parse_args(["run", *argv])
    return args.recorded(args)


CAN = {
    "name": "can",
    "kind": "cylinder",
    "size": [0.05, 0.06],
    "colour": "red",
    "pose": {"xyz": [0.4, 0.0, 0.03]},
}


@pytest.mark.parametrize(
    ("objects", "goal", "why"),
    [
        ([cube("a", 0.4, -0.16, 0.025)], "(in a tray)", "regions are the geometric episode's"),
        ([cube("a", 0.4, 0.16, 0.025), CAN], "(on a can)", "objects[1] (can): a cylinder"),
        ([cube("a", 0.55, 0.25, 0.025)], "(ontable a)", "a in tray: objects in regions"),
    ],
)
def test_what_the_loop_cannot_run_runs_as_the_geometric_episode(tmp_path, objects, goal, why):
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene(*objects, regions=[TRAY])))
    config = recorded(["--scene", str(path), "--goal", goal, "--sim", "mujoco", "--seed", "4"])
    assert config["executor"] == "geometric" and why in config["why"], config["why"]
    assert config["planner"] == "motion-aware" and config["sim"] == "mujoco"
    assert config["seed"] == 4 and config["domain"] is None
    assert config["scene_file"] == str(path) and config["goal"] == f"(and {goal})"


def test_a_loop_scene_runs_geometrically_with_geo_planner(tmp_path):
    path = tower_file(tmp_path)
    assert "executor" not in recorded(["--scene", str(path), "--goal", "(on b c)"])
    config = recorded(["--scene", str(path), "--goal", "(on b c)", "--geo-planner", "search"])
    assert config["executor"] == "geometric" and config["planner"] == "search"
    assert config["why"] == "--geo-planner search"


def test_a_canonical_problem_runs_by_name_with_its_shipped_goal():
    from tamp.world.canonical import shipped

    config = recorded(["--scene", "packed", "--time-limit", "30", "--inject", "drop:0.5"])
    assert config["executor"] == "geometric" and config["goal"] == shipped("packed")[1].text()
    assert config["time_limit_s"] == 30.0 and config["inject"] == "drop:0.5"
    hanoi = recorded(["--scene", "hanoi"])
    assert hanoi["domain"] == "hanoi-pick-place"  # ours plans it by its rules, as bench tamp
    assert recorded(["--scene", "hanoi", "--geo-planner", "search"])["domain"] is None
    own = recorded(["--scene", "sorting", "--goal", "(in o1 green_zone)"])
    assert own["goal"] == "(and (in o1 green_zone))"


def test_a_problem_file_with_a_canonical_problem_is_refused(capsys):
    """Its problem is read from the scene's geometry: a PDDL problem would be ignored."""
    assert main(["run", "p.pddl", "--scene", "packed"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "PROBLEM.pddl with --scene packed" in err, err


@pytest.mark.sim
def test_a_cube_goes_into_the_tray_by_the_geometric_episode(tmp_path, capsys):
    """The smallest region goal end to end: one move, checked and run in PyBullet."""
    path, out = tmp_path / "s.json", tmp_path / "out"
    path.write_text(json.dumps(scene(cube("a", 0.45, -0.2, 0.025), regions=[TRAY])))
    argv = ["run", "--scene", str(path), "--goal", "(in a tray)", "--out", str(out), "--no-video"]
    assert main(argv) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["reached_goal"] and report["collisions"] == 0
    assert report["status"] == "goal_reached"  # as the Blocksworld loop spells it
    assert [m["move"].split(" at ")[0] for m in report["moves"]] == ["move a -> tray"]
    assert report["config"]["executor"] == "geometric"
    printed = capsys.readouterr()
    assert "goal reached (ground truth): yes" in printed.out and "wrote report.json" in printed.out
    assert "plan 1: solved, 1 moves" in printed.err  # progress as the episode goes
    assert "move 1: move a -> tray" in printed.err and ": ok" in printed.err


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


@pytest.mark.sim
def test_the_python_api_runs_the_same_geometric_episode(tmp_path):
    from tamp import api
    from tamp.geo.config import GeoEpisodeConfig

    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene(cube("a", 0.45, -0.2, 0.025), regions=[TRAY])))
    report = api.run(path, "(in a tray)", sim="mujoco")
    assert report.reached_goal and report.sim == "mujoco" and report.planner == "motion-aware"
    # a loaded Scene, with the geometric episode's config: its simulator and its planner
    loaded = api.load_scene(path)
    report = api.run(loaded, "(in a tray)", GeoEpisodeConfig(sim="pybullet"))
    assert report.reached_goal and report.sim == "pybullet" and report.problem == "test"
    report = api.run(loaded, "(in a tray)", GeoEpisodeConfig(planner="search-then-check"))
    assert report.planner == "search-then-check"
    with pytest.raises(api.TampError, match="needs --goal"):
        api.run(path)


@pytest.mark.sim
def test_the_geometric_episode_injects_the_loop_s_nudge_and_noise(tmp_path, capsys):
    """``--inject nudge:1,noise:1``: the cube placed in the tray is pushed after the move and
    every pose reading is noisy; the report lists the nudge as the loop's does."""
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene(cube("a", 0.45, -0.2, 0.025), regions=[TRAY])))
    argv = ["run", "--scene", str(path), "--goal", "(in a tray)", "--inject", "nudge:1,noise:1"]
    main([*argv, "--json"])
    report = json.loads(capsys.readouterr().out)
    assert report["config"]["executor"] == "geometric"
    assert report["config"]["inject"] == "nudge:1,noise:1"
    assert report["faults"][0] == "nudge@0" and report["moves"][0]["ok"]
    assert all(f.startswith("nudge@") for f in report["faults"])
