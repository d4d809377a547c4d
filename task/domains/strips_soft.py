"""The tensors of the generic STRIPS lift: the soft step and goal terms over a grounded task.

A problem is one row of P independent fluent-atom probabilities, ``F: (B, 1, P)``, and one
commitment per step over ``A = G + 1`` columns (the G reachable ground actions, then STAY).
Columns P and P + 1 of the extended row ``[F, 1, 0]`` are a constant-true and a constant-false
atom: precondition lists are padded with P, padded actions' with P + 1 (they never apply), and
effect lists with P + 1 (a dump column, dropped). Each per-action list is an index tensor
``(B, G, k)``: a step costs O(B G k) (a gather and two scatter-adds), never O(B G P). The
grounded task these are batched from is the crisp `task.symbolic.strips_task.StripsTask`.

Goal terms: "atoms" is the paper's CE, which a 3-5 step window cannot feel for goal atoms more
than a window away. The default "hadd" adds the expected h_add of the goal (`relaxed_cost`),
so reaching preconditions of goal achievers pays. Its cost: ``sweeps`` Jacobi sweeps (relaxed
depth of the window's crisp start + 2) of one gather and one scatter over (B, G, ka, kp), once
per rollout, against T steps of the transition. Tuned on generated Blocksworld (3-6 blocks),
tiny gripper (3-6 balls) and Logistics instances 201-286 only.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch
from torch import Tensor

from task.domains.base import SoftBatch
from task.errors import ProblemError, one_of
from task.problem import Problem
from task.symbolic import relaxed
from task.symbolic.strips import atom_str
from task.symbolic.strips_task import StripsTask

CAP = 30.0  # the relaxed cost of an atom nothing reaches (and the ceiling of every cost)
SOFTMIN_TAU = 0.1  # temperature of the softmin over an atom's achievers
ATOMS_WEIGHT = 1.0  # weight of the paper's goal cross-entropy inside "hadd"
SWEEP_MARGIN = 2  # Bellman sweeps beyond the relaxed depth of the window's start
MAX_SWEEPS = 40
GOAL_LOSSES = ("hadd", "atoms")  # the first is the default


def encode(
    problems: Sequence[Problem], states: Sequence[frozenset], dtype: torch.dtype = torch.float32
) -> SoftBatch:
    """One-hot rows of crisp states (sets of fluent atoms; static ones are ignored), padded.

    ``static``: ``pre`` (B, G, kp) into P + 2 extended columns, ``add`` and ``delete``
    (B, G, ka), (B, G, kd) (deletes the same action does not add), ``consumed`` (B, G, kp)
    (the precondition is deleted), ``sweeps`` (B,)."""
    tasks: list[StripsTask] = [p.data for p in problems]
    b, n, g = len(tasks), max(len(t.atoms) for t in tasks), max(len(t.actions) for t in tasks)
    F0, goal = torch.zeros(b, 1, n, dtype=dtype), torch.zeros(b, 1, n, dtype=dtype)
    mask = torch.zeros(b, 1, g + 1, dtype=torch.bool)
    mask[:, :, -1] = True  # STAY
    static = {  # padded actions: false preconditions, no effects
        k: torch.full((b, g, max(getattr(t, k).shape[1] for t in tasks)), n + 1)
        for k in ("pre", "add", "delete")
    }
    static["consumed"] = static["pre"] < 0  # (B, G, kp) all False
    depth = []
    for i, (task, state) in enumerate(zip(tasks, states, strict=True)):
        bad = sorted(a for a in state if a not in task.column and a not in task.static)
        if bad:
            raise ProblemError(f"atom {atom_str(bad[0])} is not reachable in {problems[i].name}")
        F0[i, 0, [task.column[a] for a in state if a in task.column]] = 1.0
        goal[i, 0, [task.column[a] for a in task.goal]] = 1.0
        p, rows = len(task.atoms), len(task.actions)
        mask[i, 0, :rows] = True
        for key in static:
            own = torch.from_numpy(getattr(task, key))  # (G_i, k_i)
            if key != "consumed":  # the task's own columns P, P + 1 -> the batch's n, n + 1
                static[key][i, :rows] = n + (key != "pre")
                own = torch.where(own >= p, own - p + n, own)
            static[key][i, :rows, : own.shape[1]] = own
        h = relaxed.hmax(task, state)
        depth.append(int(h[np.isfinite(h)].max()))
    static["sweeps"] = (torch.tensor(depth) + SWEEP_MARGIN).clamp_max(MAX_SWEEPS)
    return SoftBatch(F0, torch.ones(b, 1, dtype=torch.bool), mask, goal, static)


def _extend(x: Tensor, one: float, zero: float) -> Tensor:
    """(B, P) -> (B, P + 2): the constant-true and constant-false columns appended."""
    return torch.cat([x, x.new_full((x.shape[0], 1), one), x.new_full((x.shape[0], 1), zero)], -1)


def _gather(ext: Tensor, index: Tensor) -> Tensor:
    """ext (B, P + 2), index (B, G, k) -> (B, G, k)."""
    return ext.gather(1, index.flatten(1)).view(index.shape)


def _scatter(values: Tensor, index: Tensor, width: int) -> Tensor:
    """Sum ``values`` (B, G) of each action into its listed columns: -> (B, width)."""
    src = values.unsqueeze(-1).expand(index.shape).reshape(index.shape[0], -1)  # (B, G k)
    return values.new_zeros(values.shape[0], width).scatter_add(1, index.flatten(1), src)


def step(F: Tensor, M: Tensor, batch: SoftBatch) -> tuple[Tensor, Tensor]:
    """One soft STRIPS step. F (B, 1, P), M (B, 1, G + 1) -> (F' (B, 1, P), g (B, 1, G)).

    Applicability (product t-norm): a_j = prod_{i in pre_j} p_i; gated mass g_j = M_j a_j.
    Effects: A = g @ Add, D = g @ (Del minus Add); p'_i = p_i (1 - D_i) + (1 - p_i) A_i.
    Exact on one-hot F and M (delete, then add); in [0, 1] since sum_j g_j <= 1."""
    p = F[:, 0]  # (B, P)
    width = p.shape[1] + 2
    a = _gather(_extend(p, 1.0, 0.0), batch.static["pre"]).prod(-1)  # (B, G)
    g = M[:, 0, :-1] * a  # (B, G)
    add = _scatter(g, batch.static["add"], width)[:, :-2]  # (B, P)
    delete = _scatter(g, batch.static["delete"], width)[:, :-2]  # (B, P)
    return (p * (1.0 - delete) + (1.0 - p) * add).unsqueeze(1), g.unsqueeze(1)


def consistency(F: Tensor, batch: SoftBatch) -> Tensor:
    """T_P of independent atoms: a clamp to [0, 1] (rounding only; identity on [0, 1])."""
    return F.clamp(0.0, 1.0)


def relaxed_cost(F: Tensor, batch: SoftBatch) -> Tensor:
    """Expected h_add cost of every fluent atom from the soft state: (B, 1, P) -> (B, P).

    An atom is free with probability p_i, else it costs its cheapest achiever:
    c_i = (1 - p_i) S_i, S_i = softmin_tau(CAP, C_ji for j adding i), from S = CAP, over
    ``sweeps`` Jacobi sweeps: crisp h_add on one-hot states (tau -> 0), linear in each p_i.
    C_ji = 1 + sum_{q in pre_j} (1 - p'_q) S_q, where a precondition q that j consumes
    (deletes) counts as true with the mass already past j to i, p'_q = min(1, p_q + p_i):
    independent atoms would otherwise charge the mass moved from q to i twice (q lost, i not
    yet certain) and make every first step of a relaxed plan look worse than staying put."""
    p = _extend(F[:, 0], 1.0, 0.0)  # (B, P + 2)
    pre, add = batch.static["pre"], batch.static["add"]
    flat = add.flatten(1)  # (B, G ka)
    p_pre = _gather(p, pre).unsqueeze(2)  # (B, G, 1, kp)
    p_add = _gather(p, add).unsqueeze(3)  # (B, G, ka, 1)
    consumed = batch.static["consumed"].unsqueeze(2)  # (B, G, 1, kp)
    free = torch.where(consumed, (p_pre + p_add).clamp_max(1.0), p_pre)  # (B, G, ka, kp)
    S = torch.full_like(p, CAP)
    for _ in range(int(batch.static["sweeps"].max())):
        s_pre = _gather(S, pre).unsqueeze(2)  # (B, G, 1, kp)
        src = (1.0 + ((1.0 - free) * s_pre).sum(-1)).clamp_max(CAP).flatten(1)  # (B, G ka)
        m = torch.full_like(p, CAP).scatter_reduce(1, flat, src.detach(), "amin")  # (B, P + 2)
        terms = torch.exp(-(src - m.gather(1, flat)) / SOFTMIN_TAU)
        s = torch.exp(-(CAP - m) / SOFTMIN_TAU).scatter_add(1, flat, terms)  # >= 1
        S = m - SOFTMIN_TAU * torch.log(s)
    return ((1.0 - p) * S)[:, :-2]


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """The goal term, (B, 1, P) -> (B,): "atoms", the paper's CE -sum_goal log p_i, or
    "hadd" (default): sum over goal atoms of `relaxed_cost` plus ``ATOMS_WEIGHT`` times the CE.
    The h_add part rewards reaching the preconditions of goal achievers that a 3-5 step
    window cannot finish; the CE part pulls hard on goal atoms the window can reach."""
    tiny = torch.finfo(F.dtype).tiny
    atoms = -(batch.goal * torch.log(F.clamp_min(tiny))).sum((-1, -2))
    if kind == "atoms":
        return atoms
    if kind in ("hadd", "default"):
        return (batch.goal[:, 0] * relaxed_cost(F, batch)).sum(-1) + ATOMS_WEIGHT * atoms
    raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")
