"""The ``tamp`` command line through ``main(argv)``: plan, validate, demo, bench, bad input."""

from __future__ import annotations

import csv
import json

import pytest

from tamp.cli import main
from tamp.cli import plan as commands
from task import data
from task.domains import blocksworld
from task.problem import Plan, PlanResult, PlanStatus
from task.symbolic.generate import random_problem
from tests.cli_check import one_line_error

FAST = ["--restarts", "8", "--iters", "60"]
ARTEFACTS = ("instances.csv", "results.json", "steps.png")


@pytest.fixture
def files(tmp_path):
    """The embedded domain and a generated 5-block problem written as PDDL."""
    domain = tmp_path / "domain.pddl"
    domain.write_text(data.read_text(data.DOMAIN_FILE))
    problem = tmp_path / "problem.pddl"
    problem.write_text(blocksworld.to_pddl(random_problem(5, seed=3)))
    return domain, problem


def test_example_plans_validates_and_writes_files(capsys, tmp_path):
    assert main(["example", *FAST, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for text in ("initial", "goal", "move(", "PDDL plan", "; cost = ", "VALID: valid plan of"):
        assert text in out
    names = (data.DOMAIN_FILE, data.EXAMPLE_FILE, "example-5.plan")
    assert main(["validate", *(str(tmp_path / n) for n in names)]) == 0
    assert capsys.readouterr().out.startswith("VALID")


def test_plan_generated_problem_writes_a_valid_plan_file(capsys, files, tmp_path):
    plan_file = tmp_path / "out" / "plan.txt"
    assert main(["plan", *map(str, files), *FAST, "--out", str(plan_file)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[-1].startswith("VALID: valid plan of")
    assert plan_file.read_text() in out
    assert main(["validate", *map(str, files), str(plan_file)]) == 0


def test_plan_json_parses(capsys, files):
    import torch

    before = torch.get_num_threads()
    argv = ["plan", *map(str, files), *FAST, "--horizon", "2", "--threads", "2", "--json"]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["status"] == "solved" and report["valid"]
    assert len(report["actions"]) == 2 * len(report["moves"]) == report["validation"]["length"]
    assert report["config"]["horizon"] == 2 and report["config"]["restarts"] == 8
    assert report["config"]["threads"] == 2 and torch.get_num_threads() == before  # restored


def test_plan_motion_aware_prices_the_arm_and_refuses_other_domains(
    capsys, files, tmp_path, monkeypatch
):
    """The arm's costs reach the planner (a cost source that prices the laid-out problem's
    moves unequally, weighted by lambda_motion) and the printed plan is the priced one."""
    import tamp.slots
    from task.planner import plan as real_plan

    priced = []

    def spy(problem, config, seed=0, costs=None, **kw):
        result = real_plan(problem, config, seed=seed, costs=costs, **kw)
        priced.append((problem, config, costs, result))
        return result

    monkeypatch.setattr(tamp.slots, "plan", spy)
    files[1].write_text(data.read_text(data.EXAMPLE_FILE))  # unstacks onto the table
    args = ["plan", *map(str, files), *FAST, "--motion-aware", "--scene", "shelf", "--json"]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["status"] == "solved" and report["valid"]
    assert report["config"]["lambda_motion"] == 0.05
    ((problem, config, costs, result),) = priced
    assert config.lambda_motion == 0.05 and costs is not None
    matrix = costs([0], [problem.init]).compute()  # (1, N, Y): the arm's cost of each move
    assert matrix.shape[:2] == (1, problem.n) and float(matrix.std()) > 0
    assert [m[0] for m in report["moves"]] == [m.entity for m in result.plan.moves]
    onto_table = [m for m in report["moves"] if m[1] == "table"]
    assert onto_table and all(len(m) == 3 and len(m[2]) == 2 for m in onto_table)  # its place
    places = {tuple(m[2]) for m in onto_table}
    assert len(places) == len(onto_table)  # the example's blocks stay apart: one place each
    assert main(["plan", *map(str, files), *FAST, "--motion-aware"]) == 0
    assert "table places (m, base frame):" in capsys.readouterr().out
    gripper = tmp_path / "gripper.pddl"  # a STRIPS domain: not blocks on a table
    gripper.write_text(
        "(define (domain g) (:requirements :strips) (:predicates (at ?b) (held ?b) (free))\n"
        " (:action pick :parameters (?b) :precondition (and (at ?b) (free))"
        " :effect (and (held ?b) (not (at ?b)) (not (free)))))"
    )
    problem = tmp_path / "g1.pddl"
    problem.write_text(
        "(define (problem g1) (:domain g) (:objects b1) (:init (at b1) (free))"
        " (:goal (and (held b1))))"
    )
    assert main(["plan", str(gripper), str(problem), "--motion-aware"]) == 2
    assert "blocksworld problems on a table" in one_line_error(capsys)


def test_plan_without_a_plan_exits_1(capsys, files, monkeypatch):
    def no_plan(problem, config, seed, costs=None, deadline=None):
        return PlanResult(PlanStatus.NO_PLAN, Plan(), problem, None, {"windows": 12, "time_s": 1})

    monkeypatch.setattr(commands, "plan", no_plan)
    assert main(["plan", *map(str, files)]) == 1
    assert capsys.readouterr().out.startswith("no plan found within 40 windows: goal not reached")


def test_validate_names_the_first_failing_step(capsys, files, tmp_path):
    plan = tmp_path / "bad.plan"
    plan.write_text("(stack a b)\n")
    assert main(["validate", *map(str, files), str(plan)]) == 1
    assert capsys.readouterr().out.startswith("INEXECUTABLE: step 1 (stack a b): precondition")
    plan.write_text("")
    assert main(["validate", *map(str, files), str(plan), "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["status"] == "non_goal_reaching" and not report["valid"]


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["plan", "{domain}", "{missing}"], "no such file"),
        (["plan", "{domain}", "{malformed}"], "parse error"),
        (["validate", "{domain}", "{problem}", "{missing}"], "no such file"),
        (["frobnicate"], "invalid choice: 'frobnicate'"),
        ([], "required: COMMAND"),
        (["plan", "{domain}", "{problem}", "--horizon", "x"], "--horizon"),
        (["plan", "{domain}", "{problem}", "--horizon", "0"], "window length in [1, 64]"),
        (["plan", "{domain}", "{problem}", "--goal-loss", "l2"], "invalid choice: 'l2'"),
        (["bench", "planbench", "--horizon", "1,x"], "comma-separated"),
        (["bench", "planbench", "--data", "{missing}"], "PlanBench blocksworld data not found"),
        (["bench", "random", "--blocks", "1"], "at least 2 blocks"),
        (["bench"], "required: SUITE"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, files, tmp_path, argv, expected):
    malformed = tmp_path / "malformed.pddl"
    malformed.write_text("(define (problem x")
    paths = {
        "domain": files[0],
        "problem": files[1],
        "missing": tmp_path / "nope",
        "malformed": malformed,
    }
    assert main([a.format(**paths) for a in argv]) == 2
    assert expected in one_line_error(capsys)


def test_help_exits_0(capsys):
    assert main(["--help"]) == 0
    assert "plan" in capsys.readouterr().out


def _bench_artefacts(out, n: int) -> tuple[list[dict], dict]:
    """Check a planning benchmark's files in ``out`` against each other; (CSV rows, JSON).

    ``n`` instances, one horizon and one seed: every plan valid and no shorter than its optimum
    (lengths in 4-op actions), and the JSON summaries counting exactly what the CSV holds."""
    assert all((out / name).stat().st_size > 0 for name in ARTEFACTS)
    assert (out / "steps.png").read_bytes().startswith(b"\x89PNG")
    with (out / "instances.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == n and len({r["instance"] for r in rows}) == n
    assert [r["status"] for r in rows] == ["valid"] * n, rows
    lengths = [(int(r["length"]), int(r["optimal"])) for r in rows]
    assert all(ours >= best > 0 and ours % 2 == 0 for ours, best in lengths), lengths
    report = json.loads((out / "results.json").read_text())
    assert report["instances"] == n
    (summary,) = report["summary"]  # one horizon, one seed: no mean row
    assert (summary["n"], summary["known"], summary["valid"]) == (n, n, n)
    assert summary["optimal"] == sum(ours == best for ours, best in lengths)
    assert summary["inexecutable"] == summary["non_goal_reaching"] == summary["no_plan"] == 0
    times = [float(r["time_s"]) for r in rows]
    assert summary["time_s"] == pytest.approx(sum(times) / n, abs=1e-3)
    per_block = {int(b["size"]): b for b in report["by_size"]}
    assert sorted(per_block) == sorted({int(r["size"]) for r in rows})
    for blocks, row in per_block.items():
        mine = [(o, b) for (o, b), r in zip(lengths, rows, strict=True) if int(r["size"]) == blocks]
        assert row["n"] == row["valid"] == len(mine)
        assert row["optimal"] == sum(o == b for o, b in mine)
    return rows, report


@pytest.mark.shared
def test_bench_planbench_plans_every_instance_validly(capsys, planbench_dir, tmp_path):
    argv = ["bench", "planbench", "--data", str(planbench_dir / "blocksworld"), "--limit", "6"]
    argv += ["--seeds", "1", *FAST, "--out", str(tmp_path), "--json", "--no-progress"]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    rows, report = _bench_artefacts(tmp_path, 6)
    assert [int(r["size"]) for r in rows] == [3, 4, 4, 4, 4, 5]
    for key in ("instances", "summary", "by_size", "config", "speed"):
        assert printed[key] == report[key], key


def test_bench_random_plans_every_instance_validly(capsys, tmp_path):
    argv = ["bench", "random", "--blocks", "3,4", "--n", "2", *FAST, "--out", str(tmp_path)]
    assert main([*argv, "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("random: 4 instances") and "by block count" in out
    rows, report = _bench_artefacts(tmp_path, 2 * 2)  # block counts x --n
    assert [r["size"] for r in rows] == ["3", "3", "4", "4"]
    assert report["benchmark"] == "random" and "4/4" in out  # the printed table: 4 of 4 valid


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "--sim", "gazebo"],
        ["run", "--inject", "drop:2"],
        ["run", "--inject", "explode:0.1"],
        ["run", "missing-problem.pddl", "--no-video"],
        ["bench", "motion", "--sim", "gazebo"],
        ["bench", "motion", "--data", "/nonexistent/planbench", "--n", "2"],
    ],
)
def test_bad_run_and_motion_arguments_exit_2_with_one_line(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error" in err[0]


def test_plan_with_a_time_limit_says_how_far_it_got(capsys, files):
    assert main(["plan", *map(str, files), "--time-limit", "1e-9"]) == 1
    out = capsys.readouterr().out
    assert out.startswith("no plan found within the time limit: stopped at the 1e-09 s time")
    assert main(["plan", *map(str, files), "--time-limit", "0"]) == 2
    assert "expected seconds > 0" in capsys.readouterr().err


def test_plan_motion_aware_says_a_goal_tower_too_tall_for_the_scene_is_unsolvable(capsys, tmp_path):
    """Eight blocks stacked into one tower: the scene's towers take seven, so motion-aware
    planning answers ``unsolvable: REASON`` (exit 1) at once; task-only planning plans it."""
    import itertools

    from task.problem import TABLE, Problem

    names = tuple("abcdefgh")
    eight = Problem("tall8", "blocksworld", names, (TABLE,) * 8, tuple(itertools.pairwise(names)))
    domain, problem = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    domain.write_text(data.read_text(data.DOMAIN_FILE))
    problem.write_text(blocksworld.to_pddl(eight))
    assert main(["plan", str(domain), str(problem), "--motion-aware"]) == 1
    out = capsys.readouterr().out
    assert out == (
        "unsolvable: the goal stacks 8 blocks in one tower; this scene's towers take at most 7 "
        "(SceneConfig.max_height)\n"
    )
    assert main(["plan", str(domain), str(problem), *FAST]) == 0


def test_tamp_run_runs_its_episode_on_one_torch_thread(monkeypatch):
    """The thread count is the edge's choice: ``tamp run`` runs the episode on one thread
    (the episode itself leaves the setting alone) and restores the caller's afterwards."""
    import torch

    from task.errors import TampError

    seen = []

    class Stop:
        def __init__(self, *args, **kwargs):
            pass

        def run(self):
            seen.append(torch.get_num_threads())
            raise TampError("stopped here")

    monkeypatch.setattr("tamp.cli.run.Episode", Stop)
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        code = main(["run", "--json"])
        after = torch.get_num_threads()
    finally:
        torch.set_num_threads(before)
    assert code == 2 and seen == [1] and after == 2


def test_an_episode_of_no_moves_prints_no_time_per_move():
    """'0.00 s per move' was printed for an episode that made no move."""
    from types import SimpleNamespace

    from tamp.cli.run import summary_lines

    report = SimpleNamespace(
        steps=(),
        problem="p",
        sim="pybullet",
        status=SimpleNamespace(value="goal_reached"),
        reason="",
        reached_goal=True,
        moves=(),
        replans=0,
        faults=(),
        sim_time_s=0.0,
        wall_time_s=0.5,
        plan_time_s=0.1,
    )
    assert "per move" not in summary_lines(report)[-1]
    report.moves = (SimpleNamespace(ok=True), SimpleNamespace(ok=False))
    assert "(0.25 s per move, 0.0x real time)" in summary_lines(report)[-1]
