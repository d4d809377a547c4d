"""Benchmark machinery: instance sources, plan checking, summaries, artefacts."""

from __future__ import annotations

import dataclasses
import json

import pytest

from tamp.bench import planning as bench
from tamp.bench import results as bench_io
from tamp.bench import suites, tables
from tamp.bench.planning import Row
from tamp.bench.summary import latency_rows, main_rows, size_rows, summarise
from task import data, instances
from task.config import PlannerConfig
from task.errors import DataError
from task.problem import Move, Plan, PlanResult, PlanStatus
from task.symbolic.search import optimal_moves


def _result(instance, moves, status=PlanStatus.SOLVED):
    return PlanResult(status, Plan(tuple(moves)), instance.problem, None, {})


def test_check_uses_the_pddl_validator():
    domain, inst = instances.example()
    best = optimal_moves(inst.problem)
    assert bench.check(domain, inst, _result(inst, best)) == ("valid", 2 * len(best))
    assert bench.check(domain, inst, _result(inst, best[:2])) == ("non_goal_reaching", 4)
    assert bench.check(domain, inst, _result(inst, [Move("a", "c")])) == ("inexecutable", 2)
    assert bench.check(domain, inst, _result(inst, [], PlanStatus.NO_PLAN)) == ("no_plan", None)


@pytest.mark.parametrize("limit", [1, 4, 7, 10, None])
def test_spread_is_stratified_and_deterministic(limit):
    items = [3] * 10 + [4] * 40 + [5] * 10
    chosen = suites.spread(list(enumerate(items)), limit, key=lambda x: x[1])
    assert len(chosen) == (limit or len(items))
    assert chosen == suites.spread(list(enumerate(items)), limit, key=lambda x: x[1])
    if limit and limit >= 4:
        assert {b for _, b in chosen} == {3, 4, 5}


def test_summaries_follow_the_paper_format():
    def row(seed, status, length, optimal=4, blocks=3):
        return Row("i", blocks, optimal, None, 3, seed, length, status, 0.5, 1)

    seed0 = (row(0, "valid", 4), row(0, "valid", 6), row(0, "no_plan", None, blocks=4))
    seed1 = (row(1, "valid", 4), row(1, "valid", 4), row(1, "inexecutable", 8, None, 4))
    runs = (bench.Run(3, 0, 1.5, seed0), bench.Run(3, 1, 2.5, seed1))
    result = bench.Bench("t", "synthetic", 3, PlannerConfig(), (0, 1), (3,), runs)
    first, second, mean = main_rows(result)
    assert (first.valid, first.optimal, first.optimal_pct, first.no_plan) == (2, 1, 50.0, 1)
    assert (second.known, second.optimal_pct, second.inexecutable) == (2, 100.0, 1)
    assert (mean.seed, mean.valid, mean.optimal_pct, mean.wall_s) == (None, 2.0, 75.0, 2.0)
    by_blocks = {s.size: s for s in size_rows(result)}
    assert by_blocks[3].valid == 2 and by_blocks[4].valid == 0 and by_blocks[4].optimal_pct is None
    assert summarise((), 3, 0, None, None).optimal_pct is None


def test_run_ablation_sequential_and_artefacts(tmp_path):
    suite = suites.generated([3, 4], n=2, seed=1)
    assert [i.name for i in suite.instances] == [
        i.name for i in suites.generated([3, 4], 2, seed=1).instances
    ]
    assert all(i.optimal is not None for i in suite.instances)
    done = []
    config = PlannerConfig(restarts=4, iters=40)
    result = bench.run(suite, config, (0, 1), (1, 3), sequential=2, progress=done.append)
    assert sum(done) == bench.total(4, 2, 2, 2) == 20
    assert [(r.horizon, r.seed) for r in result.runs] == [(1, 0), (1, 1), (3, 0), (3, 1)]
    assert len(main_rows(result)) == 6 and len(size_rows(result)) == 4
    rows = result.rows()
    assert len(rows) == 4 * 4 and {r.instance for r in rows} == {i.name for i in suite.instances}
    assert all(r.status == "valid" for r in rows), [(r.instance, r.status) for r in rows]
    assert all(r.optimal <= r.length and r.length % 2 == 0 for r in rows)  # 4-op actions
    assert [run.valid() for run in result.runs] == [4] * 4
    assert all(s.valid == 4 for s in main_rows(result))  # per (horizon, seed) and their mean
    speed = result.speed  # fields agree with each other; how fast is for the benchmarks
    assert (speed.n, speed.horizon, speed.seed) == (2, 1, 0)
    assert speed.batched_valid == speed.sequential_valid == speed.n
    assert speed.batched_s > 0 and speed.sequential_s > 0
    assert speed.speedup == pytest.approx(speed.sequential_s / speed.batched_s)
    q = speed.latency_s  # per-problem planning latency of the one-at-a-time run
    assert 0 < q["p50"] <= q["p90"] <= q["max"] <= speed.sequential_s
    paths = bench_io.write(result, tmp_path / "out")
    report = json.loads(paths[1].read_text())
    assert report["config"]["restarts"] == 4 and report["horizons"] == [1, 3]
    assert report["machine"]["cores"] and report["instances"] == 4
    assert report["speed"] == {**dataclasses.asdict(speed), "speedup": speed.speedup}
    assert [s["valid"] for s in report["summary"]] == [4] * 6
    assert len(paths[0].read_text().splitlines()) == 1 + 4 * 4
    assert paths[2].read_bytes().startswith(b"\x89PNG")


