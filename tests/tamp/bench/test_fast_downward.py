"""Fast Downward optima (the benchmark-only ``bench`` extra); skipped when it is not installed."""

from __future__ import annotations

import csv
import json
import tempfile
import time
from pathlib import Path

import pytest

from tamp.bench import fast_downward
from tamp.cli import main
from task import data
from task.domains import blocksworld
from task.errors import DataError
from task.symbolic.generate import random_problem
from task.symbolic.search import optimal_moves

_installed = pytest.mark.skipif(
    not fast_downward.available(), reason="needs the bench extra: pip install 'soft-tamp[bench]'"
)


def needs_fd(test):
    """Fast Downward runs only in the slow tests (benchmark-only), and only when installed."""
    return pytest.mark.slow(_installed(test))


_DEAD_END = """(define (problem stuck) (:domain blocksworld-4ops)
(:objects a b)
(:init (handempty) (ontable a) (clear a) (ontable b) (clear b))
(:goal (and (on a b) (on b a))))
"""
_COSTLY_DOMAIN = """(define (domain costly) (:requirements :strips :action-costs)
(:predicates (start) (half) (done))
(:functions (total-cost))
(:action direct :parameters () :precondition (start)
 :effect (and (done) (increase (total-cost) 10)))
(:action first :parameters () :precondition (start) :effect (and (half) (increase (total-cost) 1)))
(:action second :parameters () :precondition (half) :effect (and (done) (increase (total-cost) 1))))
"""
_COSTLY_PROBLEM = """(define (problem costly-1) (:domain costly)
(:init (start) (= (total-cost) 0)) (:goal (done)) (:metric minimize (total-cost)))
"""


def _write_pair(tmp_path, seed: int, n_blocks: int = 3):
    """The embedded domain and a random ``n_blocks`` problem as files; and the problem."""
    problem = random_problem(n_blocks, seed)
    domain_path = tmp_path / "domain.pddl"
    domain_path.write_text(data.read_text(data.DOMAIN_FILE))
    problem_path = tmp_path / f"problem-{seed}.pddl"
    problem_path.write_text(blocksworld.to_pddl(problem))
    return domain_path, problem_path, problem


@needs_fd
def test_optimal_length_matches_blocksworld_astar(tmp_path, monkeypatch):
    domain, problem_path, problem = _write_pair(tmp_path, seed=0)
    (tmp_path / "tmp").mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    result = fast_downward.optimal_length(domain, problem_path, time_limit_s=30)
    assert result.status == "optimal", result.detail
    assert result.length == 2 * len(optimal_moves(problem)) > 0
    assert result.seconds > 0
    assert not any((tmp_path / "tmp").iterdir())  # Fast Downward's files are gone


@needs_fd
def test_length_not_cost_is_minimised(tmp_path):
    """One action of cost 10 beats two of cost 1: the optimum counts actions."""
    (tmp_path / "d.pddl").write_text(_COSTLY_DOMAIN)
    (tmp_path / "p.pddl").write_text(_COSTLY_PROBLEM)
    result = fast_downward.optimal_length(tmp_path / "d.pddl", tmp_path / "p.pddl", 30)
    assert (result.length, result.status) == (1, "optimal")


@needs_fd
def test_unsolvable_is_a_status(tmp_path):
    domain, _, _ = _write_pair(tmp_path, seed=0)
    stuck = tmp_path / "stuck.pddl"
    stuck.write_text(_DEAD_END)
    result = fast_downward.optimal_length(domain, stuck, time_limit_s=30)
    assert (result.length, result.status) == (None, "unsolvable")


@needs_fd
def test_pddl_that_fast_downward_rejects_is_an_error_status(tmp_path):
    domain, problem_path, _ = _write_pair(tmp_path, seed=0)
    result = fast_downward.optimal_length(problem_path, domain, time_limit_s=30)
    assert result.status == "error" and "\n" not in result.detail


