"""h^2 reachability over a grounded STRIPS task, and the goal conflicts it proves.

h^2 (Haslum & Geffner 2000) over-approximates which *pairs* of atoms can hold together in a
reachable state: a pair is reached at init, or when an action whose preconditions are
pairwise reached adds both, or adds one while the other (not deleted) is reached with every
precondition. A goal pair never reached can never hold together: a block on two others,
two blocks on one, a package in two places. The fixpoint is sound for any STRIPS task.

The same pairs prove an *invariant* that no single pair shows: a binary predicate (``on``)
stays acyclic when it is acyclic at init and every action that adds an edge ``(on x y)``
needs a precondition that excludes every edge into ``x`` (or every edge out of ``y``): the
new edge cannot close a cycle. A goal whose edges form a cycle is then unsolvable.

``task`` is a `task.symbolic.strips_task.StripsTask` (fluent atoms, actions with fluent
preconditions, adds and deletes).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from task.symbolic.strips import Atom, atom_str


@dataclass(frozen=True, eq=False)
class Pairs:
    """The h^2 fixpoint: ``pairs`` (P, P) bool, symmetric, its diagonal the reached atoms;
    ``applicable`` (G,) bool: actions whose preconditions are pairwise reached."""

    pairs: np.ndarray
    applicable: np.ndarray

    def together(self, i: int, j: int) -> bool:
        """Whether atom columns ``i`` and ``j`` may hold in one reachable state."""
        return bool(self.pairs[i, j])


def _columns(task, atoms) -> np.ndarray:
    return np.array(sorted(task.column[a] for a in atoms if a in task.column), dtype=np.int64)


def h2(task, deadline: float | None = None) -> Pairs | None:
    """The h^2 fixpoint of ``task`` from its initial state; None when ``deadline``
    (``time.perf_counter()`` seconds) passes first (a partial fixpoint proves nothing).

    An action is looked at again only when a row of ``pairs`` it reads (one per
    precondition; the diagonal when it has none) changed since it last was: what it adds
    depends on nothing else."""
    n = len(task.atoms)
    pre = [_columns(task, e.pre_pos) for e in task.effects]
    add = [_columns(task, e.add) for e in task.effects]
    delete = [_columns(task, e.delete - e.add) for e in task.effects]
    pairs = np.zeros((n, n), dtype=bool)  # (P, P)
    init = _columns(task, task.init)
    for row in init:
        pairs[row, init] = True
    applicable = np.zeros(len(task.effects), dtype=bool)  # (G,)
    stamp = np.ones(n + 1, dtype=np.int64)  # (P + 1,) when each row changed; [n]: the diagonal
    seen = np.zeros(len(task.effects), dtype=np.int64)  # (G,) when each action was looked at
    clock, changed = 1, True
    while changed:
        changed = False
        if deadline is not None and time.perf_counter() > deadline:
            return None
        for j, p in enumerate(pre):
            if (stamp[p].max() if p.size else stamp[n]) <= seen[j]:
                continue
            seen[j] = clock
            if not applicable[j]:
                if not pairs[p][:, p].all():
                    continue  # (the diagonal: each precondition reached)
                applicable[j] = True
            a = add[j]
            if not a.size:
                continue
            others = pairs.diagonal().copy() if not p.size else pairs[p].all(axis=0)  # (P,)
            others[delete[j]] = False
            others[a] = True
            q = np.flatnonzero(others)
            new = ~pairs[a][:, q]  # (|a|, |q|)
            if new.any():
                clock += 1
                for row in a:
                    pairs[row, q] = True
                    pairs[q, row] = True
                stamp[a[new.any(axis=1)]] = clock
                stamp[q[new.any(axis=0)]] = clock
                if (np.diag(new[:, np.searchsorted(q, a)]) if a.size else new[:0]).any():
                    stamp[n] = clock
                changed = True
    return Pairs(pairs, applicable)


def goal_conflict(task, found: Pairs) -> str | None:
    """Why the goal is unreachable under h^2 (an atom, or two atoms that never hold
    together), or None."""
    goal = [(a, task.column[a]) for a in task.goal]
    for atom, i in goal:
        if not found.together(i, i):
            return f"goal {atom_str(atom)} is unreachable: {_blocked(task, found, atom)} (h^2)"
    for k, (atom, i) in enumerate(goal):
        for other, j in goal[k + 1 :]:
            if not found.together(i, j):
                return (
                    f"goal atoms {atom_str(atom)} and {atom_str(other)} never hold together "
                    "in a reachable state (h^2 mutex)"
                )
    return None


def _blocked(task, found: Pairs, atom: Atom) -> str:
    """Why no action reaches ``atom``: one achiever and two preconditions that exclude each
    other (or "no action adds it")."""
    for action, effect in zip(task.actions, task.effects, strict=True):
        if atom not in effect.add:
            continue
        cols = sorted((task.column[a], a) for a in effect.pre_pos)
        for x, (i, a) in enumerate(cols):
            for j, b in cols[x:]:
                if not found.together(i, j):
                    if i == j:
                        return f"e.g. {action} needs {atom_str(a)}, which never holds"
                    return (
                        f"e.g. {action} needs {atom_str(a)} and {atom_str(b)}, "
                        "which never hold together"
                    )
    return "no action adds it"


def _cycle(edges: list[tuple[str, str]]) -> list[tuple[str, str]] | None:
    """A cycle among directed ``edges`` (as its edges in order), or None."""
    out: dict[str, list[str]] = {}
    for x, y in edges:
        out.setdefault(x, []).append(y)
    state: dict[str, int] = {}  # 1: on the path, 2: done
    path: list[str] = []

    def visit(x: str) -> list[str] | None:
        state[x] = 1
        path.append(x)
        for y in out.get(x, ()):
            if state.get(y) == 1:
                return path[path.index(y) :]
            if y not in state and (found := visit(y)):
                return found
        path.pop()
        state[x] = 2
        return None

    for start in sorted(out):
        if start not in state and (loop := visit(start)):
            return list(zip(loop, loop[1:] + loop[:1], strict=True))
    return None


def _excludes(task, found: Pairs, pre: list[int], atoms: list[Atom]) -> bool:
    """Whether some precondition column in ``pre`` never holds with any of ``atoms`` (or
    there are none to exclude)."""
    cols = [task.column[a] for a in atoms if a in task.column]
    if len(cols) < len(atoms):
        return False  # a static atom among them: it always holds
    if not cols:
        return True
    return any(not found.pairs[i, cols].any() for i in pre)


def acyclic(task, found: Pairs, pred: str) -> str | None:
    """Why the binary predicate ``pred`` is acyclic in every reachable state (see the module
    docstring), or None when that cannot be shown this way."""
    holds = [*task.init, *task.static]
    if _cycle([(a[1], a[2]) for a in holds if a[0] == pred and len(a) == 3]):
        return None
    edges = [a for a in (*task.atoms, *task.static) if a[0] == pred and len(a) == 3]
    into: dict[str, list[Atom]] = {}
    out: dict[str, list[Atom]] = {}
    for a in edges:
        out.setdefault(a[1], []).append(a)
        into.setdefault(a[2], []).append(a)
    for j, effect in enumerate(task.effects):
        added = [a for a in effect.add if a[0] == pred and len(a) == 3]
        if not added or not found.applicable[j]:
            continue
        if len(added) > 1 or added[0][1] == added[0][2]:
            return None
        _, x, y = added[0]
        pre = [task.column[a] for a in effect.pre_pos]
        if not (
            _excludes(task, found, pre, into.get(x, []))
            or _excludes(task, found, pre, out.get(y, []))
        ):
            return None
    return (
        f"{pred} is acyclic at init and every action adding ({pred} x y) needs a precondition "
        f"that excludes any ({pred} ? x) or any ({pred} y ?)"
    )


def goal_cycle(task, found: Pairs, goal: tuple[Atom, ...]) -> str | None:
    """Why ``goal`` (its atoms, static ones included) is unsolvable when its atoms of a
    binary predicate form a cycle that the predicate never has (`acyclic`), or None."""
    preds = sorted({a[0] for a in goal if len(a) == 3})
    for pred in preds:
        loop = _cycle([(a[1], a[2]) for a in goal if a[0] == pred])
        if loop is None:
            continue
        why = acyclic(task, found, pred)
        if why is not None:
            atoms = " ".join(atom_str((pred, x, y)) for x, y in loop)
            return f"goal atoms {atoms} form a cycle, which no reachable state has ({why})"
    return None
