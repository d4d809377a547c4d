"""Sokoban's crisp side: the static grid tables, the rules of a move, and the bounds.

`Grid` (``problem.data``) holds the static part of a problem and the tables derived from it:
neighbours per direction, robot distances, the robot's regions with a box on a cell (`zones`),
push distances over box cell x robot region (`push_dist`) and the fewest actions that take a
lone box to a goal from every box and robot cell (`lone_cost`). A crisp state is the cell of
every entity, ``(robot, box...)``; a move is ``Move("robot", dir)``: a step onto a free cell,
or a push when a box is ahead and the cell behind it is free.

`lower_bound` is admissible, INF at a dead end: a box on a dead cell, a box off its goal that
never moves in a plan reaching the goal (blocked by walls and such boxes, pushable only from
cells the robot cannot reach, or only onto dead cells), or no push the robot can reach. It is
the max of (1) pushes + the robot's walk to its first push, ``sum_b pd_b + min(useful walk, any
walk + 2 on a bipartite grid)``, and (2) the lone-box cost of every box (the plan restricted to
the robot and that box is a plan of the lone-box problem).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from task.errors import ProblemError, one_of
from task.problem import Move, Problem

INF = math.inf
ROBOT = "robot"
State = tuple[str, ...]


@dataclass(frozen=True)
class Grid:
    """The static part of a Sokoban problem; cell indices follow ``cells`` (= problem.fixed)."""

    locs: tuple[str, ...]  # every LOC object in file order, walls too
    dirs: tuple[str, ...]  # DIR objects in action-column order
    boxes: tuple[str, ...]  # BOX objects in file order
    adjacent: tuple[tuple[str, str, str], ...]  # every (adjacent l1 l2 d) fact
    cells: tuple[str, ...]  # the non-wall cells
    cache: dict = field(default_factory=dict, compare=False, repr=False)  # derived tables

    @functools.cached_property
    def index(self) -> dict[str, int]:
        return {c: i for i, c in enumerate(self.cells)}

    @functools.cached_property
    def ahead(self) -> dict[tuple[str, str], str]:
        """(loc, dir) -> the loc ``dir`` of it (walls included)."""
        return {(a, d): b for a, b, d in self.adjacent}

    @functools.cached_property
    def nbr(self) -> tuple[tuple[int, ...], ...]:
        """(C, D): index of the non-wall cell ``dir`` of each cell, -1 for a wall or the edge."""
        get = self.ahead.get
        return tuple(
            tuple(self.index.get(get((c, d), ""), -1) for d in self.dirs) for c in self.cells
        )

    @functools.cached_property
    def back(self) -> tuple[tuple[int, ...], ...]:
        """(C, D): the cell from which a step ``dir`` enters each cell, -1 if none."""
        out = [[-1] * len(self.dirs) for _ in self.cells]
        for i, row in enumerate(self.nbr):
            for d, j in enumerate(row):
                out[j][d] = i if j >= 0 else out[j][d]
        return tuple(map(tuple, out))

    @functools.cached_property
    def bipartite(self) -> bool:
        """Whether the cell graph has no odd cycle (true of any grid); then a push that does
        not shorten a box's push distance lengthens it (parity)."""
        colour: dict[int, float] = {}
        for s in (s for s in range(len(self.cells)) if s not in colour):
            colour |= {i: d % 2 for i, d in enumerate(self.bfs(s)) if d < INF}
        return all(colour[i] != colour[j] for i, row in enumerate(self.nbr) for j in row if j >= 0)

    def bfs(self, start: int, blocked: Iterable[int] = ()) -> tuple[float, ...]:
        """Robot distances from cell ``start`` avoiding the ``blocked`` cells (and walls)."""
        out, stop = [INF] * len(self.cells), set(blocked)
        out[start], queue = 0, [start]
        for i in queue:
            for j in self.nbr[i]:
                if j >= 0 and out[j] == INF and j not in stop:
                    out[j] = out[i] + 1
                    queue.append(j)
        return tuple(out)

    def zones(self, blocked: frozenset[int] = frozenset()) -> tuple[tuple[int, ...], ...]:
        """(C, C): with a box on cell c and boxes that never move on ``blocked``, the robot's
        region (its least cell) of every cell, -1 on c and blocked cells. Cached."""
        key = ("zones", blocked)
        if key not in self.cache:
            rows = []
            for c in range(len(self.cells)):
                zone = [-1] * len(self.cells)
                for s in (s for s in range(len(self.cells)) if s != c and s not in blocked):
                    if zone[s] < 0:
                        zone[s], queue = s, [s]
                        for i in queue:
                            for j in self.nbr[i]:
                                if j >= 0 and zone[j] < 0 and j != c and j not in blocked:
                                    zone[j] = s
                                    queue.append(j)
                rows.append(tuple(zone))
            self.cache[key] = tuple(rows)
        return self.cache[key]

    def push_dist(self, goal: int, blocked: frozenset[int] = frozenset()) -> tuple[dict, ...]:
        """Pushes that take a lone box to ``goal``: per cell c, {robot zone: pushes} (reverse
        BFS over box cell x robot region; no entry: dead), with ``blocked`` cells filled."""
        key = ("push", goal, blocked)
        if key not in self.cache:
            zone = self.zones(blocked)
            out: list[dict] = [{} for _ in self.cells]
            out[goal] = dict.fromkeys(set(zone[goal]) - {-1}, 0)
            queue = [(goal, z) for z in out[goal]]
            for j, zj in queue:
                for d, c in enumerate(self.back[j]):  # the box came from c, the robot ends on c
                    r = self.back[c][d] if c >= 0 and zone[j][c] == zj else -1
                    if r >= 0 and r not in blocked and zone[c][r] not in out[c]:
                        out[c][zone[c][r]] = out[j][zj] + 1
                        queue.append((c, zone[c][r]))
            self.cache[key] = tuple(out)
        return self.cache[key]

    def lone_cost(self, goal: int) -> tuple[tuple[float, ...], ...]:
        """(C_box, C_robot): fewest actions that take a lone box on c to ``goal`` with the
        robot on r (reverse BFS over moves and pulls), INF where it cannot. Cached."""
        key = ("lone", goal)
        if key not in self.cache:
            cost = [[INF] * len(self.cells) for _ in self.cells]
            queue = [(goal, r) for r in range(len(self.cells)) if r != goal]
            for _, r in queue:
                cost[goal][r] = 0
            for c, r in queue:
                for d, q in enumerate(self.back[r]):  # the robot stepped from q onto r
                    if q >= 0 and q != c and cost[c][q] == INF:
                        cost[c][q] = cost[c][r] + 1
                        queue.append((c, q))
                    if q >= 0 and self.nbr[r][d] == c and cost[r][q] == INF:  # pushed r -> c
                        cost[r][q] = cost[c][r] + 1
                        queue.append((r, q))
            self.cache[key] = tuple(map(tuple, cost))
        return self.cache[key]


