"""The planner's complete fallback (`PlannerConfig.fallback`): when the receding windows revisit a
state or run out, a search over crisp states (`task.symbolic.lazy_search`) with the cost
source's feasibility checked lazily, from where the windows left off or over again from the
initial state; the plan it finds is committed to the cost source move by move.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, replace

import torch

from task.beliefs import BeliefSource
from task.config import PlannerConfig
from task.costs import IMPOSSIBLE, CostSource, CostSourceBase, WindowCosts, finite_costs
from task.domains.base import Domain, State
from task.errors import TampError
from task.problem import Move, Problem
from task.symbolic.lazy_search import (
    Feasible,
    LazyResult,
    SearchStatus,
    lazy_best_first,
    lazy_greedy,
)
from task.symbolic.shorten import merge_runs


def fallback_on(
    config: PlannerConfig, source: BeliefSource | None, costs: CostSource | None
) -> bool:
    """Whether the complete fallback search runs (`PlannerConfig.fallback`): by default only
    with a cost source; never while planning from perception (the search plans on the world
    state, which the planner does not see there)."""
    if source is not None:
        if config.fallback:
            raise TampError(
                "PlannerConfig.fallback=True plans on the world state: it cannot run with beliefs"
            )
        return False
    return costs is not None if config.fallback is None else config.fallback


def cost_checks(domain: Domain, problem: Problem, costs: CostSource, index: int):
    """``feasible(state, move)`` from a cost source: a move is ruled out where its price
    reaches `task.costs.IMPOSSIBLE` (as the decoder rules it out), one pricing per state, and
    the priced windows by state (their ``commit`` records the moves the fallback chose)."""
    windows: dict[State, WindowCosts] = {}
    ruled_out: dict[State, set[Move]] = {}

    def feasible(state: State, move: Move) -> bool:
        if state not in ruled_out:
            windows[state] = costs([index], [state], 1)
            with torch.no_grad():
                matrix = finite_costs(windows[state].compute()[0])  # (N, A - 1) of row 0
            rows = matrix.shape[0]
            ruled_out[state] = {
                domain.decode(problem, r, c, rows)
                for r, c in (matrix >= IMPOSSIBLE).nonzero().tolist()
            }
        return move not in ruled_out[state]

    return feasible, windows


def fall_back(
    domain: Domain,
    problem: Problem,
    state: State,
    config: PlannerConfig,
    costs: CostSourceBase | None = None,
    index: int = 0,
    deadline: float | None = None,
) -> LazyResult:
    """The complete fallback search for ``problem`` (``index``: its position in the list given
    to `task.planner.plan_batch`, what the cost source is told) from its world ``state``, over
    the moves the cost source does not rule out (`task.symbolic.lazy_search`). A plan found is
    committed to the cost source move by move (restart row 0 of a one-row window priced in the state
    the move starts from). ``config.fallback_search`` picks the search: A* on the lower bound,
    or greedy on the domain's ``estimate`` (else its lower bound).

    When A* spends its ``fallback_nodes`` with time left, a greedy search goes on from the
    same state with as many again (the states priced so far stay priced): longer plans, but
    one within the budget where A* at 15-20 slotted blocks found none. When that runs out too
    and ``state`` is not the initial state, a greedy search from the initial state may find a
    plan that drops the windows' moves (``from_start``; only without a cost source or with
    one that can ``forget`` the moves committed to it); the last search there is, it runs
    until the ``deadline`` when there is one, not for ``fallback_nodes``; with a deadline,
    each search before it stops at an equal share of the time left to those still to come
    (A* at a third where both others may follow), so that under load A* alone does not spend
    the deadline where a start over would have found a plan. Before all that,
    where such a start over is possible, A* may look from the initial state for
    ``config.restart_probe`` expansions, and its plan is taken when it finds one: windows
    that packed a region in a bad order left a state from which A* spent the whole deadline
    (36 s, packed variant 18) where from the initial state it finds the shortest plan in 30
    expansions (greedy there took 19,314). When no plan exists
    from ``state``, the initial state is searched too: UNSOLVABLE only when neither has a plan
    within these choices (the windows may have led into a dead end). A plan found has its runs
    of one block's moves merged (`task.symbolic.shorten.merge_runs`, each merged move checked
    feasible) before it is committed."""
    feasible, windows = (None, {}) if costs is None else cost_checks(domain, problem, costs, index)
    run = _Fallback(
        domain=domain,
        problem=problem,
        config=config,
        feasible=feasible,
        windows=windows,
        costs=costs,
        index=index,
        deadline=deadline,
    )
    search = lazy_greedy if config.fallback_search == "greedy" else lazy_best_first
    start = domain.initial_state(problem)
    can_forget = costs is None or costs.can_forget
    probing = config.restart_probe > 0 and search is lazy_best_first
    if probing and state != start and can_forget:
        probed = _probe(run, start)
        if probed is not None:
            return probed
    restart = state != start and can_forget  # a last search from the initial state may run
    stages = 1 + (search is lazy_best_first) + restart  # searches that may still run, this one too
    found = search(domain, problem, state, feasible, config.fallback_nodes, run.share(stages))
    if search is lazy_best_first and found.status is SearchStatus.BUDGET and not run.late():
        stages -= 1
        nodes = config.fallback_nodes
        greedy = lazy_greedy(domain, problem, state, feasible, nodes, run.share(stages))
        found = _after(found, greedy, f"A* {found.reason}; then greedy: {greedy.reason}")
    if found.status is SearchStatus.BUDGET and restart and not run.late():
        state, found = _start_over(run, state, found)
    if found.status is SearchStatus.UNSOLVABLE and state != start:
        found = _dead_end(run, search, found)
        if found.status is SearchStatus.DEAD_END:
            return found
    return _commit(domain, problem, state, found, feasible, windows, costs)


@dataclass(frozen=True)
class _Fallback:
    """One problem's fallback search (`fall_back`): what each of its searches shares."""

    domain: Domain
    problem: Problem
    config: PlannerConfig
    feasible: Feasible | None  # the cost source's verdicts (None: every move is feasible)
    windows: dict  # the cost source's one-row windows, by the state they price
    costs: CostSourceBase | None
    index: int
    deadline: float | None

    def late(self) -> bool:
        return self.deadline is not None and time.perf_counter() >= self.deadline

    def share(self, stages: int) -> float | None:
        """The deadline of a search with ``stages`` searches (itself included) still to run:
        an equal share of the time left, so that under load a slow first search does not
        leave the later ones, from elsewhere, no time at all."""
        if self.deadline is None or stages <= 1:
            return self.deadline
        now = time.perf_counter()
        return now + max(0.0, self.deadline - now) / stages

    def forget(self) -> None:
        """Tell the cost source (one that can) to drop the moves committed to it."""
        if self.costs is not None:
            self.costs.forget(self.index)


