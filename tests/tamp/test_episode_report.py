"""One report type for both stacks (`tamp.episode_report.EpisodeReport`): the Blocksworld loop
and the geometric episode return it, and ``tamp run --out`` writes a ``report.json`` with the
same top-level keys for a Blocksworld problem, a scene file of cubes and any other scene file,
naming the planner that ran and the simulator."""

from __future__ import annotations

import json

import pytest

from tamp.cli import main
from tamp.episode_report import EpisodeReport
from tamp.geo.episode import MoveRecord
from tamp.geo.types import GeoMove, Place
from tamp.loop.execute import ExecutionResult
from tamp.outcome import EpisodeStatus, Failure
from task.problem import Move
from tests.tamp.world.test_load import TRAY, cube, scene

TWO = """(define (problem two) (:domain blocksworld-4ops)
  (:objects a b)
  (:init (handempty) (ontable a) (ontable b) (clear a) (clear b))
  (:goal (and (on a b))))
"""


def _loop_report() -> EpisodeReport:
    moves = (
        ExecutionResult(Move("a", "b"), True),
        ExecutionResult(Move("b", "a"), False, Failure.IK_INFEASIBLE),
    )
    return EpisodeReport(
        "two",
        "pybullet",
        EpisodeStatus.GOAL_REACHED,
        True,
        moves,
        (),
        0,
        (),
        0,
        1.0,
        2.0,
        0.5,
        first_plan=(Move("a", "b"),),
        planner="soft",
        touched={"table": 3},
    )


def _geo_report() -> EpisodeReport:
    place = Place("tray.c0", "tray", (0.5, 0.1, 0.025))
    records = (
        MoveRecord("move a -> tray", "top0", True),
        MoveRecord("move b -> tray", "", False, Failure.COLLISION, {"phase": "lift"}),
        MoveRecord("move b -> tray", "top0", False, Failure.UNEXPECTED),
    )
    return EpisodeReport(
        "tray",
        "mujoco",
        EpisodeStatus.REPLAN_BUDGET,
        False,
        records,
        (),
        2,
        ("drop@1",),
        0,
        4.0,
        5.0,
        1.5,
        first_plan=(GeoMove("a", place),),
        planner="motion-aware",
        plan_times_s=(1.0, 0.5),
        arm_path_rad=2.5,
    )


def test_both_episodes_reports_have_the_same_keys_in_json():
    loop, geo = _loop_report().to_json(), _geo_report().to_json()
    assert set(loop) == set(geo)
    assert {"sim", "planner", "status", "reason", "reached_goal", "moves", "replans"} <= set(loop)
    assert {"plan_time_s", "sim_time_s", "wall_time_s", "collisions", "plan_length"} <= set(loop)
    json.dumps(loop), json.dumps(geo)  # plain JSON
    assert geo["first_plan"] == ["move a -> tray at (0.500, 0.100)"]
    assert geo["moves"][1] == {
        "move": "move b -> tray",
        "grasp": "",
        "ok": False,
        "failure": "collision",
        "evidence": {"phase": "lift"},
    }
    assert (geo["motion_failures"], geo["collisions"], geo["plan_length"]) == (1, 0, 1)
    assert (loop["motion_failures"], loop["collisions"], loop["planner"]) == (1, 1, "soft")


def test_the_counts_come_from_the_moves_and_contacts():
    geo = _geo_report()
    assert geo.motion_failures == 1  # an unexpected outcome is not a motion failure
    assert geo.plan_length == 1 and not geo.solved_clean
    assert _loop_report().collided and _loop_report().collisions == 1


@pytest.mark.sim
def test_tamp_run_writes_one_report_for_a_problem_a_scene_of_cubes_and_a_region_scene(tmp_path):
    """Three small episodes in PyBullet through ``tamp run --out``: the loop on a PDDL problem,
    the loop on a scene file of cubes, the geometric episode on a scene with a tray."""
    problem = tmp_path / "two.pddl"
    problem.write_text(TWO)
    cubes, tray = tmp_path / "cubes.json", tmp_path / "tray.json"
    cubes.write_text(json.dumps(scene(cube("a", 0.4, -0.16, 0.025), cube("b", 0.4, 0.16, 0.025))))
    tray.write_text(json.dumps(scene(cube("a", 0.45, -0.2, 0.025), regions=[TRAY])))
    runs = {
        "problem": [str(problem)],
        "cubes": ["--scene", str(cubes), "--goal", "(on a b)"],
        "region": ["--scene", str(tray), "--goal", "(in a tray)"],
    }
    bodies = {}
    for name, argv in runs.items():
        out = tmp_path / name
        assert main(["run", *argv, "--out", str(out), "--no-video", "--json"]) == 0, name
        bodies[name] = json.loads((out / "report.json").read_text())
    keys = {name: set(body) for name, body in bodies.items()}
    assert keys["problem"] == keys["cubes"] == keys["region"], keys
    assert {b["sim"] for b in bodies.values()} == {"pybullet"}
    assert [b["planner"] for b in bodies.values()] == ["soft", "soft", "motion-aware"]
    assert all(b["reached_goal"] and b["status"] == "goal_reached" for b in bodies.values())
    assert bodies["region"]["config"]["executor"] == "geometric"
