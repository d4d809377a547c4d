"""Best-first search over crisp states with feasibility checked lazily: the planner's complete
fallback (`task.planner`), PDDLStream's incremental idea in its simplest form.

The search runs A* over the crisp states of any domain that
gives ``legal_moves``, ``apply_move``, ``is_goal`` and an admissible ``lower_bound`` (every
`task.domains.base.Domain` does), with unit move costs. Each move is also a geometric choice
that may not be executable (the arm cannot reach it, it failed there before): a callback
``feasible(state, move) -> bool`` says so. It is called only when the search pops the move, i.e.
when the move would close its successor state, and each answer is cached: a move found
infeasible is pruned from that state only (the successor may still be reached another way), and
the search continues. Successors are generated optimistically, so a move that is never popped
is never checked.

The search is complete over these choices (the domain's crisp moves, minus the ones ``feasible``
rules out, states the lower bound calls dead ends cut): it ends ``SOLVED`` with a plan,
``UNSOLVABLE`` when the reachable feasible space is exhausted without a goal (no plan exists
within these choices), or ``BUDGET`` when ``max_nodes`` expansions or the deadline run out.
A plan is a shortest one among the feasible moves.

``below`` bounds the plans sought (`improve`, the planner's anytime improvement): a
successor whose moves so far plus lower bound reach ``below`` is cut, so only plans of fewer
than ``below`` moves are found, and UNSOLVABLE then says that none exists within these choices
(a plan of ``below`` moves in hand is then a shortest one).

`lazy_greedy` is the same search made greedy, for problems far beyond A*'s reach (the generic
STRIPS lift's fallback, `PlannerConfig.fallback_search`): Fast Downward's lazy greedy
best-first search on the domain's inadmissible ``estimate`` (h_FF for the lift), with deferred
evaluation and the domain's ``helpful`` moves as preferred operators. Equally complete, same
statuses; its plans are not shortest (`task.symbolic.shorten` takes detours out).
"""

from __future__ import annotations

import enum
import heapq
import itertools
import math
import time
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from typing import Protocol

from task.problem import Move, Problem

Feasible = Callable[[Hashable, Move], bool]  # (state, move) -> whether it can be executed


class CrispDomain(Protocol):
    """The crisp side of a domain the search needs (`task.domains.base.Domain` has it)."""

    def legal_moves(self, problem: Problem, state: Hashable) -> list[Move]: ...

    def apply_move(self, problem: Problem, state: Hashable, move: Move) -> Hashable: ...

    def is_goal(self, problem: Problem, state: Hashable) -> bool: ...

    def lower_bound(self, problem: Problem, state: Hashable) -> float: ...


class SearchStatus(enum.Enum):
    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"  # every reachable state expanded: no plan within these choices
    BUDGET = "budget"  # the node budget or the deadline ran out first
    DEAD_END = "dead_end"  # none from this state, though one may exist from an earlier one
    # (`task.planner` says so when the windows led into such a state)


@dataclass(frozen=True)
class LazyResult:
    """What the lazy search found, and what it cost."""

    status: SearchStatus
    moves: tuple[Move, ...]  # the plan (empty unless SOLVED; empty too when start is a goal)
    expanded: int  # states expanded (their legal moves generated)
    checked: int  # feasibility checks made (cache misses of ``feasible``)
    ruled_out: int  # distinct (state, move) pairs ``feasible`` ruled out
    time_s: float
    reason: str  # one line: what the status means here
    from_start: bool = False  # the plan starts at the initial state, not where the search was
    # asked to start (`task.planner`'s fallback starting over: the windows' moves are dropped)

    def stats(self) -> dict:
        """A JSON-ready summary for a planner result's ``stats``."""
        return {
            "status": self.status.value,
            "moves": len(self.moves),
            "expanded": self.expanded,
            "checked": self.checked,
            "ruled_out": self.ruled_out,
            "time_s": self.time_s,
            "reason": self.reason,
            "from_start": self.from_start,
        }


class _Checks:
    """The lazy feasibility checks of one search, started now: each (state, move) pair is
    checked by ``feasible`` (None: every move is allowed) at most once, when the search first
    needs it."""

    def __init__(self, feasible: Feasible | None) -> None:
        self.feasible, self.t0 = feasible, time.perf_counter()
        self.allowed: dict[tuple[Hashable, Move], bool] = {}
        self.checked = 0  # cache misses

    def ok(self, state: Hashable, move: Move) -> bool:
        key = (state, move)
        if key not in self.allowed:
            self.checked += 1
            self.allowed[key] = True if self.feasible is None else bool(self.feasible(state, move))
        return self.allowed[key]

    def ruled_out(self) -> int:
        """Distinct (state, move) pairs ruled out so far."""
        return sum(not v for v in self.allowed.values())

    def result(
        self, status: SearchStatus, moves: tuple[Move, ...], expanded: int, reason: str
    ) -> LazyResult:
        """The search's result after ``expanded`` expansions, timed from the start."""
        elapsed = time.perf_counter() - self.t0
        return LazyResult(status, moves, expanded, self.checked, self.ruled_out(), elapsed, reason)