def _probe(run: _Fallback, start: State) -> LazyResult | None:
    """A* from the initial ``start`` for ``config.restart_probe`` expansions: its plan,
    committed, when it finds one (the windows' moves dropped), else None."""
    nodes = run.config.restart_probe
    probe = lazy_best_first(run.domain, run.problem, start, run.feasible, nodes, run.deadline)
    if probe.status is not SearchStatus.SOLVED:
        return None
    run.forget()
    why = f"from the initial state, A* within {nodes} expansions: {probe.reason}"
    found = replace(probe, from_start=True, reason=why)
    return _commit(run.domain, run.problem, start, found, run.feasible, run.windows, run.costs)


def _start_over(run: _Fallback, state: State, found: LazyResult) -> tuple[State, LazyResult]:
    """After the searches from ``state`` ran out (``found``), a last greedy search from the
    initial state (until the deadline when there is one): its start and result when it
    finds a plan, else ``state`` and ``found``."""
    start = run.domain.initial_state(run.problem)
    last = run.config.fallback_nodes if run.deadline is None else sys.maxsize  # the time left
    again = lazy_greedy(run.domain, run.problem, start, run.feasible, last, run.deadline)
    if again.status is not SearchStatus.SOLVED:
        return state, found
    run.forget()
    why = f"{found.reason}; from the initial state, greedy: {again.reason}"
    return start, _after(found, again, why, from_start=True)


def _dead_end(run: _Fallback, search, found: LazyResult) -> LazyResult:
    """No plan from the windows' state (``found``): the initial state searched too, with
    the expansions left; DEAD_END when a plan may exist from there, else still UNSOLVABLE."""
    start = run.domain.initial_state(run.problem)
    left = max(1, run.config.fallback_nodes - found.expanded)
    again = search(run.domain, run.problem, start, run.feasible, left, run.deadline)
    if again.status is not SearchStatus.UNSOLVABLE:
        why = (
            "the windows reached a state from which no plan exists within these choices, "
            f"and from the initial state the search ended {again.status.value}"
        )
        return replace(found, status=SearchStatus.DEAD_END, reason=why)
    return replace(found, reason=found.reason + ", from the initial state too")


def _commit(domain, problem, state, found: LazyResult, feasible, windows, costs) -> LazyResult:
    """``found`` (a search from ``state``) with its runs of one block's moves merged, each
    move committed to the cost source's window priced in the state it starts from."""
    tidy = merge_runs(domain, problem, state, found.moves, feasible)
    if len(tidy) < len(found.moves):  # a block parked twice in a row: once
        why = f"{found.reason}; {len(found.moves) - len(tidy)} moves of runs merged"
        found = replace(found, moves=tidy, reason=why)
    for move in found.moves if costs is not None else ():
        windows[state].commit([0], [(move,)])
        state = domain.apply_move(problem, state, move)
    return found


def _after(first: LazyResult, then: LazyResult, reason: str, **changes) -> LazyResult:
    """``then``, the search that went on after ``first`` ran out, with both searches'
    expansions, checks and seconds, and ``reason``."""
    return replace(
        then,
        expanded=first.expanded + then.expanded,
        checked=first.checked + then.checked,
        time_s=first.time_s + then.time_s,
        reason=reason,
        **changes,
    )
