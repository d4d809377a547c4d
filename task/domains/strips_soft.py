"""The tensors of the generic STRIPS lift: the soft step and goal terms over a grounded task.

A problem is one row of P independent fluent-atom probabilities, ``F: (B, 1, P)``, and one
commitment per step over ``A = G + 1`` columns (the G reachable ground actions, then STAY).
Columns P and P + 1 of the extended row ``[F, 1, 0]`` are a constant-true and a constant-false
atom: precondition lists are padded with P, padded actions' with P + 1 (they never apply), and
effect lists with P + 1 (a dump column, dropped). Each per-action list is an index tensor
``(B, G, k)``: a step costs O(B G k) (a gather and two scatter-adds), never O(B G P). The
grounded task these are batched from is the crisp `task.symbolic.strips_task.StripsTask`.

Goal terms: "atoms" is the paper's CE, which a 3-5 step window cannot feel for goal atoms more
than a window away. "hadd" adds the expected h_add of the goal (`relaxed_cost`), so reaching
preconditions of goal achievers pays. The default "ff" adds instead the expected size of the
relaxed plan (`relaxed_plan_size`, a soft h_FF), which counts a precondition that many goal
achievers share once (h_add counts it per goal atom: picking a ball into the last free
gripper, unstacking onto the one free hand looked like a step back). Both keep the CE with a
floor (``CE_FLOOR``): at log(tiny) a goal atom far away charged 87 and its gradient chased
the stray mass a soft window leaks onto it, not the moves that make progress. Their cost:
``sweeps`` Jacobi sweeps (relaxed depth of the window's crisp start + 2) of one gather and one
scatter over (B, G, ka, kp), once per rollout, forwards (and backwards for "ff"), against T
steps of the transition. Helpful-action priors (`prior`) reweight the commitment of every
step. Measured on IPC gripper, miconic and Blocksworld-600 (see BENCHMARKS.md); tuned before
on generated Blocksworld (3-6 blocks), tiny gripper (3-6 balls) and Logistics 201-286.
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
ATOMS_WEIGHT = 1.0  # weight of the (floored) goal cross-entropy inside "ff" and "hadd"
SWEEP_MARGIN = 2  # Bellman sweeps beyond the relaxed depth of the window's start
MAX_SWEEPS = 40
PRIOR_PLAN = 0.0  # logit bonus of the actions of the crisp start's relaxed plan (`prior`)
PRIOR_HELPFUL = 1.0  # further bonus of its helpful actions (those applicable at the start)
CE_FLOOR = 0.05  # "ff", "hadd": the goal CE is -log((p + floor) / (1 + floor)), <= 3.04 an atom
GOAL_LOSSES = ("ff", "hadd", "atoms")  # the first is the default


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
    static["prior"] = prior(tasks, states, g, dtype)
    return SoftBatch(F0, torch.ones(b, 1, dtype=torch.bool), mask, goal, static)


def prior(
    tasks: Sequence[StripsTask], states: Sequence[frozenset], g: int, dtype: torch.dtype
) -> Tensor:
    """Helpful-action priors of each window, (B, G + 1) multiplicative weights on the
    commitment (1 for STAY and padding): ``exp(PRIOR_PLAN)`` for the actions of the crisp
    start's relaxed plan (`task.symbolic.relaxed.relaxed_plan`), ``exp(PRIOR_PLAN +
    PRIOR_HELPFUL)`` for its helpful actions, 1 elsewhere. The step reweights M by them, which
    is adding their logs to the logits: the window starts (and anneals) near the moves the
    delete relaxation says lead to the goal, not from uniform noise over all G actions, of
    which a few applicable ones matter (miconic: 1,156 actions, a handful useful per state)."""
    w = torch.zeros(len(tasks), g + 1, dtype=dtype)
    for i, (task, state) in enumerate(zip(tasks, states, strict=True)):
        fluent = frozenset(a for a in state if a in task.column)
        chosen = relaxed.relaxed_plan(task, fluent) or ()
        w[i, list(chosen)] = PRIOR_PLAN
        w[i, list(relaxed.helpful(task, fluent, chosen))] += PRIOR_HELPFUL
    return w.exp()


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

    Priors: m = w M / sum_k w_k M_k with the helpful-action priors w =
    ``batch.static["prior"]`` (`prior`; the softmax of the logits plus log w), the identity on
    one-hot M. Applicability (product t-norm): a_j = prod_{i in pre_j} p_i; gated mass
    g_j = m_j a_j. Effects: A = g @ Add, D = g @ (Del minus Add);
    p'_i = p_i (1 - D_i) + (1 - p_i) A_i. Exact on one-hot F and M (delete, then add); in
    [0, 1] since sum_j g_j <= 1."""
    p = F[:, 0]  # (B, P)
    width = p.shape[1] + 2
    weighted = M[:, 0] * batch.static["prior"]  # (B, G + 1); STAY's weight is 1
    m = weighted / weighted.sum(-1, keepdim=True)  # (B, G + 1)
    a = _gather(_extend(p, 1.0, 0.0), batch.static["pre"]).prod(-1)  # (B, G)
    g = m[:, :-1] * a  # (B, G)
    add = _scatter(g, batch.static["add"], width)[:, :-2]  # (B, P)
    delete = _scatter(g, batch.static["delete"], width)[:, :-2]  # (B, P)
    return (p * (1.0 - delete) + (1.0 - p) * add).unsqueeze(1), g.unsqueeze(1)


