"""PlanBench as users have it: no manifest.csv, official files by name, cached A* optima."""

from __future__ import annotations

import csv
import json
import shutil

import pytest

import tamp.cli
from tamp.bench import optimal, suites
from task import data
from task.domains import blocksworld
from task.errors import DataError
from task.symbolic import pddl_io
from task.symbolic.generate import random_problem
from task.symbolic.search import optimal_length_strips

# (file under instances/, blocks, seed); the last two are outside the official 600
_FAKE = (
    ("generated_basic/instance-1", 4, 11),
    ("generated_basic/instance-2", 5, 12),
    ("generated_basic/instance-3", 4, 13),
    ("generated_basic_3/instance-1", 3, 14),
    ("generated_basic_3/instance-2", 3, 15),
    ("generated_basic/instance-501", 4, 16),
    ("generated_basic_3/instance-101", 3, 17),
)
_ORDER = [  # by block count, then manifest order (the 3-block set first, each by number)
    "generated_basic_3/instance-1",
    "generated_basic_3/instance-2",
    "generated_basic/instance-1",
    "generated_basic/instance-3",
    "generated_basic/instance-2",
]
_OTHER_DOMAIN = """(define (domain tiny-grid)
  (:requirements :strips)
  (:predicates (at ?x) (adjacent ?x ?y))
  (:action walk :parameters (?from ?to)
    :precondition (and (at ?from) (adjacent ?from ?to))
    :effect (and (at ?to) (not (at ?from)))))
"""
_OTHER_PROBLEM = """(define (problem walk-1) (:domain tiny-grid)
  (:objects p q) (:init (at p) (adjacent p q)) (:goal (at q)))
"""


def _write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")


@pytest.fixture
def fake_planbench(tmp_path):
    """A PlanBench-shaped folder from the embedded domain and seeded random problems."""
    root = tmp_path / "blocksworld"
    _write(root / "domain.pddl", data.read_text(data.DOMAIN_FILE))
    for name, blocks, seed in _FAKE:
        _write(
            root / "instances" / f"{name}.pddl", blocksworld.to_pddl(random_problem(blocks, seed))
        )
    return root


def _bfs_optimum(path):
    """Optimal length by plain STRIPS breadth-first search, independent of the A* code."""
    domain = data.domain()
    return optimal_length_strips(domain, pddl_io.load_problem(path, domain))


def test_suite_loads_without_manifest(fake_planbench):
    suite = suites.planbench(fake_planbench)
    assert [i.name for i in suite.instances] == _ORDER
    blocks = {name: b for name, b, _ in _FAKE}
    assert [i.blocks for i in suite.instances] == [blocks[n] for n in _ORDER]
    for i in suite.instances:
        assert i.optimal == _bfs_optimum(fake_planbench / "instances" / f"{i.name}.pddl")
    limited = suites.planbench(fake_planbench, limit=2).instances
    assert [i.name for i in limited] == [_ORDER[1], _ORDER[3]]  # `spread`: slice middles
    assert not list(fake_planbench.parent.rglob(optimal.CACHE_FILE))  # no cache_dir: no cache


def test_planbench_own_layout_is_accepted(fake_planbench, tmp_path):
    upstream = tmp_path / "llm_planning_analysis" / "instances" / "blocksworld"
    shutil.copytree(fake_planbench / "instances", upstream)
    shutil.copy(fake_planbench / "domain.pddl", upstream / "generated_domain.pddl")
    assert [i.name for i in suites.planbench(upstream).instances] == _ORDER


def test_optima_are_cached_by_name_and_file_hash(fake_planbench, tmp_path, monkeypatch):
    out = tmp_path / "out"
    first = [i.optimal for i in suites.planbench(fake_planbench, cache_dir=out).instances]
    cached = json.loads((out / optimal.CACHE_FILE).read_text())["instances"]
    assert sorted(cached) == sorted(_ORDER)

    def searched(problem):
        searched.calls += 1
        return real(problem)

    real, searched.calls = optimal.optimal_moves, 0
    monkeypatch.setattr(optimal, "optimal_moves", searched)
    again = [i.optimal for i in suites.planbench(fake_planbench, cache_dir=out).instances]
    assert (again, searched.calls) == (first, 0)

    changed = fake_planbench / "instances" / "generated_basic" / "instance-3.pddl"
    changed.write_text(blocksworld.to_pddl(random_problem(4, 99)), encoding="utf-8")
    suite = suites.planbench(fake_planbench, cache_dir=out)
    assert searched.calls == 1
    assert suite.instances[3].optimal == _bfs_optimum(changed)

    (out / optimal.CACHE_FILE).write_text("{not json")  # a broken cache is rebuilt
    assert [i.optimal for i in suites.planbench(fake_planbench, cache_dir=out).instances][:3] == (
        first[:3]
    )