def grid(problem: Problem) -> Grid:
    """The `Grid` of a Sokoban problem; ProblemError for a problem of another domain."""
    if not isinstance(problem.data, Grid):
        raise ProblemError(f"problem {problem.name} is not a Sokoban problem (no grid in data)")
    return problem.data


def goals(problem: Problem) -> dict[int, int]:
    """Box number (row - 1) -> its goal cell, for the boxes the goal places."""
    return {problem.entities.index(b) - 1: grid(problem).index[c] for b, c in problem.goal}


# -------------------------------------------------------------------------------------- rules


def initial_state(problem: Problem) -> State:
    return tuple(problem.init)


def _ahead(problem: Problem, state: State, move: Move) -> tuple[str | None, str | None]:
    """(cell ahead of the robot, cell behind it) by name, walls included; ProblemError for an
    unknown mover or direction."""
    g = grid(problem)
    if move.entity != ROBOT:
        raise ProblemError(f"only the robot moves, not {one_of(move.entity, (ROBOT,))}")
    if move.target not in g.dirs:
        raise ProblemError(f"unknown direction {one_of(move.target, g.dirs)}")
    one = g.ahead.get((state[0], move.target))
    return one, None if one is None else g.ahead.get((one, move.target))


def check_move(problem: Problem, state: State, move: Move) -> str | None:
    """None if ``move`` is legal in ``state``, else a one-line reason."""
    one, two = _ahead(problem, state, move)
    cells, d = grid(problem).cells, move.target
    if one is None or one not in cells:
        return f"{d} of {state[0]} is {'the edge' if one is None else 'a wall'}"
    if one not in state[1:]:
        return None
    box = problem.entities[state.index(one, 1)]
    if two is None or two not in cells:
        return f"{box} cannot be pushed {d}: {'the edge' if two is None else 'a wall'} is behind"
    if two in state[1:]:
        return f"{box} cannot be pushed {d}: {problem.entities[state.index(two, 1)]} is behind"
    return None


