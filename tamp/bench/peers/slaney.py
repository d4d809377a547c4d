"""Slaney & Thiébaux's near-optimal Blocksworld algorithms, as baselines beside ours.

J. Slaney and S. Thiébaux, "Blocks World revisited", Artificial Intelligence 125 (2001), and
"Linear time near-optimal planning in the Blocks World" (AAAI 1996). Both algorithms rest on
one notion: a block is *in position* when it never has to move again, and *misplaced*
otherwise. Here, for goals that name a support for some blocks only (PlanBench's and our
random problems' goals list the ``on`` atoms):

- a block with a goal support is in position when it stands on that support and the support is
  the table or a block in position;
- a block the goal leaves free is in position when it stands on the table, or on a block in
  position that no goal asks another block to stand on.

Every misplaced block moves at least once in any plan (it stands on the wrong support, or on a
block that must move, or where another block must go), and a *constructive* move (a clear
misplaced block onto the table when the table is where it belongs or the goal leaves it free, or
onto its goal support when that support is in position and clear) puts a block in position for
good.

- **US** (unstack-stack): move every misplaced block that is not on the table to the table,
  then make constructive moves until the goal holds. Each misplaced block moves at most twice,
  so US is at most twice the optimum.
- **GN1** (Gupta & Nau's algorithm as Slaney & Thiébaux state it): make a constructive move
  whenever one exists; otherwise move a clear *deadlocked* block to the table (`deadlocked`:
  misplaced a and b stand in N(a, b) when b is above some block x now and the goal puts a
  above x; a deadlock is a cycle of N). GN1 moves a block to the table only when it is
  misplaced, off the table, and no constructive move exists, and every block it moves goes in
  position by its next move, so it is never longer than US.

The paper's versions run in linear time with incremental bookkeeping; these recompute the
positions after each move (quadratic, a few milliseconds at 100 blocks), which changes the
plans' lengths not at all. Plans are sequences of `task.problem.Move` checked move by move
with the Blocksworld rules; the benchmark validates them against the PDDL too.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from task.domains import blocksworld
from task.domains.blocksworld import TABLE
from task.errors import ProblemError, TampError, one_of
from task.problem import Move, Problem

State = tuple  # the support of each block, in entity order (`blocksworld.initial_state`)


def in_position(problem: Problem, state: State) -> dict[str, bool]:
    """Per block, whether it never has to move again (the module docstring's definition)."""
    on = dict(zip(problem.entities, state, strict=True))
    goal = dict(problem.goal)
    wanted = {y for y in goal.values() if y != TABLE}
    known: dict[str, bool] = {}
    for x in problem.entities:
        chain = []  # x and the blocks below it whose position is not known yet
        y = x
        while y != TABLE and y not in known:
            chain.append(y)
            y = on[y]
        for z in reversed(chain):  # bottom up: each block's support is known first
            below = on[z]
            ready = below == TABLE or known[below]
            if z in goal:
                known[z] = below == goal[z] and ready
            else:
                known[z] = below == TABLE or (ready and below not in wanted)
    return known


def _clear(state: State, entities: Sequence[str]) -> set[str]:
    covered = set(state)
    return {x for x in entities if x not in covered}


def constructive(problem: Problem, state: State) -> list[Move]:
    """Every constructive move in ``state``, blocks in entity order."""
    placed = in_position(problem, state)
    clear = _clear(state, problem.entities)
    goal = dict(problem.goal)
    on = dict(zip(problem.entities, state, strict=True))
    out = []
    for x in problem.entities:
        if placed[x] or x not in clear:
            continue
        target = goal.get(x, TABLE)
        if target == TABLE and on[x] != TABLE:
            out.append(Move(x, TABLE))
        elif target != TABLE and placed[target] and target in clear:
            out.append(Move(x, target))
    return out


def _to_table(problem: Problem, state: State) -> list[Move]:
    """The clear misplaced blocks off the table, as moves to the table (entity order)."""
    placed = in_position(problem, state)
    clear = _clear(state, problem.entities)
    on = dict(zip(problem.entities, state, strict=True))
    return [
        Move(x, TABLE) for x in problem.entities if x in clear and not placed[x] and on[x] != TABLE
    ]


def _check(problem: Problem) -> None:
    if problem.domain != blocksworld.NAME or blocksworld.slotted(problem):
        raise TampError(
            f"Slaney & Thiébaux's algorithms plan plain Blocksworld problems; {problem.name} is "
            f"{'a slotted table' if problem.domain == blocksworld.NAME else problem.domain}"
        )


def _apply(problem: Problem, state: State, move: Move, moves: list[Move]) -> State:
    reason = blocksworld.check_move(problem, state, move)
    if reason is not None:  # a bug here, never the problem's fault
        raise ProblemError(f"{problem.name}: baseline move {move} is illegal: {reason}")
    moves.append(move)
    return blocksworld.apply_move(problem, state, move)


def _bounded(problem: Problem) -> int:
    return 2 * problem.n + 1  # each block moves at most twice


def us(problem: Problem) -> tuple[Move, ...]:
    """US: every misplaced block off the table to the table, then constructive moves."""
    _check(problem)
    state, moves = blocksworld.initial_state(problem), []
    while table := _to_table(problem, state):
        for move in table:  # all clear at once: moving one uncovers the next round's
            state = _apply(problem, state, move, moves)
    while not blocksworld.is_goal(problem, state):
        good = constructive(problem, state)
        if not good or len(moves) > _bounded(problem):
            raise ProblemError(f"{problem.name}: US found no constructive move; a bug")
        state = _apply(problem, state, good[0], moves)
    return tuple(moves)


def gn1(problem: Problem) -> tuple[Move, ...]:
    """GN1: a constructive move when there is one, else a deadlock-breaking move to the table."""
    _check(problem)
    state, moves = blocksworld.initial_state(problem), []
    while not blocksworld.is_goal(problem, state):
        if len(moves) > _bounded(problem):
            raise ProblemError(f"{problem.name}: GN1 exceeded two moves per block; a bug")
        good = constructive(problem, state)
        if good:
            state = _apply(problem, state, good[0], moves)
            continue
        table = _to_table(problem, state)
        if not table:
            raise ProblemError(f"{problem.name}: GN1 found no move; a bug")
        stuck = deadlocked(problem, state)
        chosen = [m for m in table if m.entity in stuck]
        state = _apply(problem, state, (chosen or table)[0], moves)
    return tuple(moves)


def deadlocked(problem: Problem, state: State) -> set[str]:
    """The blocks in a deadlock in ``state`` (Gupta & Nau; Slaney & Thiébaux's form): misplaced
    blocks a, b stand in N(a, b) when b is above some block x now and the goal puts a above x
    (so b must move before a can go in position); a deadlock is a cycle of N, and a block is
    deadlocked when it lies on one (a strongly connected component of N with an edge inside)."""
    placed = in_position(problem, state)
    on = dict(zip(problem.entities, state, strict=True))
    goal = dict(problem.goal)
    misplaced = [x for x in problem.entities if not placed[x]]

    def above(support: dict, x: str) -> set[str]:
        out, y = set(), support.get(x, TABLE)
        while y != TABLE and y not in out:
            out.add(y)
            y = support.get(y, TABLE)
        return out

    now = {b: above(on, b) for b in misplaced}
    wanted = {a: above(goal, a) for a in misplaced}
    edges = {a: [b for b in misplaced if now[b] & wanted[a]] for a in misplaced}
    return _on_cycles(misplaced, edges)


def _on_cycles(nodes: Sequence[str], edges: dict[str, list[str]]) -> set[str]:
    """The nodes on a cycle of the directed graph (Tarjan's strongly connected components,
    iterative: a component of two or more nodes, or one node with an edge to itself)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: set[str] = set()
    for root in nodes:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            v, i = work.pop()
            if i == 0:
                index[v] = low[v] = len(index)
                stack.append(v)
                on_stack.add(v)
            if i < len(edges[v]):
                work.append((v, i + 1))
                w = edges[v][i]
                if w not in index:
                    work.append((w, 0))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            if low[v] == index[v]:
                component = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    component.append(w)
                    if w == v:
                        break
                if len(component) > 1 or v in edges[v]:
                    out.update(component)
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[v])
    return out


BASELINES: dict[str, Callable[[Problem], tuple[Move, ...]]] = {"us": us, "gn1": gn1}
LABELS = {"us": "US", "gn1": "GN1"}


@dataclass(frozen=True)
class Baseline:
    """One baseline's plan of one problem: its moves and the seconds it took."""

    name: str
    moves: tuple[Move, ...]
    seconds: float


def run(name: str, problem: Problem) -> Baseline:
    """Baseline ``name`` (`BASELINES`) on ``problem``, timed."""
    if name not in BASELINES:
        raise TampError(f"unknown baseline {one_of(name, BASELINES)}")
    start = time.perf_counter()
    moves = BASELINES[name](problem)
    return Baseline(name, moves, time.perf_counter() - start)
