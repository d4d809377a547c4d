"""Adam on the action logits of one planning window, for a whole batch at once.

Instances and restarts are independent rows of one tensor program: the summed loss has a
block-diagonal gradient and Adam is element-wise, so each row is optimised exactly as it would
be alone.
"""

from __future__ import annotations

import torch
from torch import Tensor

from task.config import PlannerConfig
from task.domains.base import Domain, SoftBatch
from task.rollout import Rollout, rollout


def initial_logits(
    batch: SoftBatch, horizon: int, config: PlannerConfig, generator: torch.Generator
) -> Tensor:
    """Gaussian logits, (B, T, N, A); each restart row draws its own noise."""
    b, n, a = batch.action_mask.shape
    shape = (b, horizon, n, a)
    noise = torch.randn(shape, generator=generator, dtype=torch.float64)
    return (config.init_noise * noise).to(batch.F0.dtype)


def optimise_window(
    domain: Domain,
    batch: SoftBatch,
    steps: Tensor,
    config: PlannerConfig,
    generator: torch.Generator,
) -> tuple[Tensor, Rollout]:
    """Optimise the window's logits; returns them and the final rollout (no grad).

    steps: (B, T) bool, the live steps of each row (rows may have shorter windows).
    """
    logits = initial_logits(batch, steps.shape[1], config, generator).requires_grad_(True)
    opt = torch.optim.Adam([logits], lr=config.lr)
    for k in range(config.iters):
        opt.zero_grad(set_to_none=True)
        tau = temperature(config, k)
        rollout(domain, logits, batch, steps, config, tau).loss.sum().backward()
        opt.step()
    with torch.no_grad():
        tau = temperature(config, config.iters - 1)
        return logits.detach(), rollout(domain, logits, batch, steps, config, tau)


def temperature(config: PlannerConfig, k: int) -> float:
    """Softmax temperature at Adam step k: geometric from ``tau`` to ``tau_end``."""
    frac = k / max(config.iters - 1, 1)
    return config.tau * (config.tau_end / config.tau) ** frac