def _error(root):
    with pytest.raises(DataError) as caught:
        suites.planbench(root)
    message = str(caught.value)
    assert "\n" not in message
    return message


def test_missing_folder_points_to_the_data(tmp_path):
    message = _error(tmp_path / "missing")
    assert "PlanBench blocksworld data not found at" in message and "karthikv792" in message
    assert "manifest" not in message


def test_folder_without_instances_is_named(fake_planbench):
    shutil.rmtree(fake_planbench / "instances")
    (fake_planbench / "instances").mkdir()
    message = _error(fake_planbench)
    assert str(fake_planbench) in message
    assert "no official PlanBench blocksworld instances" in message


def test_other_domain_is_named(fake_planbench):
    _write(fake_planbench / "domain.pddl", _OTHER_DOMAIN)
    message = _error(fake_planbench)
    assert str(fake_planbench) in message
    assert "'tiny-grid'" in message and "'blocksworld-4ops'" in message


def test_instance_of_another_domain_is_named(fake_planbench):
    path = fake_planbench / "instances" / "generated_basic" / "instance-2.pddl"
    _write(path, _OTHER_PROBLEM)
    message = _error(fake_planbench)
    assert str(path) in message and "'tiny-grid'" in message


@pytest.mark.shared
def test_real_domain_of_another_benchmark_is_named(planbench_dir):
    message = _error(planbench_dir / "logistics")  # its manifest.csv is not ours: domain first
    assert "'logistics-strips'" in message and "'blocksworld-4ops'" in message


def _without_manifest(planbench_dir, tmp_path, files=None):
    """A copy of the real Blocksworld folder without manifest.csv (only ``files`` if given)."""
    source, root = planbench_dir / "blocksworld", tmp_path / "data"
    for name in files or [
        p.relative_to(source / "instances") for p in (source / "instances").rglob("*.pddl")
    ]:
        _write(root / "instances" / name, (source / "instances" / name).read_text())
    shutil.copy(source / "domain.pddl", root / "domain.pddl")
    return root


@pytest.mark.shared
@pytest.mark.parametrize("limit", [1, 6, 37, None])
def test_same_instances_with_and_without_manifest(planbench_dir, tmp_path, limit):
    root = _without_manifest(planbench_dir, tmp_path)
    with_manifest = suites.planbench(planbench_dir / "blocksworld", limit).instances
    without = suites.planbench(root, limit).instances
    assert [(i.name, i.blocks, i.optimal) for i in without] == [
        (i.name, i.blocks, i.optimal) for i in with_manifest
    ]


@pytest.mark.shared
def test_cli_without_manifest_matches_manifest_optima(planbench_dir, tmp_path, monkeypatch):
    names = [f"generated_basic_3/instance-{i}.pddl" for i in (1, 50, 101)] + [
        f"generated_basic/instance-{i}.pddl" for i in (1, 200, 445, 499, 501)
    ]
    root, out = _without_manifest(planbench_dir, tmp_path, names), tmp_path / "out"
    argv = ["bench", "planbench", "--data", str(root), "--no-progress", "--out", str(out)]
    assert tamp.cli.main(argv) == 0
    with (planbench_dir / "blocksworld" / "manifest.csv").open(newline="") as handle:
        manifest = {r["file"]: int(r["optimal_plan_length"]) for r in csv.DictReader(handle)}
    with (out / "instances.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert sorted(r["instance"] for r in rows) == sorted(  # 101 and 501 are not official
        n.removesuffix(".pddl") for n in names if not n.endswith(("-101.pddl", "-501.pddl"))
    )
    assert all(r["status"] == "valid" for r in rows)
    assert all(int(r["optimal"]) == manifest[f"instances/{r['instance']}.pddl"] for r in rows)
    assert (out / optimal.CACHE_FILE).is_file()

    def no_search(problem):
        raise AssertionError("the second run must read the cached optima")

    monkeypatch.setattr(optimal, "optimal_moves", no_search)
    assert tamp.cli.main(argv) == 0
