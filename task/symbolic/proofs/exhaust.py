"""Breadth-first search over every reachable ground state of a STRIPS task, under a cap.

When the reachable state space is small, enumerating it is a proof: no reachable state
satisfies the goal, so no plan exists. States are Python ints, one bit per fluent atom of a
`task.symbolic.strips_task.StripsTask`; an action applies when its precondition bits are
set, and its successor clears its delete bits and sets its add bits (`task.symbolic.strips`
semantics). Successors are found through one precondition per action (its pivot), so a state
looks only at the actions one of its atoms can enable.
"""

from __future__ import annotations

import enum
import time
from collections import deque
from dataclasses import dataclass


class Outcome(enum.Enum):
    UNSOLVABLE = "unsolvable"  # every reachable state searched, none a goal state
    SOLVABLE = "solvable"  # a goal state is reachable
    CAP = "cap"  # more reachable states than the cap
    TIME = "time"  # the deadline passed first


@dataclass(frozen=True)
class Exhausted:
    """What the search found: its outcome, the states it saw, the plan length (SOLVABLE)."""

    outcome: Outcome
    states: int
    length: int | None = None


def _mask(columns) -> int:
    bits = 0
    for c in columns:
        bits |= 1 << c
    return bits


def exhaust(task, max_states: int, deadline: float | None = None) -> Exhausted:
    """Search ``task`` breadth first from its initial state, at most ``max_states`` states;
    ``deadline``: a ``time.perf_counter()`` time."""
    col = task.column
    pre = [_mask(col[a] for a in e.pre_pos) for e in task.effects]
    add = [_mask(col[a] for a in e.add) for e in task.effects]
    keep = [~_mask(col[a] for a in e.delete - e.add) for e in task.effects]
    by_pivot: dict[int, list[int]] = {}
    always = []
    for j, e in enumerate(task.effects):
        if e.pre_pos:
            by_pivot.setdefault(min(col[a] for a in e.pre_pos), []).append(j)
        else:
            always.append(j)
    goal = _mask(col[a] for a in task.goal)
    start = _mask(col[a] for a in task.init)
    depth = {start: 0}
    todo = deque([start])
    expanded = 0
    while todo:
        state = todo.popleft()
        if state & goal == goal:
            return Exhausted(Outcome.SOLVABLE, len(depth), depth[state])
        expanded += 1
        if deadline is not None and expanded % 512 == 0 and time.perf_counter() > deadline:
            return Exhausted(Outcome.TIME, len(depth))
        bits, candidates = state, list(always)
        while bits:
            low = bits & -bits
            candidates.extend(by_pivot.get(low.bit_length() - 1, ()))
            bits ^= low
        for j in candidates:
            if state & pre[j] != pre[j]:
                continue
            succ = (state & keep[j]) | add[j]
            if succ not in depth:
                if len(depth) >= max_states:
                    return Exhausted(Outcome.CAP, len(depth))
                depth[succ] = depth[state] + 1
                todo.append(succ)
    return Exhausted(Outcome.UNSOLVABLE, len(depth))