def test_missing_planbench_data_is_one_line(tmp_path):
    with pytest.raises(DataError, match=r"PlanBench blocksworld data not found at .*karthikv792"):
        suites.planbench(tmp_path / "missing")


def test_manifest_without_columns_is_named(tmp_path):
    (tmp_path / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    (tmp_path / "manifest.csv").write_text("file,n_blocks\n")
    (tmp_path / "instances").mkdir()
    with pytest.raises(DataError, match="missing column"):
        suites.planbench(tmp_path)


@pytest.mark.shared
def test_planbench_official_600(planbench_dir):
    suite = suites.planbench(planbench_dir / "blocksworld")
    counts = {b: sum(i.blocks == b for i in suite.instances) for b in (3, 4, 5)}
    assert counts == {3: 100, 4: 445, 5: 55}
    assert all(i.optimal is not None and i.optimal % 2 == 0 for i in suite.instances)
    limited = suites.planbench(planbench_dir / "blocksworld", limit=6)
    assert [i.blocks for i in limited.instances] == [3, 4, 4, 4, 4, 5]


def test_lengths_are_summarised_against_the_optimum_and_lama():
    def row(length, optimal, lama, status="valid"):
        return Row("i", 5, optimal, None, 3, 0, length, status, 0.5, 1, lama, 0.25)

    rows = (row(6, 6, 8), row(12, 8, 8), row(None, 4, None, "no_plan"))
    result = bench.Bench(
        "t", "synthetic", 3, PlannerConfig(), (0,), (3,), (bench.Run(3, 0, 1.0, rows),)
    )
    (s,) = size_rows(result)
    assert (s.length, s.ratio, s.lama, s.lama_length) == (9.0, 1.25, 2, 8.0)
    assert (s.lama_s, s.vs_lama) == (0.25, 1.125) and s.lama_ratio == pytest.approx(7 / 6)
    text = tables.lengths_table(result)
    assert "LAMA moves" in text and "2/3" in text and "4.50" in text  # 9 actions = 4.5 moves
    bare = tuple(dataclasses.replace(r, lama_length=None, lama_s=None) for r in rows)
    assert summarise(bare, 3, 0, None, None).lama is None  # LAMA did not run
    without = dataclasses.replace(result, runs=(bench.Run(3, 0, 1.0, bare),))
    assert "LAMA" not in tables.lengths_table(without)


def test_one_at_a_time_runs_report_latency_percentiles_per_size():
    def row(size, seconds):
        return Row("i", size, None, None, 3, 0, 4, "valid", seconds, 1)

    rows = (*(row(5, 0.1 * k) for k in range(1, 11)), row(10, 2.0))
    alone = bench.Bench(
        "t",
        "synthetic",
        11,
        PlannerConfig(batched=False),
        (0,),
        (3,),
        (bench.Run(3, 0, 1.0, rows),),
    )
    five, ten = latency_rows(alone)
    assert (five["size"], five["n"], five["max"]) == (5, 10, pytest.approx(1.0))
    assert (five["p50"], five["p90"]) == (pytest.approx(0.6), pytest.approx(1.0))
    assert ten == {"horizon": 3, "size": 10, "n": 1, "p50": 2.0, "p90": 2.0, "max": 2.0}
    assert "planning latency by blocks" in tables.lengths_table(alone)
    batched = dataclasses.replace(alone, config=PlannerConfig())
    assert latency_rows(batched) == [] and "latency" not in tables.lengths_table(batched)


@pytest.mark.parametrize("n", [0, -1])
def test_a_random_suite_of_no_problems_is_refused_naming_n(n):
    """Not "none of 0 random problems fits the scene": n itself is the bad input."""
    with pytest.raises(DataError, match=f"n={n}: a random suite needs at least one problem"):
        suites.generated([3], n, seed=0)