def consistency(F: Tensor, batch: SoftBatch) -> Tensor:
    """T_P of independent atoms: a clamp to [0, 1] (rounding only; identity on [0, 1])."""
    return F.clamp(0.0, 1.0)


def relaxed_cost(F: Tensor, batch: SoftBatch) -> Tensor:
    """Expected h_add cost of every fluent atom from the soft state: (B, 1, P) -> (B, P).

    An atom is free with probability p_i, else it costs its cheapest achiever:
    c_i = (1 - p_i) S_i, S_i = the softmin-weighted mean of CAP and C_ji for j adding i
    (weights softmax(-C / tau)), from S = CAP, over ``sweeps`` Jacobi sweeps: crisp h_add on
    one-hot states (tau -> 0), linear in each p_i. A mean, not the log-sum-exp softmin, which
    lies tau log k below a k-way tie: there an atom with k equal achievers (a ball any of two
    grippers may pick, a passenger any of 30 floors' lifts) looked cheaper than with one, so
    the first move of a plan, which breaks such ties, looked like a step back.
    C_ji = 1 + sum_{q in pre_j} (1 - p'_q) S_q, where a precondition q that j consumes
    (deletes) counts as true with the mass already past j to i, p'_q = min(1, p_q + p_i):
    independent atoms would otherwise charge the mass moved from q to i twice (q lost, i not
    yet certain) and make every first step of a relaxed plan look worse than staying put."""
    return _achievers(F, batch)[0]


def _achievers(F: Tensor, batch: SoftBatch) -> tuple[Tensor, ...]:
    """The soft h_add sweeps of `relaxed_cost`. -> (c (B, P) the atoms' expected costs,
    share (B, G, ka) each achiever's softmin weight among an added atom's achievers (and CAP),
    free (B, G, ka, kp) each precondition's truth for its action reaching each added atom,
    consumed ones as in `relaxed_cost`)."""
    p = _extend(F[:, 0], 1.0, 0.0)  # (B, P + 2)
    pre, add = batch.static["pre"], batch.static["add"]
    flat = add.flatten(1)  # (B, G ka)
    p_pre = _gather(p, pre).unsqueeze(2)  # (B, G, 1, kp)
    p_add = _gather(p, add).unsqueeze(3)  # (B, G, ka, 1)
    consumed = batch.static["consumed"].unsqueeze(2)  # (B, G, 1, kp)
    free = torch.where(consumed, (p_pre + p_add).clamp_max(1.0), p_pre)  # (B, G, ka, kp)
    S = torch.full_like(p, CAP)
    share = torch.ones_like(flat, dtype=p.dtype)
    for _ in range(int(batch.static["sweeps"].max())):
        s_pre = _gather(S, pre).unsqueeze(2)  # (B, G, 1, kp)
        src = (1.0 + ((1.0 - free) * s_pre).sum(-1)).clamp_max(CAP).flatten(1)  # (B, G ka)
        m = torch.full_like(p, CAP).scatter_reduce(1, flat, src.detach(), "amin")  # (B, P + 2)
        terms = torch.exp(-(src - m.gather(1, flat)) / SOFTMIN_TAU)  # (B, G ka) in (0, 1]
        cap = torch.exp(-(CAP - m) / SOFTMIN_TAU)  # (B, P + 2) the weight of CAP itself
        weight = cap.scatter_add(1, flat, terms)  # >= 1: the cheapest has weight 1
        total = (cap * CAP).scatter_add(1, flat, terms * src)  # (B, P + 2)
        S = total / weight
        share = terms / weight.gather(1, flat)  # (B, G ka)
    return ((1.0 - p) * S)[:, :-2], share.view(add.shape), free


