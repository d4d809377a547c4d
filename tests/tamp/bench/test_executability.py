"""``tamp bench executability`` (`tamp.bench.executability.run_given`): plans of any source,
read from a CSV like ../shared/data/planbench/llm_plans, validated at task level and executed
open-loop. A valid plan reaches the goal; an invalid one is task-invalid with its first failure
reported; an unparseable one is a row outcome; a missing --plans path is a one-line error. The
instances run are those the plan files name; our row honours --motion-aware and --placements.
The data are written here: three PDDL instances in the PlanBench layout and a three-row CSV."""

from __future__ import annotations

import csv
import json

import pytest

from tamp.bench import executability as motion
from tamp.bench.suites import planbench
from tamp.cli import main
from task import data

# b on a, c on the table; goal: the tower c-a-b
PROBLEM = """(define (problem three) (:domain blocksworld-4ops) (:objects a b c)
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a c) (on b a))))
"""
PLANS = {  # instance -> (plan as in the CSVs: actions joined by ';', PlanBench's verdict)
    1: ("(unstack b a);(put-down b);(pick-up a);(stack a c);(pick-up b);(stack b a)", "1"),
    2: ("(pick-up c);(stack c a)", "0"),  # b is on a: (clear a) fails at step 2
    3: ("(unstack a)", "0"),  # malformed, as PlanBench's extraction sometimes gives
}


def _data(tmp_path):
    """A PlanBench-layout folder of 3 instances, and the plans CSV; returns their paths."""
    root = tmp_path / "blocksworld"
    (root / "instances" / "generated_basic_3").mkdir(parents=True)
    (root / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    for k in PLANS:
        (root / "instances" / "generated_basic_3" / f"instance-{k}.pddl").write_text(PROBLEM)
    plans = tmp_path / "model-x.csv"
    with plans.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["file", "llm_correct", "plan", "source", "plan_converted"])
        for k, (plan, flag) in PLANS.items():
            writer.writerow(
                [f"instances/generated_basic_3/instance-{k}.pddl", flag, plan, "upstream", plan]
            )
    return root, plans


def test_sources_are_read_and_checked_at_task_level(tmp_path):
    root, _ = _data(tmp_path)
    sources = motion.read_sources(tmp_path)  # a folder: one source per CSV
    assert list(sources) == ["model-x"]
    assert sources["model-x"]["generated_basic_3/instance-2"] == (PLANS[2][0], False)
    suite = planbench(root, 3)
    got = sources["model-x"]
    checks = [motion.check_given(got[i.name][0], i, suite.domain, "x") for i in suite.instances]
    assert [c[1] for c in checks] == ["valid", "inexecutable", "unparseable"]
    assert "step 2 (stack c a): precondition (clear a) does not hold" in checks[1][2]
    assert checks[2][0] is None and "takes 2 arguments" in checks[2][2]
    assert motion.check_given(None, suite.instances[0], suite.domain, "x")[1] == "no-plan"
    assert "the plan is empty" in motion.check_given("", suite.instances[0], suite.domain, "x")[2]


