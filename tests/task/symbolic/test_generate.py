"""The seeded instance generator: determinism, parseable files, goals that need work."""

from __future__ import annotations

import random

import pytest

from task.domains import blocksworld as bw
from task.domains.blocksworld_pddl import write_instances
from task.errors import ProblemError
from task.problem import TABLE
from task.symbolic import generate, pddl_io, search


@pytest.mark.parametrize("n_blocks", [2, 3, 5, 12, 26, 27])
def test_seeded_determinism(n_blocks):
    assert generate.random_problem(n_blocks, seed=3) == generate.random_problem(n_blocks, seed=3)
    problems = {generate.random_problem(n_blocks, seed=s) for s in range(10)}
    assert len(problems) > 1 or n_blocks == 2


def test_problems_belong_to_the_blocksworld_domain():
    assert generate.random_problem(4, seed=0).domain == generate.DOMAIN == bw.NAME


def test_block_names():
    assert generate.block_names(3) == ("a", "b", "c")
    assert generate.block_names(26)[-1] == "z"
    assert generate.block_names(27)[:2] == ("b1", "b2")


@pytest.mark.parametrize("seed", range(20))
def test_goal_is_consistent_partial_and_unsatisfied(seed):
    n_blocks = 2 + seed % 6
    problem = generate.random_problem(n_blocks, seed)
    state = bw.initial_state(problem)
    assert not bw.is_goal(problem, state)
    assert problem.goal and all(y != TABLE for _, y in problem.goal)
    assert len({y for _, y in problem.goal}) == len(problem.goal)  # one block per support
    moves = search.optimal_moves(problem)
    for move in moves:
        state = bw.apply_move(problem, state, move)
    assert bw.is_goal(problem, state)


@pytest.mark.parametrize(("n_blocks", "k"), [(2, 1), (5, 1), (5, 4), (9, 8), (30, 29)])
def test_goal_atom_count(n_blocks, k):
    assert len(generate.random_problem(n_blocks, seed=0, n_goal_atoms=k).goal) == k


@pytest.mark.parametrize(("n_blocks", "k"), [(1, None), (4, 0), (4, 4)])
def test_bad_arguments(n_blocks, k):
    with pytest.raises(ProblemError):
        generate.random_problem(n_blocks, seed=0, n_goal_atoms=k)


def test_random_towers_are_forests():
    rng = random.Random(0)
    names = generate.block_names(10)
    for n_towers in (None, 1, 4, 10):
        support = generate.random_towers(names, rng, n_towers)
        assert sorted(s for s in support if s != TABLE) == sorted(set(support) - {TABLE})
        if n_towers is not None:
            assert support.count(TABLE) == n_towers


def test_write_instances(tmp_path, bw_domain_path):
    paths = write_instances(tmp_path / "gen", n_blocks=4, n=5, seed=11)
    assert [p.name for p in paths] == [f"instance-{i}.pddl" for i in range(1, 6)]
    again = write_instances(tmp_path / "again", n_blocks=4, n=5, seed=11)
    assert [p.read_text() for p in paths] == [p.read_text() for p in again]
    domain = pddl_io.load_domain(bw_domain_path)
    for path in paths:
        problem = bw.problem_from_files(bw_domain_path, path)
        assert problem.n == 4
        assert not bw.is_goal(problem, bw.initial_state(problem))
        assert search.optimal_moves(problem)
        assert pddl_io.load_problem(path, domain)
