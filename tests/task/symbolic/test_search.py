"""Optimal search: A* over moves against PlanBench's optimal lengths and against STRIPS BFS."""

from __future__ import annotations

import csv

import pytest

from task.domains import blocksworld as bw
from task.errors import ProblemError
from task.problem import TABLE, Problem
from task.symbolic import generate, pddl_io, search, validate


def _manifest(planbench_dir, official_only: bool = True) -> list[dict[str, str]]:
    with open(planbench_dir / "blocksworld" / "manifest.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return [r for r in rows if r["in_official_600"] == "1" or not official_only]


@pytest.mark.shared
def test_astar_matches_optimal_length_on_official_600(planbench_dir):
    root = planbench_dir / "blocksworld"
    domain = pddl_io.load_domain(root / "domain.pddl")
    rows = _manifest(planbench_dir)
    assert len(rows) == 600
    for row in rows:
        text = pddl_io.read_text(root / row["file"])
        problem = bw.problem_from_text(domain, text, row["file"])
        moves = search.optimal_moves(problem)
        assert moves is not None
        assert 2 * len(moves) == int(row["optimal_plan_length"]), row["file"]


@pytest.mark.shared
def test_strips_bfs_matches_optimal_length_on_30(planbench_dir):
    root = planbench_dir / "blocksworld"
    domain = pddl_io.load_domain(root / "domain.pddl")
    rows = _manifest(planbench_dir)[::20]
    assert len(rows) == 30
    for row in rows:
        problem = pddl_io.load_problem(root / row["file"], domain)
        assert search.optimal_length_strips(domain, problem) == int(row["optimal_plan_length"])


@pytest.mark.parametrize("seed", range(8))
def test_astar_agrees_with_strips_bfs(bw_domain_path, seed):
    domain = pddl_io.load_domain(bw_domain_path)
    problem = generate.random_problem(3 + seed % 2, seed)
    pddl_problem = pddl_io.parse_problem(bw.to_pddl(problem), domain=domain)
    moves = search.optimal_moves(problem)
    assert 2 * len(moves) == search.optimal_length_strips(domain, pddl_problem)
    plan = bw.moves_to_actions(problem, moves)
    assert validate.validate(domain, pddl_problem, plan).valid


def test_goal_at_init_needs_no_moves():
    problem = Problem("done", "blocksworld", ("a", "b"), ("b", TABLE), (("a", "b"),))
    assert search.optimal_moves(problem) == ()


def test_budget_exhausted_returns_none():
    problem = generate.random_problem(20, seed=1)
    assert search.optimal_moves(problem, max_nodes=10) is None


def test_unreachable_goal_raises():
    problem = Problem("loop", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"), ("b", "a")))
    with pytest.raises(ProblemError, match="unsolvable goal"):
        search.optimal_moves(problem)
