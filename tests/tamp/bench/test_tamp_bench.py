"""``tamp bench tamp``: the canonical problems, planners side by side (tamp.bench.geo)."""

from __future__ import annotations

import csv
import json

import pytest

from tamp.bench.geo import run as bench
from tamp.bench.tables import tamp_table
from tamp.cli import main
from tamp.cli.bench.options import TAMP_PROBLEMS
from tamp.modes import GeoPlanner, Observation
from task.errors import TampError


def test_the_parser_names_what_the_library_has():
    from tamp.world.canonical import PROBLEMS

    assert TAMP_PROBLEMS == PROBLEMS
    assert set(bench.PLANNERS) <= set(GeoPlanner)
    from tamp.cli import build_parser

    run = build_parser()._subparsers._group_actions[0].choices["run"]
    scene = next(a for a in run._actions if a.dest == "scene")
    assert all(name in scene.help for name in PROBLEMS)  # tamp run --scene NAME
    geo = next(a for a in run._actions if a.dest == "geo_planner")
    assert geo.choices == [m.value for m in GeoPlanner]  # tamp run --geo-planner, ours first


def test_an_item_holds_its_planner_and_sensor_as_modes_and_refuses_unknown_names():
    item = bench.Item("blocked", 0, "motion-aware", "pybullet", 0, observe="camera")
    assert item.planner is GeoPlanner.MOTION_AWARE and item.observe is Observation.CAMERA
    with pytest.raises(TampError, match=r"^unknown planner 'ours' \(valid: motion-aware, "):
        bench.Item("blocked", 0, "ours", "pybullet", 0)


def test_items_give_every_planner_and_simulator_the_same_variants(tmp_path):
    todo = bench.items(("blocked", "tall"), 2, ("soft", "search"), ("pybullet", "mujoco"), 5)
    assert len(todo) == 2 * 2 * 2 * 2
    for problem in ("blocked", "tall"):
        variants = {(i.planner, i.sim): [] for i in todo}
        for i in todo:
            if i.problem == problem:
                variants[(i.planner, i.sim)].append((i.variant, i.seed))
        assert len({tuple(v) for v in variants.values()}) == 1  # same scenes and seeds for all
        assert [v for v, _ in next(iter(variants.values()))] == [5, 6]
    assert all(i.video is None for i in todo)
    videos = bench.items(("blocked",), 2, ("soft",), ("pybullet",), 0, tmp_path)
    assert [i.video is not None for i in videos] == [True, False]  # the first variant only


def _row(problem, planner, sim, reached, failures=0, collisions=0, t=1.0):
    return {
        "problem": problem,
        "variant": 0,
        "planner": planner,
        "sim": sim,
        "status": "goal_reached" if reached else "no_plan",
        "reached_goal": reached,
        "clean": reached and failures == 0,
        "plan_length": 3 if reached else 0,
        "moves": 3,
        "motion_failures": failures,
        "replans": 0,
        "collisions": collisions,
        "plan_time_s": t,
        "sim_time_s": 20.0,
        "arm_path_rad": 9.0,
        "wall_time_s": 30.0,
        "reason": "",
        "note": "",
    }


def test_summary_counts_solved_clean_and_collided_per_planner_and_simulator():
    rows = [
        _row("blocked", "soft", "pybullet", False, t=0.1),
        _row("blocked", "soft", "pybullet", True, failures=1, collisions=2, t=0.3),
        _row("blocked", "search", "pybullet", True, t=2.0),
        _row("blocked", "search", "pybullet", True, t=4.0),
    ]
    summary = {(s["planner"], s["sim"]): s for s in bench.summarise(rows)}
    soft, search = summary[("soft", "pybullet")], summary[("search", "pybullet")]
    assert (soft["episodes"], soft["solved"], soft["clean"], soft["collided"]) == (2, 1, 0, 1)
    assert (search["solved"], search["clean"], search["collided"]) == (2, 2, 0)
    assert search["planning_p50_s"] == pytest.approx(3.0)
    assert soft["plan_length"] == 3  # over solved episodes only
    text = tamp_table(bench.summarise(rows), ("pybullet", "mujoco"))
    lines = text.splitlines()
    assert lines[1].split()[:4] == ["blocked", "soft", "1/2", "0/2"]
    assert lines[1].split()[-1] == "-"  # no mujoco rows: not applicable


def test_video_without_out_is_refused_in_one_line(capsys):
    assert main(["bench", "tamp", "--video", "--n", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--out" in err


def test_unknown_problem_is_refused_naming_the_valid_ones(capsys):
    assert main(["bench", "tamp", "--problems", "blocked,stacked"]) == 2
    err = capsys.readouterr().err
    assert "unknown problem 'stacked'" in err and "nonmonotonic" in err


@pytest.mark.sim
def test_one_episode_writes_results_and_rows(tmp_path):
    out = tmp_path / "out"
    argv = ["bench", "tamp", "--problems", "blocked", "--n", "1", "--sim", "pybullet"]
    assert main([*argv, "--planner", "soft", "--out", str(out), "--no-progress"]) == 0
    body = json.loads((out / "results.json").read_text())
    assert body["config"]["problems"] == ["blocked"] and body["config"]["planners"] == ["soft"]
    (summary,) = body["summary"]
    assert summary["episodes"] == 1 and summary["planner"] == "soft"
    rows = list(csv.DictReader((out / "episodes.csv").open()))
    assert len(rows) == 1 and rows[0]["problem"] == "blocked" and rows[0]["note"]


def test_a_failed_moves_place_and_a_successful_moves_run_notes_reach_the_row():
    from tamp.geo.episode import MoveRecord
    from tamp.outcome import Failure

    where = {"phase": "lift", "other": "p1"}
    hit = MoveRecord("move(a -> b)", "top0", False, Failure.COLLISION, where)
    ik = MoveRecord("move(a -> c)", "", False, Failure.IK_INFEASIBLE, {})
    done = MoveRecord("move(a -> d)", "top0", True, None, {"regrasped": 1, "corrected_mm": 2.5})
    plain = MoveRecord("move(b -> d)", "top0", True, None, {})
    assert bench._failure(hit) == "collision@lift:p1" and bench._failure(ik) == "ik_infeasible"
    assert bench._notes(done) == "move(a -> d){regrasped=1,corrected_mm=2.5}"
    assert bench._notes(plain) == ""
    assert "run_notes" in bench.ROW_COLUMNS


def test_an_episode_that_errs_is_its_own_row_and_the_others_go_on(monkeypatch):
    """One episode's error (a Hanoi disc slid off its peg: the scene is no state of the domain)
    used to end the whole benchmark and lose every row; now it is that episode's row, status
    "error" with the reason, and stays out of the planning-time quantiles."""
    import tamp.geo.episode as episode
    from task.errors import ProblemError

    def fail(*args, **kwargs):
        raise ProblemError("hanoi: initial state holds (ontable d5)")

    monkeypatch.setattr(episode, "run_geo_episode", fail)
    row = bench.play(bench.Item("blocked", 0, "soft", "pybullet", 0))
    assert row["status"] == "error" and "ontable d5" in row["reason"] and not row["reached_goal"]
    assert set(row) == set(bench.ROW_COLUMNS)
    (summary,) = bench.summarise([row, _row("blocked", "soft", "pybullet", True, t=2.0)])
    assert summary["episodes"] == 2 and summary["solved"] == 1
    assert summary["planning_p50_s"] == pytest.approx(2.0)
    assert summary["statuses"]["error"] == 1
