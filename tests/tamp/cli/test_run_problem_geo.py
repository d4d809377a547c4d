"""``tamp run PROBLEM.pddl --geo-planner P`` and ``api.run(problem, config=GeoEpisodeConfig)``:
a Blocksworld problem laid out on a workcell as the loop lays it out
(`tamp.world.convert.from_problem`) runs as the geometric episode with the planner named;
without a planner it runs in the Blocksworld loop as before."""

from __future__ import annotations

import json

import pytest

from tamp.cli import build_parser, main
from tamp.geo.scene_file import problem_episode
from tamp.world import read_facts
from tamp.world.goal_check import UnsolvableGoal
from task.problem import TABLE, Problem

PDDL = """(define (problem bw3) (:domain blocksworld-4ops) (:objects a b c)
  (:init (handempty) (ontable a) (on b a) (clear b) (ontable c) (clear c))
  (:goal (and (on a b) (on b c))))"""


def problem_file(tmp_path):
    path = tmp_path / "bw3.pddl"
    path.write_text(PDDL)
    return path


def recorded(argv):
    """What ``tamp run ARGV`` records as its config (its refusals raise), without running it."""
    args = build_parser().parse_args(["run", *argv])
    return args.recorded(args)


@pytest.mark.parametrize("planner", ["search-then-check", "search", "motion-aware", "soft"])
def test_a_problem_with_a_planner_named_runs_as_the_geometric_episode(tmp_path, planner):
    path = problem_file(tmp_path)
    config = recorded([str(path), "--geo-planner", planner, "--scene", "shelf", "--seed", "2"])
    assert config["executor"] == "geometric" and config["planner"] == planner
    assert config["problem"] == str(path) and config["scene"] == "shelf"
    assert config["scene_file"] is None and config["seed"] == 2
    assert config["goal"] == "(and (on a b) (on b c))"
    assert "bw3 laid out on workcell shelf, seed 2" in config["why"]


def test_without_a_planner_the_problem_runs_in_the_blocksworld_loop(tmp_path):
    config = recorded([str(problem_file(tmp_path))])
    assert "executor" not in config and config["scene"] == "tabletop"
    # the embedded example too, on a workcell, with a planner named
    config = recorded(["--geo-planner", "search", "--scene", "clutter"])
    assert config["executor"] == "geometric" and config["scene"] == "clutter"


def test_the_episode_starts_from_the_problems_initial_state_among_the_workcells_obstacles():
    problem = Problem("p", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "b"),))
    task = problem_episode(problem, "clutter", "search", 5)
    supports = dict(read_facts(task.scene).supports)
    assert supports == {"a": TABLE, "b": "a", "c": TABLE}
    assert task.goal.atoms == (("on", "a", "b"),)
    assert {o.name for o in task.scene.obstacles} >= {"wall", "post_0"}
    assert task.workcell == "clutter" and task.planner == "search"


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--plan", "p.txt"], "--plan with --geo-planner search: a given plan runs in the"),
        (["--goal", "(on a b)"], "--goal with PROBLEM.pddl"),
    ],
)
def test_what_the_geometric_episode_of_a_problem_cannot_do_is_one_line(
    tmp_path, capsys, extra, expected
):
    argv = ["run", str(problem_file(tmp_path)), "--geo-planner", "search", *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and expected in err, err


def test_a_goal_no_plan_can_reach_is_unsolvable_before_planning():
    problem = Problem("p", "blocksworld", ("a", "b", "c"), (TABLE,) * 3, (("a", "b"), ("b", "a")))
    with pytest.raises(UnsolvableGoal, match="cycle"):
        problem_episode(problem, "tabletop", "search", 0)


@pytest.mark.sim
def test_a_three_block_problem_reaches_its_goal_by_search_then_check(tmp_path, capsys):
    out = tmp_path / "out"
    argv = [
        "run",
        str(problem_file(tmp_path)),
        "--geo-planner",
        "search-then-check",
        "--out",
        str(out),
        "--no-video",
    ]
    assert main(argv) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["reached_goal"] and report["planner"] == "search-then-check"
    assert report["config"]["executor"] == "geometric" and report["sim"] == "pybullet"


@pytest.mark.sim
def test_the_python_api_runs_a_problem_with_any_planner():
    from tamp import api
    from tamp.geo.config import GeoEpisodeConfig

    config = GeoEpisodeConfig(planner="search-then-check")
    report = api.run(PDDL, config=config)
    assert report.reached_goal and report.planner == "search-then-check"
    assert report.problem == "bw3"
