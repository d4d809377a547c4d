"""Adam on the action logits of one planning window, for a whole batch at once.

Instances and restarts are independent rows of one tensor program: the summed loss has a
block-diagonal gradient and Adam is element-wise, so each row is optimised exactly as it would
be alone.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import Tensor

from task.beliefs import WindowBeliefs
from task.config import PlannerConfig
from task.costs import WindowCosts, finite_costs
from task.domains.base import STAY_PRIOR, Domain, SoftBatch
from task.errors import TampError
from task.rollout import Rollout, check_deadline, rollout


def initial_logits(
    batch: SoftBatch, horizon: int, config: PlannerConfig, generator: torch.Generator
) -> Tensor:
    """Gaussian logits, (B, T, N, A), on the batch's device; each restart row draws its own
    noise. ``generator`` is a CPU generator, so every device starts from the same logits.
    A domain's `task.domains.base.STAY_PRIOR` raises the rows' STAY logits."""
    b, n, a = batch.action_mask.shape
    shape = (b, horizon, n, a)
    noise = torch.randn(shape, generator=generator, dtype=torch.float64)
    logits = (config.init_noise * noise).to(batch.F0.dtype).to(batch.F0.device)
    prior = batch.static.get(STAY_PRIOR)
    if prior is not None:  # STAY e^prior times more likely at the first temperature
        logits[..., -1] += config.tau * prior.to(logits.device)[:, None, None]
    return logits


@dataclass(frozen=True)
class Window:
    """One planning window's tensor program: the ``domain``, its encoded ``batch`` (B rows:
    problems x restarts), the live ``steps`` of each row ((B, T) bool: rows may have shorter
    windows), the settings, and the soft inputs from outside. ``beliefs`` (see
    `task.beliefs`) replace the batch's F0 and goal by soft ones, recomputed at every step;
    their parameters, if any, are optimised too, at their own learning rate. ``costs`` (see
    `task.costs`) add the expected move cost to the loss, likewise. ``deadline`` (a
    `time.perf_counter` value): raise `task.rollout.OutOfTime` once it has passed, checked at
    every Adam step and every rollout step."""

    domain: Domain
    batch: SoftBatch
    steps: Tensor  # (B, T) bool
    config: PlannerConfig
    beliefs: WindowBeliefs | None = None
    costs: WindowCosts | None = None
    deadline: float | None = None


def optimise_window(
    window: Window,
    generator: torch.Generator,
    stop: Callable[[Rollout], bool] | None = None,
) -> tuple[Tensor, Rollout]:
    """Optimise the window's logits, drawn from ``generator``; returns them and the final
    rollout (no grad; at ``config.decode_tau`` when set, the temperature the decoder reads the
    moves at).

    ``stop``: shown that rollout after every ``config.proof_every`` Adam steps (not after the
    last); the optimisation ends early, returning it, when ``stop`` says so (the planner's
    proof that the window's decode is already an optimal plan, `task.planner`).
    """
    domain, batch, steps, config = window.domain, window.batch, window.steps, window.config
    beliefs, costs, deadline = window.beliefs, window.costs, window.deadline
    logits = initial_logits(batch, steps.shape[1], config, generator).requires_grad_(True)
    groups = [{"params": [logits], "lr": config.lr}]
    extra = beliefs.parameters() if beliefs is not None else []
    if extra:
        groups.append({"params": extra, "lr": beliefs.lr})
    placed = costs.parameters() if costs is not None else []
    if placed:
        groups.append({"params": placed, "lr": costs.lr})
    opt = Adam(groups)
    for k in range(config.iters):
        check_deadline(deadline)
        opt.zero_grad()
        tau = temperature(config, k)
        live, penalty = with_beliefs(batch, beliefs)
        c = with_costs(batch, costs)
        roll = rollout(domain, logits, live, steps, config, tau, costs=c, deadline=deadline)
        (roll.loss.sum() + penalty).backward()
        opt.step()
        every = config.proof_every
        if stop is not None and every and (k + 1) % every == 0 and k + 1 < config.iters:
            decoded = _decoded(window, logits)
            if stop(decoded):
                return logits.detach(), decoded
    return logits.detach(), _decoded(window, logits)


@torch.no_grad()
def _decoded(window: Window, logits: Tensor) -> Rollout:
    """The rollout the decoder reads: at ``config.decode_tau`` (None: the last Adam step's
    temperature), without a graph."""
    config = window.config
    tau = config.decode_tau
    tau = temperature(config, config.iters - 1) if tau is None else tau
    live, _ = with_beliefs(window.batch, window.beliefs)
    c = with_costs(window.batch, window.costs)
    return rollout(
        window.domain, logits, live, window.steps, config, tau, costs=c, deadline=window.deadline
    )


class Adam:
    """Adam (Kingma & Ba 2015; betas 0.9, 0.999, eps 1e-8), step for step the arithmetic of
    `torch.optim.Adam`'s single-tensor path, which planning used before. Written out because
    every `torch.optim` step imports ``torch._dynamo`` first, 0.8 s of the first plan."""

    def __init__(self, groups: list[dict], betas=(0.9, 0.999), eps: float = 1e-8) -> None:
        self.groups, (self.beta1, self.beta2), self.eps = groups, betas, eps
        self.state: dict[int, list] = {}  # id(param) -> [steps, first moment, second moment]

    def zero_grad(self) -> None:
        for group in self.groups:
            for p in group["params"]:
                p.grad = None

    @torch.no_grad()
    def step(self) -> None:
        b1, b2 = self.beta1, self.beta2
        for group in self.groups:
            for p in group["params"]:
                if p.grad is None:
                    continue  # as torch.optim: no gradient, no step
                state = self.state.setdefault(id(p), [0, torch.zeros_like(p), torch.zeros_like(p)])
                state[0] += 1
                k, m, v = float(state[0]), state[1], state[2]
                m.lerp_(p.grad, 1 - b1)
                v.mul_(b2).addcmul_(p.grad, p.grad, value=1 - b2)
                denom = (v.sqrt() / (1 - b2**k) ** 0.5).add_(self.eps)
                p.addcdiv_(m, denom, value=-(group["lr"] / (1 - b1**k)))


def with_beliefs(batch: SoftBatch, beliefs: WindowBeliefs | None) -> tuple[SoftBatch, Tensor]:
    """The batch with the beliefs' soft F0 and goal (each problem's restarts share them), and
    the beliefs' penalty counted once per restart row, as the planning loss is."""
    if beliefs is None:
        return batch, batch.F0.new_zeros(())
    F0, goal, penalty = beliefs.compute()  # (P, N, Y), (P, N, Y), (P,)
    F0, goal, penalty = (t.to(batch.F0.device) for t in (F0, goal, penalty))
    rows = batch.F0.shape[0]
    if F0.shape[1:] != batch.F0.shape[1:] or goal.shape != F0.shape or rows % F0.shape[0]:
        raise TampError(
            f"beliefs of shape {tuple(F0.shape)} / {tuple(goal.shape)} do not fit a batch of "
            f"{tuple(batch.F0.shape)}"
        )
    r = rows // F0.shape[0]
    soft = dataclasses.replace(
        batch, F0=F0.repeat_interleave(r, dim=0), goal=goal.repeat_interleave(r, dim=0)
    )
    return soft, r * penalty.sum()


def with_costs(batch: SoftBatch, costs: WindowCosts | None) -> Tensor | None:
    """The window's move costs, one matrix per restart row (B, N, Y): a source's (P, N, Y)
    repeated for each problem's restart rows, or its own (B, N, Y) per-row matrices."""
    if costs is None:
        return None
    c = finite_costs(costs.compute())  # (P, N, Y), or (B, N, Y) per row
    rows = batch.F0.shape[0]
    if c.shape[1:] != batch.F0.shape[1:] or rows % c.shape[0]:
        raise TampError(
            f"move costs of shape {tuple(c.shape)} do not fit a batch of {tuple(batch.F0.shape)}"
        )
    c = c.to(device=batch.F0.device, dtype=batch.F0.dtype)  # a CPU source's onto the batch's
    return c.repeat_interleave(rows // c.shape[0], dim=0)  # (B, N, Y)


def temperature(config: PlannerConfig, k: int) -> float:
    """Softmax temperature at Adam step k: geometric from ``tau`` to ``tau_end``."""
    frac = k / max(config.iters - 1, 1)
    return config.tau * (config.tau_end / config.tau) ** frac
