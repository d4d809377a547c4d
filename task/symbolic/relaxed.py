"""Crisp delete relaxations of a grounded STRIPS task: h_max, LM-cut (admissible), h_FF
(an inadmissible estimate that ranks restarts and guides the greedy fallback search) and its
helpful actions, vectorised over the task's padded arrays.

``task`` is a `task.symbolic.strips_task.StripsTask` (or any object with its arrays): ``pre``
(G, kp) precondition columns padded with P (column P is constant-true, P + 1 constant-false),
``add`` (G, ka) padded with P + 1, ``pairs`` (achievers sorted by atom), ``column``, ``goal``
and ``actions``. Unit action costs throughout.
"""

from __future__ import annotations

import math

import numpy as np

INF = math.inf


def hmax(task, state: frozenset, cost: np.ndarray | None = None, h=None):
    """h_max of every column from ``state`` (delete relaxation, action costs ``cost``, unit by
    default): Bellman sweeps from ``h`` (an upper bound; none: 0 on ``state`` and column P,
    inf elsewhere) until nothing changes. -> (P + 2,)"""
    actions, targets, starts = task.pairs
    cost = np.ones(len(task.actions)) if cost is None else cost
    if h is None:
        h = np.full(len(task.atoms) + 2, np.inf)
        h[[len(task.atoms), *(task.column[a] for a in state if a in task.column)]] = 0.0
    while targets.size:
        price = h[task.pre].max(axis=1) + cost  # (G,)
        best = np.minimum(h[targets], np.minimum.reduceat(price[actions], starts))
        if np.array_equal(best, h[targets]):
            break
        h = h.copy()
        h[targets] = best
    return h


def lm_cut(task, state: frozenset) -> float:
    """The LM-cut bound (Helmert & Domshlak 2009), unit costs; INF when the relaxation cannot
    reach the goal. Each round takes the cut of the h_max justification graph between the
    state and the goal zone (atoms reaching the costliest goal atom through zero-cost
    actions), adds its cheapest action cost and takes that cost off the whole cut."""
    n, g, pre, add = len(task.atoms), len(task.actions), task.pre, task.add
    goal = np.array([task.column[a] for a in task.goal])
    cost = np.ones(g)
    h = hmax(task, state, cost)
    start, total = h == 0.0, 0.0
    while h[goal].max() > 0.0:
        if np.isinf(h[goal].max()):
            return INF
        pcf = pre[np.arange(g), h[pre].argmax(axis=1)]  # (G,) the costliest precondition
        zone = np.zeros(n + 2, dtype=bool)
        zone[goal[h[goal].argmax()]] = True
        while True:  # the goal zone: backwards through zero-cost actions
            grow = np.zeros(n + 2, dtype=bool)
            grow[pcf[zone[add].any(axis=1) & (cost == 0.0)]] = True
            if not (grow & ~zone).any():
                break
            zone |= grow
        reach = start & ~zone
        while True:  # before the cut: forwards from the state, never into the goal zone
            grow = np.zeros(n + 2, dtype=bool)
            grow[add[reach[pcf]]] = True
            grow &= ~zone & ~reach
            grow[n + 1] = False
            if not grow.any():
                break
            reach |= grow
        cut = zone[add].any(axis=1) & reach[pcf]
        total += cost[cut].min()
        cost[cut] -= cost[cut].min()
        h = hmax(task, state, cost, h)
    return total


def hadd(task, state: frozenset) -> tuple[np.ndarray, np.ndarray]:
    """h_add of every column from ``state`` and each action's price (the sum of its
    preconditions' h_add + 1), by Bellman sweeps until nothing changes. -> (P + 2,), (G,)"""
    actions, targets, starts = task.pairs
    h = np.full(len(task.atoms) + 2, np.inf)
    h[[len(task.atoms), *(task.column[a] for a in state if a in task.column)]] = 0.0
    while True:
        price = h[task.pre].sum(axis=1) + 1.0  # (G,)
        if not targets.size:
            return h, price
        best = np.minimum(h[targets], np.minimum.reduceat(price[actions], starts))
        if np.array_equal(best, h[targets]):
            return h, price
        h = h.copy()
        h[targets] = best


def relaxed_plan(task, state: frozenset) -> tuple[int, ...] | None:
    """The actions of a relaxed plan from ``state`` (Hoffmann & Nebel 2001): every goal atom
    reached through each atom's cheapest achiever by h_add, backwards through their
    preconditions; None when the relaxation cannot reach the goal. -> action columns, sorted"""
    h, price = hadd(task, state)
    goal = [task.column[a] for a in task.goal]
    if any(math.isinf(h[g]) for g in goal):
        return None
    actions, targets, starts = task.pairs
    where = {int(t): k for k, t in enumerate(targets)}
    ends = np.append(starts[1:], len(actions))
    n, chosen, seen, todo = len(task.atoms), set(), set(), [g for g in goal if h[g] > 0]
    while todo:
        atom = todo.pop()
        if atom in seen:
            continue
        seen.add(atom)
        k = where[atom]
        adders = actions[starts[k] : ends[k]]
        best = int(adders[np.argmin(price[adders])])
        if best not in chosen:
            chosen.add(best)
            todo.extend(int(p) for p in task.pre[best] if p < n and h[p] > 0)
    return tuple(sorted(chosen))


def ff(task, state: frozenset) -> float:
    """h_FF (Hoffmann & Nebel 2001): the size of the `relaxed_plan` from ``state``; INF when
    the relaxation cannot reach the goal. Not admissible: the decoder ranks restarts by it."""
    chosen = relaxed_plan(task, state)
    return INF if chosen is None else float(len(chosen))


def helpful(task, state: frozenset, chosen: tuple[int, ...] | None = None) -> tuple[int, ...]:
    """The *helpful actions* of ``state`` (Hoffmann & Nebel 2001, as FF's and Fast Downward's
    preferred operators): the actions of its `relaxed_plan` (``chosen``, computed when None)
    that apply in ``state`` itself, i.e. whose preconditions all hold there. Empty at a dead
    end. -> action columns, sorted"""
    chosen = relaxed_plan(task, state) if chosen is None else chosen
    if not chosen:
        return ()
    false = np.ones(len(task.atoms) + 2, dtype=bool)  # (P + 2,) the atoms that do not hold
    false[[len(task.atoms), *(task.column[a] for a in state if a in task.column)]] = False
    return tuple(j for j in chosen if not false[task.pre[j]].any())
