"""What produced a benchmark's numbers: provenance in ``results.json`` and ``tamp bench record``."""

from __future__ import annotations

import json
import shlex
import subprocess

from tamp.bench import results
from tamp.cli import main


def _git(root, *args: str) -> str:
    done = subprocess.run(
        ["git", "-C", str(root), "-c", "user.name=t", "-c", "user.email=t@t", *args],
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout.strip()


def test_git_state_reads_commit_and_dirty_and_none_outside_a_checkout(tmp_path):
    assert results.git_state(tmp_path) == (None, None)
    _git(tmp_path, "init", "-q")
    assert results.git_state(tmp_path) == (None, None)  # a repository without a commit
    (tmp_path / "a.txt").write_text("a\n")
    _git(tmp_path, "add", "a.txt")
    _git(tmp_path, "commit", "-q", "-m", "a")
    head = _git(tmp_path, "rev-parse", "HEAD")
    assert results.git_state(tmp_path) == (head, False)
    (tmp_path / "b.txt").write_text("untracked\n")
    assert results.git_state(tmp_path) == (head, True)
    (tmp_path / "b.txt").unlink()
    (tmp_path / "a.txt").write_text("changed\n")
    assert results.git_state(tmp_path) == (head, True)
    inner = tmp_path / "inner"  # code inside some other repository is not that repository's
    inner.mkdir()
    assert results.git_state(inner) == (None, None)


def test_a_benchmark_run_records_its_command_commit_and_machine(tmp_path):
    out = tmp_path / "run one"
    argv = ["bench", "random", "--blocks", "3", "--n", "1", "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    record = json.loads((out / "results.json").read_text())["machine"]
    assert record["command"] == "tamp " + shlex.join(argv)
    assert shlex.split(record["command"])[1:] == argv  # quoted: re-runnable as written
    assert (record["commit"], record["dirty"]) == results.git_state()
    assert record["cores"] and record["date"] and record["load_1min"] >= 0


def test_machine_without_a_command_line_records_none():
    assert results.machine()["command"] is None
    assert results.machine(["bench", "x"])["command"] == "tamp bench x"
