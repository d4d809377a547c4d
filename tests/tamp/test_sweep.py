"""Sweeps (`tamp.sweep.run_items`): results in item order and a callback per item, in this
process and in a pool; a missing Ray is a one-line error. The motion benchmark gives the same
episode rows whatever the number of workers, and on a local Ray instance (slow, opt-in)."""

from __future__ import annotations

import dataclasses
import sys
import time

import pytest

from tamp.bench import executability, motion
from tamp.bench.suites import planbench
from tamp.loop import LoopConfig
from tamp.sweep import RAY_MISSING, run_items
from task import data
from task.errors import TampError

# two 3-block PlanBench-layout instances: b on a -> the tower c-a-b; a, b, c apart -> a on b
PROBLEMS = (
    """(define (problem one) (:domain blocksworld-4ops) (:objects a b c)
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a c) (on b a))))
""",
    """(define (problem two) (:domain blocksworld-4ops) (:objects a b c)
(:init (handempty) (ontable a) (ontable b) (ontable c) (clear a) (clear b) (clear c))
(:goal (and (on a b))))
""",
)


def _square_late(x: int) -> int:
    """x * x, the earlier items later (a pool finishes them out of order)."""
    time.sleep(0.2 * (3 - x))
    return x * x


def _fail_on_two(x: int) -> int:
    if x == 2:
        raise ValueError("item 2")
    return x


@pytest.mark.parametrize("workers", [1, 2])
def test_results_come_in_item_order_and_each_is_reported_once(workers):
    seen = []
    out = run_items(_square_late, range(4), workers, on_result=lambda k, r: seen.append((k, r)))
    assert out == [0, 1, 4, 9]
    assert sorted(seen) == [(0, 0), (1, 1), (2, 4), (3, 9)]


@pytest.mark.parametrize("workers", [1, 2])
def test_a_workers_exception_is_raised_here(workers):
    with pytest.raises(ValueError, match="item 2"):
        run_items(_fail_on_two, range(4), workers)


def test_bad_workers_and_a_missing_ray_are_one_line_errors(monkeypatch):
    with pytest.raises(TampError, match="workers must be at least 1, got 0"):
        run_items(_square_late, [3], 0)
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray fails
    with pytest.raises(TampError) as err:
        run_items(_square_late, [3], ray_address="local")
    assert str(err.value) == RAY_MISSING == "--ray needs Ray: pip install 'soft-tamp[ray]'"


def _suite(tmp_path):
    root = tmp_path / "blocksworld"
    (root / "instances" / "generated_basic_3").mkdir(parents=True)
    (root / "domain.pddl").write_text(data.read_text(data.DOMAIN_FILE))
    for k, text in enumerate(PROBLEMS, 1):
        (root / "instances" / "generated_basic_3" / f"instance-{k}.pddl").write_text(text)
    return planbench(root, len(PROBLEMS))


# wall-clock timings differ from run to run; every other field of an episode (its report, its
# moves, its episodes.csv row) and of a summary must not depend on what runs the episodes
TIMINGS = {"wall_time_s", "plan_time_s"}
MOVE_TIMINGS = {"wall_time_s", "ik_time_s", "check_time_s", "path_time_s"}
SUMMARY_TIMINGS = {f"{k}_per_move_s" for k in ("wall", "ik", "check", "path")}
SUMMARY_TIMINGS |= {"wall_s", "plan_per_episode_s"}


def _without(record: dict, timings: set[str]) -> dict:
    assert timings <= set(record), f"timing fields renamed: {sorted(timings - set(record))}"
    return {k: v for k, v in record.items() if k not in timings}


def _report(report) -> dict:
    out = _without(dataclasses.asdict(report), TIMINGS)
    out["moves"] = [_without(m, MOVE_TIMINGS) for m in out["moves"]]
    return out


def _rows(bench: motion.MotionBench) -> list:
    """Every episode report (its moves' outcomes and evidence included), every episodes.csv
    row and each simulator's summary, less the wall-clock timings."""
    reports = [_report(r) for r in bench.reports]
    rows = [_without(r, TIMINGS) for r in motion.episode_rows(bench.reports)]
    summary = {sim: _without(s, SUMMARY_TIMINGS) for sim, s in bench.summary.items()}
    return [reports, rows, summary]


def _sweep(suite, **where) -> motion.MotionBench:
    return motion.run(suite, LoopConfig(), ("pybullet",), 0, **where)


@pytest.mark.sim
@pytest.mark.slow
def test_motion_rows_do_not_depend_on_the_number_of_workers(tmp_path):
    suite = _suite(tmp_path)
    alone, pooled = _sweep(suite), _sweep(suite, workers=2)
    assert [r.problem for r in pooled.reports] == [i.name for i in suite.instances]
    assert _rows(pooled) == _rows(alone)
    assert alone.summary["pybullet"]["goal_reached"] == 2


@pytest.mark.sim
@pytest.mark.slow
def test_motion_rows_on_a_local_ray_match_the_sequential_ones(tmp_path):
    pytest.importorskip("ray")
    suite = _suite(tmp_path)
    assert _rows(_sweep(suite, ray_address="local")) == _rows(_sweep(suite))


@pytest.mark.sim
def test_executability_rows_and_shared_runs_do_not_depend_on_the_number_of_workers(tmp_path):
    suite = _suite(tmp_path)
    one, two = (i.name for i in suite.instances)
    tower = "(unstack b a);(put-down b);(pick-up a);(stack a c);(pick-up b);(stack b a)"
    sources = {
        "x": {one: (tower, True), two: ("(pick-up a);(stack a b)", True)},
        "y": {one: (tower, None), two: ("(unstack a)", False)},
    }
    runs = [
        executability.run_given(suite, sources, LoopConfig(), ("pybullet",), 0, None, workers=n)
        for n in (1, 2)
    ]
    alone, pooled = ([{**vars(r), "wall_time_s": None} for r in rows] for rows in runs)
    assert pooled == alone
    x1, y1, x2, y2 = runs[1]  # sim, then instance, then source
    assert x1.reached_goal and x2.reached_goal and y2.task == "unparseable"
    assert y1.wall_time_s == x1.wall_time_s  # the same plan ran once, its row shared
