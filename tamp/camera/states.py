"""Blocksworld states for planning from images: full goal scenes and the most likely state.

A camera sees a full scene, not a partial PDDL goal, so `complete_goal` gives the full state a
goal image shows; `most_likely_state` decodes a perceived soft support matrix F into the most
likely *valid* state (exact by enumerating `all_states` up to `ENUMERATE_UP_TO` blocks).
"""

from __future__ import annotations

import functools

import torch
from torch import Tensor

from task.domains.blocksworld import State
from task.domains.blocksworld_pddl import support_error
from task.errors import ProblemError
from task.problem import TABLE, Problem

ENUMERATE_UP_TO = 7  # blocks; 37,633 states at 7, 394,353 at 8


def complete_goal(problem: Problem) -> State:
    """A full state that satisfies the (partial) goal: blocks the goal does not mention keep
    their initial support when it stays free and makes no cycle, else go on the table."""
    support = dict(problem.goal)
    above = {y: x for x, y in support.items() if y != TABLE}
    for x, start in zip(problem.entities, problem.init, strict=True):
        if x in support:
            continue
        y = start
        if y != TABLE:
            chain = y
            while chain in support and chain != x:
                chain = support[chain]
            if y in above or chain == x:
                y = TABLE
        support[x] = y
        if y != TABLE:
            above[y] = x
    reason = support_error(list(support.items()))
    if reason is not None:
        raise ProblemError(f"cannot complete the goal of {problem.name}: {reason}")
    return tuple(support[x] for x in problem.entities)


@functools.cache
def all_states(n: int) -> Tensor:
    """Every blocksworld state of ``n`` blocks as support columns (S, n) (table = column n).

    Built by inserting block k into any position of any tower, or as a new tower: each set of
    ordered towers arises exactly once (13, 73, 501, 4051 states for 3..6 blocks).
    """
    configs: list[list[list[int]]] = [[]]
    for k in range(n):
        grown = []
        for towers in configs:
            grown.append([*towers, [k]])
            for t, tower in enumerate(towers):
                for j in range(len(tower) + 1):
                    grown.append([*towers[:t], [*tower[:j], k, *tower[j:]], *towers[t + 1 :]])
        configs = grown
    out = torch.empty(len(configs), n, dtype=torch.long)
    for i, towers in enumerate(configs):
        for tower in towers:
            for below, x in zip([n, *tower], tower, strict=False):
                out[i, x] = below
    return out


def most_likely_state(problem: Problem, F: Tensor) -> tuple[str, ...]:
    """The crisp state that maximises sum_x log F[x, support(x)] among valid blocksworld states
    (no two blocks on one, no cycles): exact by enumeration up to `ENUMERATE_UP_TO` blocks,
    the row-wise most likely supports above that (ProblemError if they are not a state).

    F: (N, Y) soft supports with N >= problem.n rows and the table at column N.
    """
    n, rows = problem.n, F.shape[0]
    if F.ndim != 2 or rows < n or F.shape[1] != rows + len(problem.fixed):
        raise ProblemError(f"soft state of shape {tuple(F.shape)} does not fit {n} blocks")
    logf = torch.log(F.detach().cpu().double().clamp_min(1e-300))  # (N, Y), read on the CPU
    blocks = torch.cat([logf[:n, :n], logf[:n, rows:]], dim=1)  # (n, n+1), table last
    names = [*problem.entities, TABLE]
    if n <= ENUMERATE_UP_TO:
        states = all_states(n)  # (S, n)
        score = blocks.gather(1, states.T).sum(0)  # (S,)
        return tuple(names[c] for c in states[int(score.argmax())].tolist())
    state = tuple(names[c] for c in blocks.argmax(1).tolist())
    reason = support_error(list(zip(problem.entities, state, strict=True)))
    if reason is not None:
        raise ProblemError(f"the most likely supports are not a state: {reason}")
    return state