@pytest.mark.parametrize("where", ["nope.csv", "empty-folder"])
def test_a_missing_plans_path_is_a_one_line_error(tmp_path, capsys, where):
    root, _ = _data(tmp_path)
    (tmp_path / "empty-folder").mkdir()
    argv = ["bench", "executability", "--plans", str(tmp_path / where), "--data", str(root)]
    code = main([*argv, "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and f"--plans {tmp_path / where}" in err


@pytest.mark.sim
def test_valid_invalid_and_unparseable_plans_and_our_reference_row(tmp_path, capsys):
    root, plans = _data(tmp_path)
    out = tmp_path / "out"
    argv = [
        "bench",
        "executability",
        "--plans",
        str(plans),
        "--data",
        str(root),
        "--n",
        "3",
        "--threads",
        "1",
        "--no-progress",
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "model-x" in printed and "ours" in printed and "first failures" in printed
    with (out / "plans.csv").open() as handle:
        rows = {(r["source"], r["problem"][-1]): r for r in csv.DictReader(handle)}
    valid, invalid, bad = (rows["model-x", k] for k in "123")
    assert valid["task"] == "valid" and valid["reached_goal"] == "True"
    assert valid["first_failure"] == "" and valid["moves"] == "3"
    assert invalid["task"] == "inexecutable" and invalid["reached_goal"] == "False"
    assert invalid["first_failure"].startswith("invalid-then-")
    assert invalid["failure_at"].startswith("1-2 (pick-up c) (stack c a)")
    assert bad["task"] == "unparseable" and bad["moves"] == "0" and "takes 2" in bad["error"]
    assert all(rows["ours", k]["reached_goal"] == "True" for k in "123")
    summary = {s["source"]: s for s in json.loads((out / "results.json").read_text())["summary"]}
    x = summary["model-x"]
    assert (x["plans"], x["task_valid"], x["planbench_valid"], x["agree"]) == (3, 1, 1, 3)
    assert x["reached"] == {"pybullet": 1} and summary["ours"]["agree"] is None


def _fake_runs(monkeypatch) -> list:
    """No simulator: every run "reaches the goal"; returns the list the runs' items go to."""
    items = []

    def run_items(fn, runs, workers, ray, done):
        for j, item in enumerate(runs):
            items.append(item)
            done(j, (True, "", "", 0, len(item[1]), 0.0))

    monkeypatch.setattr(motion, "run_items", run_items)
    return items


def _argv(root, plans, out, *more):
    return [
        "bench",
        "executability",
        "--plans",
        str(plans),
        "--data",
        str(root),
        "--threads",
        "1",
        "--no-progress",
        "--out",
        str(out),
        *more,
    ]


def test_the_instances_the_plan_files_name_are_run_and_missing_plans_reported(
    tmp_path, monkeypatch, capsys
):
    """Plans for instances 2 and 3 only: those two run (not a spread of the data), and a
    second source without a plan for 3 gets a no-plan row (the review's 1 and 201 case)."""
    root, _ = _data(tmp_path)
    folder = tmp_path / "plans"
    folder.mkdir()
    for name, ks in (("model-x", (2, 3)), ("model-y", (2,))):
        with (folder / f"{name}.csv").open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["file", "plan"])
            for k in ks:
                writer.writerow([f"instances/generated_basic_3/instance-{k}.pddl", PLANS[1][0]])
    _fake_runs(monkeypatch)
    out = tmp_path / "out"
    assert main(_argv(root, folder, out, "--n", "2", "--no-ours")) == 0
    with (out / "plans.csv").open() as handle:
        rows = {(r["source"], r["problem"]): r["task"] for r in csv.DictReader(handle)}
    two, three = "generated_basic_3/instance-2", "generated_basic_3/instance-3"
    assert rows == {
        ("model-x", two): "valid",
        ("model-x", three): "valid",
        ("model-y", two): "valid",
        ("model-y", three): "no-plan",
    }
    report = json.loads((out / "results.json").read_text())
    assert report["config"]["instances"] == [two, three]
    y = next(s for s in report["summary"] if s["source"] == "model-y")
    assert (y["no_plan"], y["unparseable"]) == (1, 0)
    capsys.readouterr()
    assert main(_argv(root, folder, out, "--n", "100000", "--no-ours")) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--n 100000: the plan files name 2 instances" in err


def test_motion_aware_and_placements_plan_our_row_on_the_table_and_are_recorded(
    tmp_path, monkeypatch, capsys
):
    """--motion-aware plans our row with the arm's costs on each episode's layout: its move
    onto the table carries the place (within --placements of a slot) to the execution."""
    root, plans = _data(tmp_path)
    items = _fake_runs(monkeypatch)
    out = tmp_path / "out"
    argv = _argv(root, plans, out, "--n", "1", "--motion-aware", "--placements", "0.02")
    assert main([*argv, "--restarts", "4", "--iters", "30"]) == 0
    config = json.loads((out / "results.json").read_text())["config"]
    assert (config["lambda_motion"], config["placements"]) == (0.05, 0.02)
    assert config["planner"]["lambda_motion"] == 0.05
    ours = [steps for _, steps, *_ in items if any(getattr(s.move, "at", None) for s in steps)]
    assert len(ours) == 1  # the CSV's plan names no places; ours does
    (placed,) = [s.move for s in ours[0] if s.move.target == "table"]
    assert placed.entity == "b" and len(placed.at) == 2
    assert all(loop.placements == 0.02 for _, _, loop, *_ in items)
    items.clear()
    assert main(_argv(root, plans, out, "--n", "1", "--restarts", "4", "--iters", "30")) == 0
    assert not any(getattr(s.move, "at", None) for _, steps, *_ in items for s in steps)
    capsys.readouterr()
