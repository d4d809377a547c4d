"""Domain-independent soft-logic operators of the soft-T_P transition.

Every function is batched (batch first) and differentiable. Products of ``(1 - p)`` terms run
over at most N entities and are taken as plain (cumulative) products, which are exact at 0 and 1
(one-hot states stay one-hot) and never divide; torch's product backward handles exact zeros.
"""

from __future__ import annotations

import torch
from torch import Tensor


def prod_others(v: Tensor) -> Tensor:
    """Exclusive product ``out[..., i] = prod_{j != i} v[..., j]``, without division.

    v: (..., N) -> (..., N), as prefix products times suffix products (O(N), exact at 0).
    Used by the competition ``q(x) = prod_{x' != x} (1 - rho(x'))`` and by T_P.
    """
    ones = torch.ones_like(v[..., :1])  # (..., 1)
    before = torch.cat([ones, v[..., :-1]], dim=-1).cumprod(-1)  # prod_{j < i}
    after = torch.cat([v[..., 1:], ones], dim=-1).flip(-1).cumprod(-1).flip(-1)  # prod_{j > i}
    return before * after


def column_free(F: Tensor, n: int) -> Tensor:
    """Soft "nothing rests on column y" for the first ``n`` columns, excluding self-support.

    Eq. clear: c(x) = prod_{z != x} (1 - F[z, x]).  F: (B, N, Y) -> (B, N).
    """
    occ = F[..., :n]  # (B, Z, X)
    eye = torch.eye(n, dtype=torch.bool, device=F.device)
    free = torch.where(eye, torch.ones_like(occ), 1.0 - occ)
    return free.prod(-2)  # product over z -> (B, X)


def exclusive_support(F: Tensor, n: int) -> Tensor:
    """Target exclusivity on the first ``n`` (capacity-one) columns.

    Eq. T_P: T_P(F)[z, y] = F[z, y] * prod_{z' != z} (1 - F[z', y]) for block targets y;
    the remaining (unlimited-capacity) columns pass through. F: (B, N, Y) -> (B, N, Y).
    """
    cols = F[..., :n].transpose(-1, -2)  # (B, Y_blocks, Z)
    others_free = prod_others(1.0 - cols).transpose(-1, -2)  # (B, Z, Y_blocks)
    return torch.cat([F[..., :n] * others_free, F[..., n:]], dim=-1)


def row_normalise(F: Tensor, eps: float = 1e-12) -> Tensor:
    """Rows back to distributions; the denominator is clamped, never zero. (B, N, Y)."""
    return F / F.sum(-1, keepdim=True).clamp_min(eps)


def transition(F: Tensor, M: Tensor, legal: Tensor) -> tuple[Tensor, Tensor]:
    """One soft-T_P step with legality-gated move mass and one-move-per-step competition.

    F: (B, N, Y) support beliefs; M: (B, N, A) action distribution, A = Y + 1 (last = STAY);
    legal: (B, N, Y) soft legality of move(x -> y) from the domain.

    Eq. gate:        g~(x, y) = M(x, y) * legal(x, y)
    Eq. competition: rho(x) = sum_y g~(x, y);  q(x) = prod_{x' != x} (1 - rho(x'));  g = g~ q
    Eq. transition:  m(x) = sum_y g(x, y);  F' = (1 - m) F + g   (1 - m is the residual STAY mass)
    Returns (F', g) with g: (B, N, Y).
    """
    g_raw = M[..., :-1] * legal  # (B, N, Y)
    rho = g_raw.sum(-1)  # (B, N)
    q = prod_others(1.0 - rho)  # (B, N)
    g = g_raw * q.unsqueeze(-1)  # (B, N, Y)
    m = g.sum(-1, keepdim=True)  # (B, N, 1)
    return (1.0 - m) * F + g, g


def goal_cross_entropy(F: Tensor, goal: Tensor) -> Tensor:
    """Eq. goal: -sum over goal atoms of log F[x, y]; partial goals leave rows empty.

    F, goal: (B, N, Y) with goal one-hot on the goal atoms -> (B,).
    """
    eps = torch.finfo(F.dtype).tiny
    return -(goal * torch.log(F.clamp_min(eps))).sum((-1, -2))


def exclusive_columns(F: Tensor, one: Tensor, rows: Tensor) -> Tensor:
    """Target exclusivity on every capacity-one column (blocks and table slots).

    Eq. T_P: T_P(F)[z, y] = F[z, y] * prod_{z' != z, z' real} (1 - F[z', y]) where ``one[y]``,
    else F[z, y] (an unlimited table). F: (B, N, Y); one: (B, Y) bool; rows: (B, N) bool, the
    real rows (padding never occupies a column). -> (B, N, Y).
    """
    occ = F * rows.unsqueeze(-1).to(F.dtype)  # (B, N, Y)
    others_free = prod_others(1.0 - occ.transpose(-1, -2)).transpose(-1, -2)  # (B, N, Y)
    return torch.where(one.unsqueeze(-2), F * others_free, F)


def log_any(F: Tensor, goal: Tensor) -> Tensor:
    """log sum_y goal[x, y] F[x, y] per row, for goals that accept any of several targets
    ("on the table": on any of its slots). F, goal: (B, N, Y) -> (B, N); rows with no goal
    target give a large negative number (finite, so gradients stay finite)."""
    tiny = torch.finfo(F.dtype).tiny
    log_f = torch.log(F.clamp_min(tiny))
    return torch.logsumexp(log_f.masked_fill(goal <= 0, -1e30), dim=-1)