def relaxed_plan_size(F: Tensor, batch: SoftBatch) -> Tensor:
    """Expected size of the relaxed plan of the goal from the soft state (a soft h_FF,
    Hoffmann & Nebel 2001): (B, 1, P) -> (B,), sum_j r_j.

    Backwards from the goal over ``sweeps`` sweeps: an atom is *needed* when it is false and
    a goal atom or a precondition of an action in the plan,
    n_q = (1 - p_q) (1 - (1 - goal_q) prod_{j: q in pre_j} prod_{i in add_j}
    (1 - w_ji (1 - free_jiq))), and an action is in the plan for atom i when it is i's
    (softmin-weighted, `relaxed_cost`) cheapest achiever and i is needed, w_ji = share_ji n_i,
    r_j = 1 - prod_{i in add_j} (1 - w_ji). On one-hot states
    (tau -> 0, no ties) this is h_FF: an action serving many needs counts once, where h_add
    counts it once per need (a Blocksworld hand that every pick needs empty, a gripper that
    every ball needs free), so that a first move which shares such a precondition no longer
    looks like a step back, and a false precondition of a goal achiever pays."""
    _, share, free = _achievers(F, batch)  # (B, G, ka), (B, G, ka, kp)
    pre, add = batch.static["pre"], batch.static["add"]
    false = _extend(1.0 - F[:, 0], 0.0, 0.0)  # (B, P + 2): the two constant columns never needed
    goal = _extend(batch.goal[:, 0], 0.0, 0.0)  # (B, P + 2)
    need = goal * false
    width, bound = need.shape[1], 1.0 - 1e-6
    r = need.new_zeros(pre.shape[:2])  # (B, G)
    for _ in range(int(batch.static["sweeps"].max())):
        w = (share * _gather(need, add)).clamp_max(bound)  # (B, G, ka)
        r = 1.0 - torch.log1p(-w).sum(-1).exp()  # (B, G)
        miss = (w.unsqueeze(-1) * (1.0 - free)).clamp_max(bound)  # (B, G, ka, kp)
        keep = need.new_zeros(need.shape[0], width).scatter_add(
            1, pre.flatten(1), torch.log1p(-miss).sum(2).flatten(1)
        )  # (B, P + 2): log prod_j prod_i (1 - w_ji (1 - free_jiq))
        need = false * (1.0 - (1.0 - goal) * keep.exp())
    return r.sum(-1)


def goal_loss(F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
    """The goal term, (B, 1, P) -> (B,): "atoms", the paper's CE -sum_goal log p_i; "ff"
    (default), `relaxed_plan_size` plus ``ATOMS_WEIGHT`` times the floored CE
    -sum_goal log((p_i + CE_FLOOR) / (1 + CE_FLOOR)); "hadd", the sum over goal atoms of
    `relaxed_cost` plus the same. The relaxed part rewards reaching the preconditions of goal
    achievers that a short window cannot finish; the CE part pulls on goal atoms the window
    can reach."""
    tiny = torch.finfo(F.dtype).tiny
    atoms = -(batch.goal * torch.log(F.clamp_min(tiny))).sum((-1, -2))
    if kind == "atoms":
        return atoms
    floored = -torch.log((F + CE_FLOOR) / (1.0 + CE_FLOOR))  # (B, 1, P)
    near = (batch.goal * floored).sum((-1, -2))  # (B,)
    if kind in ("ff", "default"):
        return relaxed_plan_size(F, batch) + ATOMS_WEIGHT * near
    if kind == "hadd":
        return (batch.goal[:, 0] * relaxed_cost(F, batch)).sum(-1) + ATOMS_WEIGHT * near
    raise ProblemError(f"unknown goal loss {one_of(kind, GOAL_LOSSES)}")
