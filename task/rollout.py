"""Differentiable rollout of a window of action logits through the soft-T_P transition.

Shared by every domain: the domain supplies its soft step and its T_P consistency operator.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import torch
from torch import Tensor

from task.config import PlannerConfig
from task.domains.base import Domain, SoftBatch, resolve_goal_loss

NEG = -1e9  # logit of a masked action


class OutOfTime(Exception):
    """The planning time limit (`task.config.PlannerConfig.time_limit_s`) passed in the middle
    of a window: the planner abandons the window and reports the limit."""


def check_deadline(deadline: float | None) -> None:
    """Raise `OutOfTime` when ``deadline`` (a `time.perf_counter` value; None: none) has
    passed."""
    if deadline is not None and time.perf_counter() >= deadline:
        raise OutOfTime


@dataclass(frozen=True)
class Rollout:
    states: Tensor  # (B, T+1, N, Y) soft supports, refined
    gates: Tensor  # (B, T, N, A - 1) move mass g_t actually applied per action column
    loss: Tensor  # (B,) total objective per rollout
    goal: Tensor  # (B,) goal cross-entropy at the window's end
    moves: Tensor  # (B,) expected number of moves, sum_t sum_x m_t(x)
    motion: Tensor | None = None  # (B,) expected move cost sum_t sum_(x,y) g_t(x,y) c(x,y)
    costs: Tensor | None = None  # (B, N, Y) the move costs c (`task.costs`), or None


def action_probs(logits: Tensor, batch: SoftBatch, tau: float, steps: Tensor) -> Tensor:
    """M_t = softmax(a_t / tau) with invalid actions masked. (B, T, N, A) -> (B, T, N, A).

    steps: (B, T) bool, False where a row's window is shorter than T (only STAY is allowed).
    """
    stay = torch.zeros_like(batch.action_mask[0, 0])  # (A,)
    stay[-1] = True
    live = steps[:, :, None, None] | stay  # (B, T, 1, A)
    mask = batch.action_mask.unsqueeze(1) & live  # (B, T, N, A)
    return torch.softmax(torch.where(mask, logits / tau, NEG), dim=-1)


def rollout(
    domain: Domain,
    logits: Tensor,
    batch: SoftBatch,
    steps: Tensor,
    config: PlannerConfig,
    tau: float | None = None,
    costs: Tensor | None = None,
    deadline: float | None = None,
) -> Rollout:
    """Roll the window out from ``batch.F0``; logits: (B, T, N, A); steps: (B, T) live steps.

    ``tau`` overrides ``config.tau`` (the optimiser anneals it). ``costs`` (B, N, Y): move
    costs, whose expectation under the applied move mass joins the loss with weight
    ``config.lambda_motion`` (`task.costs`). ``deadline``: raise `OutOfTime` at the first step
    after it (`check_deadline`), so that even a very long window stops at the time limit.
    """
    M = action_probs(logits, batch, config.tau if tau is None else tau, steps)  # (B, T, N, A)
    F = batch.F0
    states, gates = [F], []
    fp = torch.zeros(F.shape[0], dtype=F.dtype, device=F.device)
    cycle = domain.cycle_loss(F, batch)
    for t in range(M.shape[1]):
        check_deadline(deadline)
        F, g = domain.step(F, M[:, t], batch)  # (B, N, Y), (B, N, A - 1)
        refined = domain.consistency(F, batch)
        fp = fp + (refined - F).pow(2).sum((-1, -2))  # fixed-point loss before refinement
        F = refined
        for _ in range(config.fp_iters - 1):
            F = domain.consistency(F, batch)
        cycle = cycle + domain.cycle_loss(F, batch)
        states.append(F)
        gates.append(g)
    G = torch.stack(gates, dim=1)  # (B, T, N, A - 1)
    moves = G.sum((1, 2, 3))
    goal = domain.goal_loss(F, batch, resolve_goal_loss(domain, config.goal_loss))
    loss = goal + config.lambda_move * moves + config.lambda_cycle * cycle + config.lambda_fp * fp
    motion = None
    if costs is not None:
        motion = (G * costs[:, None]).sum((1, 2, 3))  # (B, T, N, Y) * (B, 1, N, Y) -> (B,)
        loss = loss + config.lambda_motion * motion
    return Rollout(torch.stack(states, dim=1), G, loss, goal, moves, motion, costs)
