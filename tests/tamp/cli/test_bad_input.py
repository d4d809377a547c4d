"""Bad input as a new user gives it: every option bounded to what the machine can do, outputs
checked before any work, Ctrl-C at any moment, a file that is not a checkpoint: one line each
(exit 2, or 130 for Ctrl-C), never a traceback, a crash or a hang."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import tamp.cli.parser
from tamp.bench import planning
from tamp.cli import main
from task import data
from tests.cli_check import one_line_error

DOMAIN = data.DOMAIN_FILE


@pytest.fixture
def files(tmp_path):
    domain = tmp_path / "domain.pddl"
    domain.write_text(data.read_text(data.DOMAIN_FILE))
    problem = tmp_path / "problem.pddl"
    problem.write_text(data.read_text(data.EXAMPLE_FILE))
    return str(domain), str(problem)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["run", "--seed", "-1"], "--seed: expected a seed in [0, 4294967295]"),
        (["bench", "executability", "--plans", "x.csv", "--seed", "-1"], "a seed in"),
        (["plan-images", "a.png", "b.png", "--threads", "100000"], "count of threads"),
        (["plan", "d", "p", "--horizon", "1000000"], "window length in [1, 64]"),
        (["plan", "d", "p", "--restarts", "100000000"], "[1, 4096]"),
        (["run", "--observe", "camera", "--blur", "100000"], "blur radius in pixels in [0, 64]"),
        (["bench", "random", "--blocks", "100000"], "[1, 200]"),
        (["bench", "motion", "--workers", "100000"], "count of threads"),
        (["bench", "planbench", "--horizon", "3,1000"], "[1, 64]"),
    ],
)
def test_options_beyond_the_machine_are_one_line_usage_errors(capsys, argv, needle):
    assert main(argv) == 2
    assert needle in one_line_error(capsys)


def test_a_motion_benchmark_of_zero_episodes_is_refused(capsys):
    argv = ["bench", "motion", "--blocks", "100", "--n", "1", "--sim", "pybullet"]
    assert main([*argv, "--no-progress"]) == 2
    assert "--blocks 100: none of 100 random 100-block problems fits" in one_line_error(capsys)


def test_more_instances_than_the_data_have_is_refused(capsys, planbench_dir):
    argv = ["bench", "planbench", "--data", str(planbench_dir / "blocksworld"), "--limit", "601"]
    assert main(argv) == 2
    assert "asked for 601 instances" in one_line_error(capsys)


def test_outputs_are_checked_before_the_work(capsys, files, tmp_path, monkeypatch):
    def no_work(*args, **kw):
        raise AssertionError("planned before checking --out")

    monkeypatch.setattr(planning, "run", no_work)
    existing = tmp_path / "existing.txt"
    existing.write_text("keep me")
    argv = ["bench", "random", "--blocks", "3", "--n", "1", "--out", str(existing)]
    assert main(argv) == 2
    assert "is a file; give a folder" in one_line_error(capsys)
    assert existing.read_text() == "keep me"
    monkeypatch.setattr("tamp.cli.plan.plan", no_work)
    assert main(["plan", *files, "--out", str(tmp_path)]) == 2
    assert "is a folder; give a file name" in one_line_error(capsys)
    assert main(["run", "--out", str(existing), "--no-video"]) == 2
    assert "is a file; give a folder" in one_line_error(capsys)


def test_ctrl_c_while_the_command_loads_is_one_line_and_130(capsys, monkeypatch):
    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(tamp.cli.parser, "build_parser", interrupted)
    assert main(["plan", "d", "p"]) == 130
    assert capsys.readouterr().err == "tamp: interrupted\n"


def test_ctrl_c_in_a_benchmark_writes_what_is_done_marked_partial(capsys, tmp_path, monkeypatch):
    real = planning.run_once
    calls = []

    def run_once(*args, **kw):
        if calls:
            raise KeyboardInterrupt  # during the second seed's run
        calls.append(1)
        return real(*args, **kw)

    monkeypatch.setattr(planning, "run_once", run_once)
    out = tmp_path / "out"
    argv = ["bench", "random", "--blocks", "3", "--n", "2", "--seeds", "2", "--out", str(out)]
    assert main([*argv, "--restarts", "4", "--iters", "20", "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert "interrupted after 2 of 4 plans" in err and "marked partial" in err
    report = json.loads((out / "results.json").read_text())
    assert report["partial"] == {"done": 2, "of": 4, "complete_runs": 1, "interrupted": True}
    assert report["config"]["seeds"] == 2
    assert len((out / "instances.csv").read_text().strip().splitlines()) == 1 + 2


def test_ctrl_c_inside_a_batched_run_keeps_the_rows_already_final(capsys, tmp_path, monkeypatch):
    """A batched run's results come a shape group at a time: Ctrl-C in the second group
    keeps the first group's rows (not the 0 a run kept before it was complete)."""
    real = planning.plan_batch

    def plan_batch(problems, config, seed, progress=None, on_result=None, **kw):
        if on_result is None:  # the untimed warm-up
            return real(problems, config, seed, progress, **kw)
        kept = []

        def then_interrupt(i, result):
            on_result(i, result)
            kept.append(i)
            if len(kept) == 2:  # the first shape group (the 3-block problems) is final
                raise KeyboardInterrupt

        return real(problems, config, seed, progress, on_result=then_interrupt, **kw)

    monkeypatch.setattr(planning, "plan_batch", plan_batch)
    out = tmp_path / "out"
    argv = ["bench", "random", "--blocks", "3,4", "--n", "2", "--out", str(out)]
    assert main([*argv, "--restarts", "4", "--iters", "20", "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert "interrupted after 2 of 4 plans" in err and "marked partial" in err
    report = json.loads((out / "results.json").read_text())
    assert report["partial"] == {"done": 2, "of": 4, "complete_runs": 0, "interrupted": True}
    rows = (out / "instances.csv").read_text().strip().splitlines()
    assert rows[0].split(",") == list(planning.INSTANCE_COLUMNS)
    assert [r.split(",")[1] for r in rows[1:]] == ["3", "3"]


@pytest.mark.parametrize(
    "argv",
    [
        ["perception", "eval", "data.npz"],
        ["bench", "perception"],
        ["run", "--observe", "camera"],
        ["bench", "latplan", "--modes", "frozen"],
    ],
)
def test_a_file_that_is_not_a_checkpoint_is_one_line(capsys, tmp_path, argv):
    """torch's several-line message for a file it cannot unpickle becomes one line (the
    perception loader's own TampError, or the CLI's catch of the exception family)."""
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"\x00garbage, not a torch file" * 10)
    assert main([*argv, "--checkpoint", str(bad)]) == 2
    line = one_line_error(capsys)
    assert str(bad) in line and "not a perception checkpoint" in line


def test_an_empty_plan_is_exit_1_in_validate(capsys, files, tmp_path):
    """An empty plan file is a plan that does not reach the goal: `validate`'s verdict, exit 1
    (`run --plan` has nothing to execute: bad input, test_an_empty_plan_file_to_run_is_exit_2)."""
    empty = tmp_path / "empty.plan"
    empty.write_text("; nothing\n")
    assert main(["validate", *files, str(empty)]) == 1
    assert capsys.readouterr().out.startswith("NON_GOAL_REACHING")


@pytest.mark.parametrize("text", ["", "; nothing\n; cost = 0 (unit cost)\n"])
def test_an_empty_plan_file_to_run_is_exit_2(capsys, files, tmp_path, text):
    """`run --plan EMPTY` ran a whole episode (exit 1); docs/guide/evaluating.md promises a
    one-line error, exit 2, before any simulator starts."""
    empty = tmp_path / "empty.plan"
    empty.write_text(text)
    out = tmp_path / "out"
    argv = ["run", files[1], "--plan", str(empty), "--no-video", "--out", str(out)]
    assert main(argv) == 2
    assert f"{empty}: the plan is empty (no action or move lines)" in one_line_error(capsys)


@pytest.mark.parametrize(
    ("typo", "needle"),
    [
        ("(shiny d)", "unknown predicate 'shiny' (valid: clear, handempty"),
        ("(on a z)", "'z' (valid: a, b, c, d, e)"),
    ],
)
def test_a_typo_in_the_goal_is_exit_2_not_unsolvable(capsys, files, tmp_path, typo, needle):
    """`tamp plan` read a goal typo as an unsolvable problem (exit 1); the same typo in :init
    was bad input (exit 2). Both are now."""
    text = data.read_text(data.EXAMPLE_FILE)
    goal = text.index(":goal")
    for where, edited in (
        ("goal", text[:goal] + text[goal:].replace("(and", f"(and {typo}", 1)),
        ("init", text.replace("(handempty)", f"(handempty) {typo}", 1)),
    ):
        problem = tmp_path / f"{where}.pddl"
        problem.write_text(edited)
        assert main(["plan", files[0], str(problem)]) == 2
        line = one_line_error(capsys)
        assert f"{where} atom {typo}" in line and needle in line


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
@pytest.mark.parametrize(
    "argv",
    [
        ["plan", "DOMAIN", "PROBLEM", "--out", "/proc/x", "--improve", "10"],
        ["bench", "random", "--blocks", "3", "--n", "1", "--out", "/proc/x/y"],
        ["run", "--no-video", "--out", "/proc/x/y"],
        ["example", "--out", "/proc/x"],
    ],
)
def test_an_out_path_that_cannot_be_created_is_refused_before_the_work(
    capsys, files, monkeypatch, argv
):
    """Under /proc nothing can be created, though a permission check passes for root: `plan
    --out /proc/x` threw away its planning, `bench planbench --out /proc/x/y` planned all its
    instances, then failed. The path is now tried (created and written, then removed) first."""

    def no_work(*args, **kw):
        raise AssertionError("worked before checking --out")

    monkeypatch.setattr("tamp.cli.plan.plan", no_work)
    monkeypatch.setattr(planning, "run", no_work)
    monkeypatch.setattr("tamp.cli.run.Episode", no_work)
    given = [{"DOMAIN": files[0], "PROBLEM": files[1]}.get(a, a) for a in argv]
    assert main(given) == 2
    assert "cannot be created or written" in one_line_error(capsys)


def test_an_out_path_is_tried_and_left_as_it_was(tmp_path):
    from tamp.cli.recorded import out_file, out_folder

    out_folder(str(tmp_path / "a" / "b"))
    out_file(str(tmp_path / "c" / "plan.txt"))
    assert list(tmp_path.iterdir()) == []