def apply_move(problem: Problem, state: State, move: Move) -> State:
    """The state after ``move``; ProblemError if it is illegal."""
    reason = check_move(problem, state, move)
    if reason is not None:
        raise ProblemError(f"illegal {move}: {reason}")
    one, two = _ahead(problem, state, move)
    return tuple(one if k == 0 else two if c == one else c for k, c in enumerate(state))


def legal_moves(problem: Problem, state: State) -> list[Move]:
    moves = [Move(ROBOT, d) for d in grid(problem).dirs]
    return [m for m in moves if check_move(problem, state, m) is None]


def is_goal(problem: Problem, state: State) -> bool:
    return all(state[problem.entities.index(b)] == c for b, c in problem.goal)


# ------------------------------------------------------------------------------------ bounds


def _pushes(g, goal: int, walls: frozenset, c: int, r: int) -> float:
    """Pushes that take a lone box on cell c to ``goal``, the robot on r (INF: dead)."""
    return g.push_dist(goal, walls)[c].get(g.zones(walls)[c][r], INF)


def _stuck(g, at: Sequence[int], goal: dict, robot: int) -> frozenset[int]:
    """Cells of the boxes that never move in a plan that reaches the goal: the greatest set
    whose every push is blocked (a wall, a box of the set), needs the robot on a cell it can
    never reach, or leaves the box on a dead cell; grown again with its cells as walls."""
    walls, where = frozenset(), {c: k for k, c in enumerate(at)}
    while True:
        zone, stuck, changed = g.zones(walls), set(range(len(at))), True
        while changed:
            changed = False
            for k in sorted(stuck):
                for f, r in zip(g.nbr[at[k]], g.back[at[k]], strict=True):
                    if min(f, r) < 0 or {where.get(f), where.get(r)} & stuck or {f, r} & walls:
                        continue
                    if zone[at[k]][r] != zone[at[k]][robot]:
                        continue
                    if k not in goal or _pushes(g, goal[k], walls, f, at[k]) < INF:
                        stuck.discard(k)
                        changed = True
                        break
        cells = frozenset(at[k] for k in stuck)
        if cells <= walls:
            return walls
        walls |= cells


def lower_bound(problem: Problem, state: State) -> float:
    """An admissible bound on the moves to the goal; INF at a dead end (see module doc)."""
    g = grid(problem)
    key = ("bound", tuple(state))
    if key not in g.cache:
        g.cache[key] = _bound(problem, g, state)
    return g.cache[key]


def _bound(problem: Problem, g, state: State) -> float:
    at, robot, goal = [g.index[c] for c in state[1:]], g.index[state[0]], goals(problem)
    todo = [k for k, c in goal.items() if at[k] != c]
    walls = _stuck(g, at, goal, robot) if todo else frozenset()
    if not todo or any(at[k] in walls for k in todo):
        return INF if todo else 0.0
    zone = g.zones(walls)
    pushes = [_pushes(g, goal[k], walls, at[k], robot) for k in todo]
    reach = g.bfs(robot, walls | {at[k] for k in todo})
    any_w, use_w = INF, INF
    for k, base in zip(todo, pushes, strict=True):
        c = at[k]
        for f, r in zip(g.nbr[c], g.back[c], strict=True):
            if min(f, r) < 0 or {f, r} & walls or zone[c][r] != zone[c][robot]:
                continue
            after = _pushes(g, goal[k], walls, f, c)
            if after < INF:
                any_w = min(any_w, reach[r])
                use_w = min(use_w, reach[r]) if after < base else use_w
    if any_w == INF or INF in pushes:
        return INF
    walk = min(use_w, any_w + (2 if g.bipartite else 1))
    lone = max(g.lone_cost(goal[k])[at[k]][robot] for k in todo)
    return float(max(sum(pushes) + walk, lone))


def ends(g, goal: int) -> set[int]:
    """Cells the robot stands on right after the last push of a box onto ``goal``."""
    return {i for d, i in enumerate(g.back[goal]) if i >= 0 and g.back[i][d] >= 0}
