"""A grounded STRIPS problem as padded index arrays: the crisp input of the delete relaxations
(`task.symbolic.relaxed`) and of the generic soft lift's tensors (`task.domains.strips_soft`).

Column j of the action axis is ``actions[j]``; column i of the state row is ``atoms[i]``, one
per *fluent* atom (one that some reachable action adds or deletes); the other atoms of init are
*static* and leave the preconditions. Columns P and P + 1 of an extended row are a
constant-true and a constant-false atom: precondition lists are padded with P, effect lists
with P + 1 (a dump column), so every per-action list is a rectangular ``(G, k)`` array.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from task.problem import Action
from task.symbolic.strips import Atom, GroundAction, initial_state


def _padded(rows: Sequence[Sequence[int]], pad: int) -> np.ndarray:
    """Ragged index lists -> (len(rows), k) int64, padded with ``pad`` (k >= 1)."""
    out = np.full((len(rows), max(map(len, rows), default=1) or 1), pad, dtype=np.int64)
    for j, r in enumerate(rows):
        out[j, : len(r)] = r
    return out


@dataclass(frozen=True, eq=False)
class StripsTask:
    """The grounding of one problem (``Problem.data`` of the lift). Column j of the action
    axis is ``actions[j]``; column i of the state row is ``atoms[i]``."""

    actions: tuple[Action, ...]  # the G reachable ground actions, sorted by (name, args)
    effects: tuple[GroundAction, ...]  # per action: fluent preconditions, adds, deletes
    atoms: tuple[Atom, ...]  # the P fluent atoms (added or deleted by some action), sorted
    static: frozenset[Atom]  # the other atoms of init: they hold in every reachable state
    init: frozenset[Atom]  # the fluent atoms of the initial state
    goal: tuple[Atom, ...]  # fluent goal atoms in file order (static goal atoms hold already)
    pre: np.ndarray = field(repr=False)  # (G, kp) fluent precondition columns, padded with P
    add: np.ndarray = field(repr=False)  # (G, ka) added columns, padded with P + 1
    delete: np.ndarray = field(repr=False)  # (G, kd) deleted and not added, padded with P + 1
    consumed: np.ndarray = field(repr=False)  # (G, kp) bool: the precondition is deleted
    goal_adds: int = 1  # the most fluent goal atoms one action adds (the goal-count bound)
    pddl_domain: object = field(default=None, repr=False)  # the parsed PDDL it was built from
    pddl_problem: object = field(default=None, repr=False)
    order: tuple[str, ...] = ()  # the problem's objects in file order

    @classmethod
    def build(cls, ground, goal: Sequence[Atom], domain, problem, order=()) -> StripsTask:
        """The task of reachable ``ground`` ``(Action, GroundAction)`` pairs; static
        preconditions (true at init, never changed) are dropped."""
        fluent = sorted({a for _, g in ground for a in g.add | g.delete})
        col, n = {a: i for i, a in enumerate(fluent)}, len(fluent)
        init = initial_state(problem)
        static = init.difference(fluent)
        effects = tuple(
            GroundAction(g.pre_pos - static, frozenset(), g.add, g.delete) for _, g in ground
        )
        goal = tuple(a for a in goal if a in col)
        return cls(
            actions=tuple(a for a, _ in ground),
            effects=effects,
            atoms=tuple(fluent),
            static=frozenset(static),
            init=frozenset(init & set(fluent)),
            goal=goal,
            pre=_padded([[col[a] for a in sorted(e.pre_pos)] for e in effects], n),
            add=_padded([[col[a] for a in sorted(e.add)] for e in effects], n + 1),
            delete=_padded([[col[a] for a in sorted(e.delete - e.add)] for e in effects], n + 1),
            consumed=_padded(
                [[a in e.delete - e.add for a in sorted(e.pre_pos)] for e in effects], 0
            )
            > 0,
            goal_adds=max((len(e.add & set(goal)) for e in effects), default=1),
            pddl_domain=domain,
            pddl_problem=problem,
            order=tuple(order),
        )

    @functools.cached_property
    def column(self) -> dict[Atom, int]:
        return {a: i for i, a in enumerate(self.atoms)}

    @functools.cached_property
    def index(self) -> dict[Action, int]:
        return {a: j for j, a in enumerate(self.actions)}

    @functools.cached_property
    def pairs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(added atom, action) pairs sorted by atom: their actions (E,), the atoms some
        action adds (U,) and where each one's pairs start (U,), for ``np.minimum.reduceat``."""
        j, k = np.nonzero(self.add < len(self.atoms))
        order = np.argsort(self.add[j, k], kind="stable")
        targets, starts = np.unique(self.add[j, k][order], return_index=True)
        return j[order], targets, starts

    @functools.cached_property
    def bounds(self) -> dict:
        """Memo of the domain's lower bound and estimate by state (restarts often reach the
        same one)."""
        return {}
