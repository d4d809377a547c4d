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


def log_chain(
    log_f: Tensor, log_on_goal: Tensor, has_goal: Tensor, goal_block: Tensor, sweeps: Tensor
) -> Tensor:
    """A soft "never has to move again", log w (B, N), by its recursion in log space.

    log_f: (B, N, Y) log support matrix, Y = N + K (the K fixed targets have log wbar = 0);
    log_on_goal: (B, N) the log mass of each goal row on its goal; has_goal: (B, N) bool, the
    goal rows; goal_block: (B, N, N) one-hot goal support of goal rows whose goal is a block
    (zero rows otherwise); sweeps: (B, 1) how many sweeps each batch row gets. Starting from
    lw = 0, every sweep sets

        goal rows:  lw(x) = log_on_goal(x) + lw(g(x))        (lw(fixed target) = 0)
        free rows:  lw(x) = logsumexp_y (log_f[x, y] + lw(y))

    Goal rows read lw(g(x)) by a gather, O(N) a sweep, and only the free rows pay the
    logsumexp over Y: a sweep costs O(B F Y) for F free rows instead of O(B N Y). The sweeps
    stop early once an iterate equals the one before exactly: every later one would be the
    same, so the result is that of all ``sweeps`` sweeps.
    """
    b, n, y = log_f.shape
    block_goal = goal_block.sum(-1) > 0  # (B, N)
    target = goal_block.argmax(-1)  # (B, N) g(x) where it is a block
    order = torch.argsort(has_goal.to(torch.int8), dim=-1, stable=True)  # free rows first
    n_free = int((~has_goal).sum(-1).max()) if n else 0
    rows = order[:, :n_free]  # (B, F): every free row, padded with goal rows
    log_f_free = log_f.gather(1, rows[..., None].expand(b, n_free, y))  # (B, F, Y)
    zeros = torch.zeros_like(log_f[:, 0, n:])  # (B, K): lw of the fixed targets
    lw = torch.zeros_like(log_on_goal)
    for k in range(n):
        below = torch.where(block_goal, lw.gather(-1, target), torch.zeros_like(lw))
        goal_term = log_on_goal + below  # (B, N)
        lwbar = torch.cat([lw, zeros], dim=-1).unsqueeze(-2)  # (B, 1, Y)
        free = torch.logsumexp(log_f_free + lwbar, dim=-1)  # (B, F)
        free_term = torch.zeros_like(lw).scatter(1, rows, free)  # (B, N), goal rows unused
        new = torch.where(k < sweeps, torch.where(has_goal, goal_term, free_term), lw)
        if torch.equal(new, lw):
            break
        lw = new
    return lw