def _path(parent: dict[Hashable, tuple[Hashable, Move] | None], state: Hashable) -> tuple:
    """The moves from the search's start to the closed ``state``, traced back through
    ``parent`` (None at the start)."""
    path = []
    while parent[state] is not None:
        state, move = parent[state]
        path.append(move)
    path.reverse()
    return tuple(path)


def lazy_best_first(
    domain: CrispDomain,
    problem: Problem,
    start: Hashable,
    feasible: Feasible | None = None,
    max_nodes: int = 20_000,
    deadline: float | None = None,
    below: float = math.inf,
) -> LazyResult:
    """Plan from crisp ``start`` to ``problem``'s goal over ``domain``'s moves that ``feasible``
    allows (None: all), checked lazily (see the module docstring). ``deadline``: a
    ``time.perf_counter()`` value after which the search stops with BUDGET. ``below``: only
    plans of fewer moves (states with moves so far + lower bound >= ``below`` are cut)."""
    checks = _Checks(feasible)

    def done(status: SearchStatus, moves: tuple[Move, ...], reason: str) -> LazyResult:
        return checks.result(status, moves, expanded, reason)

    # one heap entry per (state, g); the moves reaching the state at that g wait in ``pending``
    # and are checked in order when the entry pops, until one is feasible
    parent: dict[Hashable, tuple[Hashable, Move] | None] = {}  # closed states
    pending: dict[Hashable, dict[int, list[tuple[Hashable, Move]]]] = {}
    tie = itertools.count()
    frontier: list[tuple[float, int, int, Hashable]] = []
    expanded = 0
    h0 = domain.lower_bound(problem, start)
    if math.isinf(h0):
        return done(SearchStatus.UNSOLVABLE, (), "the start is a dead end (lower bound INF)")
    if h0 >= below:
        why = f"no plan of fewer than {below:g} moves: the lower bound from the start is {h0:g}"
        return done(SearchStatus.UNSOLVABLE, (), why)
    heapq.heappush(frontier, (h0, 0, next(tie), start))
    pending[start] = {0: []}
    while frontier:
        _, neg_g, _, state = heapq.heappop(frontier)
        if state in parent:
            continue
        g = -neg_g
        ways = pending[state].pop(g, [])
        if state == start and g == 0:
            parent[state] = None
        else:
            way = next((w for w in ways if checks.ok(*w)), None)
            if way is None:
                continue  # every move reaching it at this depth is ruled out: maybe later
            parent[state] = way
        del pending[state]
        if domain.is_goal(problem, state):
            path = _path(parent, state)
            return done(SearchStatus.SOLVED, path, f"a plan of {len(path)} moves")
        if expanded >= max_nodes:
            return done(SearchStatus.BUDGET, (), f"stopped after {expanded} expansions (budget)")
        if deadline is not None and time.perf_counter() > deadline:
            return done(SearchStatus.BUDGET, (), f"stopped after {expanded} expansions (time)")
        expanded += 1
        for move in domain.legal_moves(problem, state):
            nxt = domain.apply_move(problem, state, move)
            if nxt in parent:
                continue
            h = domain.lower_bound(problem, nxt)
            if math.isinf(h) or g + 1 + h >= below:
                continue  # a dead end, or no plan through it is shorter than ``below``
            at = pending.setdefault(nxt, {})
            if g + 1 not in at:
                at[g + 1] = []
                heapq.heappush(frontier, (g + 1 + h, -(g + 1), next(tie), nxt))
            at[g + 1].append((state, move))
    ruled = checks.ruled_out()
    shorter = "" if math.isinf(below) else f" of fewer than {below:g} moves"
    return done(
        SearchStatus.UNSOLVABLE,
        (),
        f"no plan{shorter} exists within these choices: {len(parent)} reachable states "
        f"expanded, {ruled} moves ruled out",
    )


class GuidedDomain(CrispDomain, Protocol):
    """A crisp domain with a cost-to-go ``estimate`` (INF at a dead end; inadmissible where the
    domain has its own, else its ``lower_bound``: `task.domains.base.DomainBase`) and the moves
    worth trying first, ``helpful(problem, state)`` (none by default)."""

    def estimate(self, problem: Problem, state: Hashable) -> float: ...

    def helpful(self, problem: Problem, state: Hashable) -> frozenset: ...


BOOST = 1000  # preferred-queue pops granted on each new best estimate (Fast Downward's boost)


