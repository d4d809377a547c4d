"""Optimal reference planners: A* over blocksworld moves, breadth-first search over STRIPS.

`optimal_moves` is A* over relational states (the support of every block) with unit move costs
and the admissible, consistent "must move" heuristic: a block must move at least once if its
support differs from its goal support, if it rests on a block that another block must end up
on, or if it rests on a block that must move. One move changes only the moved block's status,
so the count drops by at most one per move. The 4-op optimal plan length is ``2 * moves``.

`optimal_length_strips` is plain breadth-first search over the generic STRIPS semantics, kept
independent of the blocksworld code so tests can cross-check the two on small problems.
"""

from __future__ import annotations

import functools
import heapq
import itertools
from collections import deque

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task.errors import ProblemError
from task.problem import TABLE, Move, Problem
from task.symbolic import strips

_Code = tuple[int, ...]  # support index of each entity; n (== len) stands for the table


def _encode(problem: Problem) -> tuple[_Code, dict[int, int]]:
    names = {name: i for i, name in enumerate(problem.targets)}
    if len(problem.fixed) != 1:
        raise ProblemError(
            f"blocksworld search needs exactly one fixed target, got {problem.fixed}"
        )
    start = tuple(names[s] for s in problem.init)
    goal = {names[x]: names[y] for x, y in problem.goal}
    return start, goal


def _heuristic(state: _Code, goal: dict[int, int], claimed: dict[int, int]) -> int:
    """Number of blocks that must move at least once (see the module docstring). Codes: the
    blocks 0..n-1, the table n, fixed places (slots) above n; a goal of the table is met on
    the table or on any slot, a goal of a slot only there."""
    n = len(state)
    must: list[bool | None] = [None] * n

    def moves(x: int) -> bool:
        if must[x] is None:
            s = state[x]
            g = goal.get(x, s)
            met = g == s or (g == n and s > n)
            taken = s != n and claimed.get(s, x) != x  # another block's goal support
            must[x] = not met or taken or (s < n and moves(s))
        return bool(must[x])

    return sum(moves(x) for x in range(n))


def moves_lower_bound(problem: Problem, state: tuple[str, ...]) -> int:
    """Admissible lower bound on the moves still needed from ``state`` (crisp supports).

    Table slots (`task.domains.blocksworld.slotted`) count as the table where the goal names
    the table (the bound ignores their capacity: a relaxation, so it stays admissible); a
    block whose goal is one slot must move while it stands anywhere else (the geometric
    planner's region cells: without this the bound was blind to every cell goal), and a block
    standing on a slot another block's goal names must move too (a slot holds one tower: a base
    sent to a place with room, `tamp.slots.room_goals`, needs that place cleared)."""
    names, goal, claimed = _bound_codes(problem)
    return _heuristic(tuple(names[s] for s in state), goal, claimed)


@functools.lru_cache(maxsize=256)
def _bound_codes(problem: Problem) -> tuple[dict[str, int], dict[int, int], dict[int, int]]:
    """`moves_lower_bound`'s codes of ``problem``, built once per problem (a search calls the
    bound for every state it generates): each name's code, the goal and the claimed targets.
    Read only."""
    n = problem.n
    names = {name: i if i < n else n + 1 + i for i, name in enumerate(problem.targets)}
    names[TABLE] = n
    goal = {names[x]: names[y] for x, y in problem.goal}
    return names, goal, {y: x for x, y in goal.items() if y != n}


def _successors(state: _Code) -> list[tuple[int, int]]:
    n = len(state)
    clear = sorted(set(range(n)) - set(state))
    out = [(x, n) for x in clear if state[x] != n]
    out += [(x, y) for x in clear for y in clear if x != y and state[x] != y]
    return out


def optimal_moves(problem: Problem, max_nodes: int = 200_000) -> tuple[Move, ...] | None:
    """A shortest move sequence from init to the goal, or None after ``max_nodes`` expansions.

    Raises ProblemError if the whole reachable space is exhausted (an unsatisfiable goal).
    """
    start, goal = _encode(problem)
    claimed = {y: x for x, y in goal.items() if y < len(start)}
    targets = problem.targets
    g: dict[_Code, int] = {start: 0}
    parent: dict[_Code, tuple[_Code, tuple[int, int]]] = {}
    tie = itertools.count()
    frontier = [(_heuristic(start, goal, claimed), 0, next(tie), start)]
    expanded = 0
    while frontier:
        _, neg_g, _, state = heapq.heappop(frontier)
        if -neg_g > g[state]:
            continue  # stale entry
        if all(state[x] == y for x, y in goal.items()):
            path = []
            while state in parent:
                state, (x, y) = parent[state]
                path.append(Move(targets[x], targets[y]))
            return tuple(reversed(path))
        expanded += 1
        if expanded > max_nodes:
            return None
        for x, y in _successors(state):
            nxt = (*state[:x], y, *state[x + 1 :])
            cost = g[state] + 1
            if cost < g.get(nxt, cost + 1):
                g[nxt] = cost
                parent[nxt] = (state, (x, y))
                f = cost + _heuristic(nxt, goal, claimed)
                heapq.heappush(frontier, (f, -cost, next(tie), nxt))
    raise ProblemError(f"unsolvable goal: no state reachable from init satisfies {problem.goal}")


def optimal_length_strips(
    domain: Domain, problem: PDDLProblem, max_nodes: int = 200_000
) -> int | None:
    """The optimal number of actions by breadth-first search over ground STRIPS actions.

    None once more than ``max_nodes`` states have been generated, or if the goal is unreachable.
    """
    actions = [ga for _, ga in strips.ground_all(domain, problem)]
    goal = strips.goal_atoms(problem)
    start = strips.initial_state(problem)
    if strips.holds(start, goal):
        return 0
    depth = {start: 0}
    queue = deque([start])
    while queue and len(depth) <= max_nodes:
        state = queue.popleft()
        for ga in actions:
            if strips.applicable(state, ga):
                nxt = strips.apply(state, ga)
                if nxt not in depth:
                    depth[nxt] = depth[state] + 1
                    if strips.holds(nxt, goal):
                        return depth[nxt]
                    queue.append(nxt)
    return None
