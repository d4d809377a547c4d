"""``tamp bench pddl --peers``: pyperplan GBF+hFF (and LAMA) beside ours on the same instances.

pyperplan's own runs are skipped when it is not installed (the ``bench`` extra); Fast Downward's
optima and LAMA are switched off here (they belong to the slow tests of test_fast_downward.py).
"""

from __future__ import annotations

import csv
import json

import pytest

from tamp.bench import fast_downward
from tamp.bench.peers import gbf, side_by_side
from tamp.cli import build_parser, main
from task.errors import DataError, TampError

DOMAIN = """(define (domain hops) (:requirements :strips :typing)
(:types place)
(:predicates (at ?p - place) (link ?a - place ?b - place))
(:action hop :parameters (?a - place ?b - place)
 :precondition (and (at ?a) (link ?a ?b))
 :effect (and (at ?b) (not (at ?a)))))
"""
PROBLEM = """(define (problem three) (:domain hops)
(:objects p1 p2 p3 - place)
(:init (at p1) (link p1 p2) (link p2 p3))
(:goal (at p3)))
"""
DEAD_END = PROBLEM.replace("(link p2 p3)", "")


def _folder(tmp_path):
    data = tmp_path / "hops"
    data.mkdir()
    (data / "domain.pddl").write_text(DOMAIN)
    (data / "three.pddl").write_text(PROBLEM)
    return data


def test_peers_option_parses_and_is_recorded():
    argv = ["bench", "pddl", "--data", "x", "--peers", "lama,pyperplan,lama", "--time-limit", "5"]
    args = build_parser().parse_args(argv)
    assert args.peers == ("lama", "pyperplan")
    recorded = args.recorded(args)
    assert recorded["peers"] == ["lama", "pyperplan"]
    assert recorded["batched"] is False  # ours plans one instance at a time, as the peers do
    plain = build_parser().parse_args(["bench", "pddl", "--data", "x", "--time-limit", "5"])
    assert plain.recorded(plain)["peers"] is None
    assert plain.recorded(plain)["batched"] is True


def test_peers_need_a_time_limit():
    args = build_parser().parse_args(["bench", "pddl", "--data", "x", "--peers", "lama"])
    with pytest.raises(TampError, match="--time-limit") as info:
        args.recorded(args)
    assert "\n" not in str(info.value)


def test_unknown_peer_is_refused_listing_the_peers(capsys):
    assert main(["bench", "pddl", "--data", "x", "--peers", "ff", "--time-limit", "5"]) == 2
    err = capsys.readouterr().err.strip()
    assert "'ff'" in err and "pyperplan, lama" in err and "\n" not in err


def test_missing_pyperplan_is_one_line_naming_the_extra(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(gbf, "available", lambda: False)
    monkeypatch.setattr(fast_downward, "available", lambda: False)  # no optima searched
    with pytest.raises(DataError, match=r"soft-tamp\[bench\].*pyperplan") as info:
        gbf.gbf_hff(DOMAIN, PROBLEM, 5)
    assert "\n" not in str(info.value)
    argv = ["bench", "pddl", "--data", str(_folder(tmp_path)), "--peers", "pyperplan"]
    assert main([*argv, "--time-limit", "5", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "pyperplan is not installed" in err and "soft-tamp[bench]" in err
    assert "\n" not in err


def test_missing_fast_downward_is_one_line_naming_the_extra(monkeypatch):
    monkeypatch.setattr(fast_downward, "available", lambda: False)
    with pytest.raises(DataError, match=r"lama.*soft-tamp\[bench\]") as info:
        side_by_side.require(("lama",))
    assert "\n" not in str(info.value)


def test_gbf_hff_plans_a_tiny_strips_problem_and_says_when_there_is_none():
    pytest.importorskip("pyperplan")
    solved = gbf.gbf_hff(DOMAIN, PROBLEM, 60)
    assert (solved.status, solved.length) == ("solved", 2)
    dead = gbf.gbf_hff(DOMAIN, DEAD_END, 60)
    assert (dead.status, dead.length) == ("unsolved", None)


def test_summary_counts_coverage_and_lengths_on_the_common_instances():
    ours = [("a", 4, 1.0), ("b", None, 3.0), ("c", 6, 2.0)]
    peers = [
        side_by_side.PeerRow("a", "pyperplan", "solved", 6, 0.5),
        side_by_side.PeerRow("b", "pyperplan", "solved", 9, 0.5),
        side_by_side.PeerRow("c", "pyperplan", "timeout", None, 2.0),
    ]
    mine, theirs = side_by_side.summarise("d", ours, peers)
    assert (mine.planner, mine.solved, mine.n, mine.mean_length) == ("ours", 2, 3, 5.0)
    assert (theirs.solved, theirs.mean_length, theirs.mean_s) == (2, 7.5, 1.0)
    assert (mine.common, mine.common_length, theirs.common_length) == (1, 4.0, 6.0)
    assert "pyperplan GBF+hFF" in side_by_side.table([mine, theirs])


def test_bench_pddl_runs_pyperplan_beside_ours(tmp_path, monkeypatch, capsys):
    pytest.importorskip("pyperplan")
    monkeypatch.setattr(fast_downward, "available", lambda: False)  # no optima searched
    out = tmp_path / "out"
    argv = ["bench", "pddl", "--data", str(_folder(tmp_path)), "--peers", "pyperplan"]
    argv += ["--time-limit", "60", "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "side by side, 60 s per instance" in printed
    body = json.loads((out / "results.json").read_text())
    lines = {line["planner"]: line for line in body["peers"]["summary"]}
    assert (lines["ours"]["solved"], lines["ours"]["mean_length"]) == (1, 2.0)
    assert (lines["pyperplan"]["solved"], lines["pyperplan"]["mean_length"]) == (1, 2.0)
    assert body["config"]["peers"] == ["pyperplan"]
    with (out / "peers.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["instance"], r["peer"], r["status"], r["length"]) for r in rows] == [
        ("three", "pyperplan", "solved", "2")
    ]