@needs_fd
def test_second_run_reads_the_cache(tmp_path, monkeypatch):
    pairs = [_write_pair(tmp_path, seed)[:2] for seed in (1, 2)]
    cache = tmp_path / "fd.json"
    counted = []
    first = fast_downward.optimal_lengths(pairs, cache, 30, progress=counted.append, workers=2)
    assert [r.status for r in first] == ["optimal", "optimal"]
    for seed, result in zip((1, 2), first, strict=True):
        assert result.length == 2 * len(optimal_moves(random_problem(3, seed)))
    assert sum(counted) == 2
    stored = json.loads(cache.read_text())
    assert stored["method"] == fast_downward.METHOD and len(stored["problems"]) == 2

    def no_search(*args):
        raise AssertionError("Fast Downward ran although the cache holds the result")

    monkeypatch.setattr(fast_downward, "_solve", no_search)
    assert fast_downward.optimal_lengths(pairs, cache, 30) == first


@needs_fd
def test_missing_file_is_one_line_data_error(tmp_path):
    with pytest.raises(DataError, match=r"missing\.pddl") as error:
        fast_downward.optimal_length(tmp_path / "missing.pddl", tmp_path / "missing.pddl")
    assert "\n" not in str(error.value)


def test_missing_extra_names_the_install_command(monkeypatch, tmp_path):
    monkeypatch.setattr(fast_downward, "_driver", lambda: None)
    assert not fast_downward.available()
    with pytest.raises(DataError, match=r"soft-tamp\[bench\].*up-fast-downward") as error:
        fast_downward.optimal_length(tmp_path / "d.pddl", tmp_path / "p.pddl")
    assert "\n" not in str(error.value)


def test_wall_clock_guard_kills_the_whole_process_group(tmp_path):
    sleeper = "import subprocess, sys, time; child = subprocess.Popen([sys.executable, '-c', "
    sleeper += "'import time; time.sleep(60)']); open('child', 'w').write(str(child.pid)); "
    sleeper += "time.sleep(60)"
    started = time.monotonic()
    code, _ = fast_downward._call(["-c", sleeper], tmp_path, started + 1.0)
    assert code is None and time.monotonic() - started < 30
    pid = int((tmp_path / "child").read_text())
    for _ in range(200):  # SIGKILL is delivered asynchronously; a busy machine takes a moment
        if _dead(pid):
            break
        time.sleep(0.05)
    assert _dead(pid)


def _dead(pid: int) -> bool:
    """Gone, or a zombie waiting for init to reap it (Linux /proc)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return True
    return stat.rsplit(")", 1)[1].split()[0] in ("Z", "X")


@_installed
def test_lama_plans_a_tiny_problem(tmp_path, monkeypatch):
    """LAMA's first plan (satisficing; under a second): a length no shorter than the optimum."""
    problem = random_problem(4, 5)
    (tmp_path / "tmp").mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    result = fast_downward.lama_length(
        data.read_text(data.DOMAIN_FILE), blocksworld.to_pddl(problem), time_limit_s=20
    )
    assert result.status == "solved", result.detail
    assert result.length % 2 == 0 and result.length >= 2 * len(optimal_moves(problem)) > 0
    assert not any((tmp_path / "tmp").iterdir())  # Fast Downward's files are gone


@_installed
def test_bench_random_puts_lama_beside_ours(tmp_path, capsys):
    argv = ["bench", "random", "--blocks", "3", "--n", "2", "--restarts", "8", "--lama"]
    assert main([*argv, "--one-at-a-time", "--no-progress", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "LAMA moves" in out and "ours/LAMA" in out
    with (tmp_path / "instances.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert all(int(r["lama_length"]) >= int(r["optimal"]) and float(r["lama_s"]) > 0 for r in rows)
    by_size = json.loads((tmp_path / "results.json").read_text())["by_size"]
    assert by_size[0]["lama"] == 2 and by_size[0]["lama_ratio"] >= 1.0
    assert json.loads((tmp_path / "results.json").read_text())["config"]["batched"] is False


def test_bench_random_without_fast_downward_skips_lama(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(fast_downward, "_driver", lambda: None)
    argv = ["bench", "random", "--blocks", "3", "--n", "1", "--restarts", "8", "--lama"]
    assert main([*argv, "--no-progress", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "LAMA skipped: Fast Downward is not installed" in captured.err
    assert "LAMA" not in captured.out
    with (tmp_path / "instances.csv").open(newline="") as handle:
        assert [r["lama_length"] for r in csv.DictReader(handle)] == [""]
