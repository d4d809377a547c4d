"""Contract tests run over every registered domain: soft transition vs crisp semantics."""

from __future__ import annotations

import itertools
import random

import pytest
import torch

from task.domains import get_domain, names
from task.problem import Move
from task.soft import prod_others, transition
from task.symbolic.generate import random_problem

DOMAINS = names()
BLOCKS = (3, 4, 5, 6)
SEEDS = (0, 1)
WALK = 6  # random legal moves per walk; every state along it is a case


def _onehot_action(batch, x: int, y: int | None) -> torch.Tensor:
    """(1, N, A) with move(x -> y) for entity x and STAY for everyone else."""
    _, n, a = batch.action_mask.shape
    M = torch.zeros(1, n, a, dtype=torch.float64)
    M[0, :, -1] = 1.0
    if y is not None:
        M[0, x] = 0.0
        M[0, x, y] = 1.0
    return M


def _legal_moves(domain, problem, state) -> list[Move]:
    targets = problem.entities + problem.fixed
    moves = [Move(x, y) for x in problem.entities for y in targets if y != x]
    return [m for m in moves if domain.check_move(problem, state, m) is None]


def _cases(domain_name: str):
    """States reached by seeded random legal moves from random problems of several sizes.

    Yields ``(problem, state)`` for the initial state and every state along each walk.
    """
    domain = get_domain(domain_name)
    for n_blocks, seed in itertools.product(BLOCKS, SEEDS):
        problem = random_problem(n_blocks, seed)
        rng = random.Random(1000 * n_blocks + seed)
        state = domain.initial_state(problem)
        yield problem, state
        for _ in range(WALK):
            state = domain.apply_move(
                problem, state, rng.choice(_legal_moves(domain, problem, state))
            )
            yield problem, state


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_walks_reach_states_beyond_the_initial_ones(domain_name):
    cases = list(_cases(domain_name))
    assert len(cases) == len(BLOCKS) * len(SEEDS) * (WALK + 1)
    assert {p.n for p, _ in cases} == set(BLOCKS)
    walked = {(p.name, s) for p, s in cases if s != tuple(p.init)}
    assert len(walked) >= len(cases) // 2  # most cases are not the problem's initial state


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_soft_step_equals_crisp_apply_on_onehot_states(domain_name):
    domain = get_domain(domain_name)
    checked = {"legal": 0, "illegal": 0}
    for problem, state in _cases(domain_name):
        batch = domain.encode([problem], [state], torch.float64)
        n = batch.n
        for x, y in itertools.product(range(problem.n), range(n + len(problem.fixed))):
            if y == x:
                continue
            target = problem.entities[y] if y < n else problem.fixed[y - n]
            move = Move(problem.entities[x], target)
            F = batch.F0
            F1, g = transition(F, _onehot_action(batch, x, y), domain.soft_legality(F, batch))
            if domain.check_move(problem, state, move) is None:
                expected = domain.encode(
                    [problem], [domain.apply_move(problem, state, move)], torch.float64
                ).F0
                assert torch.equal(F1, expected), move
                assert g.sum().item() == 1.0
                checked["legal"] += 1
            else:
                assert g.abs().sum().item() == 0.0, f"illegal {move} carries mass"
                assert torch.equal(F1, F)
                checked["illegal"] += 1
    assert min(checked.values()) >= 100, checked  # both branches, over many walked states


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_rows_stay_distributions_under_soft_actions(domain_name):
    domain = get_domain(domain_name)
    gen = torch.Generator().manual_seed(0)
    for problem, state in _cases(domain_name):
        batch = domain.encode([problem], [state], torch.float64)
        F = batch.F0
        for _ in range(5):
            M = torch.softmax(torch.randn(batch.action_mask.shape, generator=gen), -1)
            M = M.to(torch.float64) * batch.action_mask
            M = M / M.sum(-1, keepdim=True)
            F, g = transition(F, M, domain.soft_legality(F, batch))
            assert torch.allclose(F.sum(-1), torch.ones_like(F[..., 0]))
            assert (F >= 0).all() and (g >= 0).all()
            F = domain.consistency(F, batch)
            assert torch.allclose(F.sum(-1), torch.ones_like(F[..., 0]))


@pytest.mark.parametrize("domain_name", DOMAINS)
def test_consistency_is_identity_on_crisp_states(domain_name):
    domain = get_domain(domain_name)
    for problem, state in _cases(domain_name):
        batch = domain.encode([problem], [state], torch.float64)
        assert torch.equal(domain.consistency(batch.F0, batch), batch.F0)
        assert domain.cycle_loss(batch.F0, batch).item() == 0.0


def test_competition_lets_only_one_entity_move():
    domain = get_domain("blocksworld")
    problem = random_problem(4, 1)
    batch = domain.encode([problem], [domain.initial_state(problem)], torch.float64)
    clear = [i for i, e in enumerate(problem.entities) if e not in domain.initial_state(problem)]
    M = _onehot_action(batch, clear[0], batch.n)  # clear block to the table
    if len(clear) > 1:
        M[0, clear[1]] = 0.0
        M[0, clear[1], batch.n] = 1.0  # a second full move in the same step
        _, g = transition(batch.F0, M, domain.soft_legality(batch.F0, batch))
        assert g.sum().item() == 0.0  # two certain movers cancel each other out


def test_prod_others_matches_loop():
    v = torch.rand(3, 5, dtype=torch.float64)
    out = prod_others(v)
    for i in range(5):
        others = torch.cat([v[:, :i], v[:, i + 1 :]], dim=1).prod(1)
        assert torch.allclose(out[:, i], others)
