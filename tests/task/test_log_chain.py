"""`task.soft.log_chain`, the towers goal's recursion: the same result as the plain n-sweep
recursion over every row (the form it replaced), padding and table slots included."""

from __future__ import annotations

import pytest
import torch

from task.domains import blocksworld as bw
from task.soft import log_any
from task.symbolic.generate import random_problem


def plain(F, batch):
    """The recursion as first written: n sweeps, every row pays the logsumexp over Y."""
    n = batch.n
    sweeps = batch.entity_mask.sum(-1, keepdim=True)
    has_goal = batch.goal.sum(-1) > 0
    log_f = torch.log(F.clamp_min(torch.finfo(F.dtype).tiny))
    log_on_goal = (log_f * batch.goal).sum(-1)
    if "one" in batch.static:
        log_on_goal = log_any(F, batch.goal)
    lw, zeros = torch.zeros_like(log_on_goal), torch.zeros_like(F[:, 0, n:])
    for k in range(n):
        lwbar = torch.cat([lw, zeros], dim=-1).unsqueeze(-2)
        goal_term = log_on_goal + (batch.goal * lwbar).sum(-1)
        free_term = torch.logsumexp(log_f + lwbar, dim=-1)
        lw = torch.where(k < sweeps, torch.where(has_goal, goal_term, free_term), lw)
    return lw


def batch_of(sizes, slots: bool):
    problems = [random_problem(b, seed) for seed, b in enumerate(sizes)]
    if slots:
        problems = [bw.with_slots(p, [f"s{k}" for k in range(p.n)]) for p in problems]
    return bw.encode(problems, [p.init for p in problems], torch.float64)


@pytest.mark.parametrize("slots", [False, True])
@pytest.mark.parametrize("soft", [0.0, 0.2, 1.0])
def test_log_chain_equals_the_plain_recursion(slots, soft):
    batch = batch_of([7, 4, 12, 9], slots)  # padded rows of 4, 7 and 9 blocks
    torch.manual_seed(3)
    mixed = torch.softmax(3 * torch.randn(batch.F0.shape, dtype=torch.float64), -1)
    F = ((1 - soft) * batch.F0 + soft * mixed).requires_grad_(True)
    fast = bw.log_well_placed(F, batch)
    slow = plain(F, batch)
    assert torch.allclose(fast, slow, rtol=1e-12, atol=1e-12)
    weights = torch.rand(fast.shape, dtype=torch.float64)
    (g_fast,) = torch.autograd.grad((weights * fast).sum(), F)
    (g_slow,) = torch.autograd.grad((weights * plain(F, batch)).sum(), F)
    assert torch.allclose(g_fast, g_slow, rtol=1e-9, atol=1e-9)


def test_crisp_towers_give_zero_only_to_well_placed_blocks():
    """On the initial (crisp) state a goal block scores log 1 = 0 exactly when it and
    everything under it already stand as the goal wants."""
    problem = random_problem(8, 5)
    batch = bw.encode([problem], [problem.init], torch.float64)
    lw = bw.log_well_placed(batch.F0, batch)[0]
    support = dict(zip(problem.entities, problem.init, strict=True))
    goal = dict(problem.goal)

    def well(x):
        if x in goal:
            return support[x] == goal[x] and well(goal[x])
        return support[x] == "table" or well(support[x])

    for i, x in enumerate(problem.entities):
        if x in goal:
            assert (lw[i] == 0) == well(x), x