def lazy_greedy(
    domain: GuidedDomain,
    problem: Problem,
    start: Hashable,
    feasible: Feasible | None = None,
    max_nodes: int = 20_000,
    deadline: float | None = None,
) -> LazyResult:
    """Greedy best-first search on ``domain.estimate`` (else its lower bound) with deferred
    evaluation and preferred operators, as Fast Downward's lazy GBFS (Richter & Helmert 2009): a
    queue entry is a (state, move) pair ranked by its parent's estimate; the successor is made, and
    its estimate computed, only when the entry pops, and the move's feasibility is checked then (as
    in `lazy_best_first`). The domain's ``helpful`` moves also enter a second queue; the
    two alternate, and every new best estimate grants the preferred queue ``BOOST`` pops.

    Complete over the same choices as `lazy_best_first` (every reachable state is closed once;
    states the estimate calls dead ends, INF, are cut), but the plan need not be shortest.
    Ends SOLVED, UNSOLVABLE or BUDGET (``max_nodes`` expansions or ``deadline``)."""
    checks = _Checks(feasible)
    guide = domain.estimate  # the domain's own, else its lower bound (`DomainBase`)

    def done(status: SearchStatus, moves: tuple[Move, ...], reason: str) -> LazyResult:
        return checks.result(status, moves, expanded, reason)

    parent: dict[Hashable, tuple[Hashable, Move] | None] = {start: None}  # closed states
    queues: tuple[list, list] = ([], [])  # every successor; the preferred ones
    credit = [0, 0]  # pops taken from each queue, less the boosts: the lower one pops next
    tie = itertools.count()
    expanded, best = 0, math.inf
    state, h = start, guide(problem, start)
    while True:
        if domain.is_goal(problem, state):
            path = _path(parent, state)
            return done(SearchStatus.SOLVED, path, f"a plan of {len(path)} moves")
        if not math.isinf(h):
            if h < best:
                best = h
                credit[1] -= BOOST
            late = deadline is not None and time.perf_counter() > deadline
            if expanded >= max_nodes or late:
                why = "time" if late else "budget"
                return done(SearchStatus.BUDGET, (), f"stopped after {expanded} expansions ({why})")
            expanded += 1
            preferred = domain.helpful(problem, state)
            for move in domain.legal_moves(problem, state):
                entry = (h, next(tie), state, move)
                heapq.heappush(queues[0], entry)
                if move in preferred:
                    heapq.heappush(queues[1], entry)
        state = None
        while state is None and (queues[0] or queues[1]):
            k = min((k for k in (0, 1) if queues[k]), key=lambda k: credit[k])
            credit[k] += 1
            _, _, before, move = heapq.heappop(queues[k])
            nxt = domain.apply_move(problem, before, move)
            if nxt in parent:
                continue
            if checks.ok(before, move):
                parent[nxt], state = (before, move), nxt
        if state is None:
            ruled = checks.ruled_out()
            return done(
                SearchStatus.UNSOLVABLE,
                (),
                f"no plan exists within these choices: {len(parent)} reachable states closed, "
                f"{ruled} moves ruled out",
            )
        h = guide(problem, state)


def improve(
    domain: CrispDomain,
    problem,
    moves: Sequence,
    max_nodes: int,
    seconds: float,
    deadline: float | None = None,
) -> tuple[tuple, dict]:
    """The anytime improvement (`PlannerConfig.improve_s`) of a plan of ``moves`` that reaches
    the goal: A* on the domain's lower bound from the initial state, cutting every state whose
    moves so far plus bound reach ``len(moves)`` (`lazy_best_first`'s ``below``), within
    ``max_nodes`` expansions and ``seconds`` (at most until ``deadline``, the planner's time
    limit). Returns the plan (the one found, a shortest one, or ``moves`` unchanged) and its
    stats: ``improved_from`` (the length before, None when unchanged), ``proved_optimal`` (the
    bound from the initial state equals the length, or the search completed), the search's
    status, expansions and seconds."""
    t0 = time.perf_counter()
    length = len(moves)
    start = domain.initial_state(problem)
    stats = {"improved_from": None, "moves": length, "proved_optimal": False, "expanded": 0}
    if domain.lower_bound(problem, start) >= length:
        stats.update(proved_optimal=True, status="bound", time_s=time.perf_counter() - t0)
        return tuple(moves), stats
    end = t0 + seconds if deadline is None else min(deadline, t0 + seconds)
    found = lazy_best_first(domain, problem, start, None, max_nodes, end, below=length)
    if found.status is SearchStatus.SOLVED and len(found.moves) < length:
        moves = found.moves
        stats.update(improved_from=length, moves=len(moves))
    stats.update(
        proved_optimal=found.status in (SearchStatus.SOLVED, SearchStatus.UNSOLVABLE),
        status=found.status.value,
        expanded=found.expanded,
        time_s=time.perf_counter() - t0,
    )
    return tuple(moves), stats
