"""Receding-window planning: optimise a window, decode, execute the legal moves, replan.

``plan_batch`` plans many problems in one tensor program per window and problem size (restarts
as extra rows; the code pads and masks, so any mix of sizes also works in one program);
problems that reach their goal leave the batch.
With ``PlannerConfig(batched=False)`` the same code runs one problem at a time, so the speed-up
of batching can be measured.

Each window decodes against a crisp state (the true one, or under the perceived protocol of
`task.beliefs` the one read from the current image), then applies its moves to the true state,
the world (with a cost source, only up to a move the source rules out in the state it starts
from: `PlannerConfig.own_state_costs`; a source that checks moves ahead, such as the arm's
executor check, also vets each move where it starts and rules out there the one it fails). A
move illegal there ends the plan as inexecutable
(`PlanStatus.INVALID`, the move kept last so that `task.symbolic.validate` names it); with
the crisp check on and the true protocol that never happens. Under the perceived protocol a
window that predicts the goal is confirmed by one more reading (a new image, no
optimisation), so a perfect reading gives exactly the true protocol's plans.

With ``PlannerConfig(improve_s=...)`` a plan found (without beliefs and move costs) is handed to
an anytime improvement (`task.symbolic.lazy_search.improve`): A* on the domain's lower bound,
cut at the plan's length, returns a shorter plan when one exists within its budget, a shortest
one.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import partial

import torch

from task.beliefs import BeliefSource, belief_source
from task.config import PlannerConfig, torch_device
from task.costs import CostSource, cost_source
from task.deadline import NO_DEADLINE, Deadline
from task.decode import DecodedWindow
from task.domains import get_domain
from task.domains.base import Domain, State, resolve_goal_loss
from task.errors import ProblemError, TampError, one_of
from task.planner.context import PlanContext, Progress
from task.planner.fallback import cost_checks, fall_back, fallback_on
from task.planner.windows import (
    crisp_states,
    execute,
    next_window,
    own_state_prefix,
    take_safe,
)
from task.problem import Move, Plan, PlanResult, PlanStatus, Problem
from task.rollout import OutOfTime
from task.symbolic.lazy_search import SearchStatus, improve
from task.symbolic.shorten import shorten


@dataclass(frozen=True)
class _Clock:
    """When a run started and must end: ``deadline`` (None: never), the earlier of
    ``config.time_limit_s`` and the caller's; ``windows_end``, where the windows stop (with
    the fallback on, at ``config.window_share`` of the time); ``limit``, the seconds the
    messages name."""

    start: float
    deadline: float | None
    windows_end: float | None
    limit: float | None

    @classmethod
    def of(cls, config: PlannerConfig, until: Deadline, fallback: bool) -> _Clock:
        start = time.perf_counter()
        limit = config.time_limit_s
        ends = [t for t in (None if limit is None else start + limit, until.at) if t is not None]
        deadline = min(ends) if ends else None
        if limit is None:
            limit = until.limit_s  # what the messages name
        windows_end = deadline
        if deadline is not None and fallback:
            windows_end = start + config.window_share * (deadline - start)
        return cls(start, deadline, windows_end, limit)


def _run(
    shared: PlanContext,
    problems: Sequence[Problem],
    indices: Sequence[int],
    on_done: Callable[[int], None],
    until: Deadline = NO_DEADLINE,
) -> list[PlanResult]:
    """Plan all ``problems`` together in the ``shared`` context (its domain, settings,
    generator and sources); ``on_done(k)`` reports k newly finished problems. ``until``: a
    caller's deadline (a command's), kept as well as ``config.time_limit_s``.

    ``indices``: the problems' positions in the caller's list (what the sources are told).
    ``config.time_limit_s`` holds inside a window too: a window the limit cuts short is
    abandoned (none of its moves are kept). With the fallback on, the windows stop at
    ``config.window_share`` of the limit, the fallback searching in the rest."""
    domain, config = shared.domain, shared.config
    fallback = fallback_on(config, shared.source, shared.costs)
    clock = _Clock.of(config, until, fallback)
    context = replace(
        shared,
        indices=indices,
        fallback=fallback,
        windows_end=clock.windows_end,
        deadline=clock.deadline,
    )
    progress = Progress.start(domain, problems)
    active = [i for i in range(len(problems)) if not progress.solved[i]]
    on_done(len(problems) - len(active))
    active, timed_out = _windows(context, problems, active, progress, on_done)
    if context.fallback:
        _fall_back_all(context, problems, progress, timed_out)
    if config.shorten and context.plain:
        _shorten_all(domain, problems, progress)
    if config.improve_s > 0 and context.plain:
        _improve_all(context, problems, progress)
    on_done(len(active))
    elapsed = time.perf_counter() - clock.start
    late = clock.deadline is not None and clock.start + elapsed >= clock.deadline
    stopped = timed_out or late  # the windows or the fallback ran out of time
    return [
        _result(domain, problems, i, progress, elapsed, stopped, clock.limit)
        for i in range(len(problems))
    ]


def _windows(
    context: PlanContext,
    problems: Sequence[Problem],
    active: list[int],
    progress: Progress,
    on_done: Callable[[int], None],
) -> tuple[list[int], bool]:
    """Plan and execute windows of the ``active`` problems until none is left or
    ``config.max_windows`` ran; returns the problems still active and whether the windows ran
    out of time (a window the limit cut short is abandoned)."""
    for _ in range(context.config.max_windows):
        if context.plain:
            active = take_safe(context, problems, active, progress)
        if not active:
            break
        try:
            decoded, priced, retried, crisp, perceived = next_window(
                context, problems, active, progress
            )
        except OutOfTime:
            return active, True  # stop with the moves so far; each unsolved problem says so
        executed, hoped = [], []  # hoped: perceived windows that predict the goal
        for i, seen, win in zip(active, crisp, decoded, strict=True):
            tried, hopes = _execute_window(context, problems[i], i, progress, seen, win, perceived)
            executed.append(tried)
            if hopes:
                hoped.append(i)
        if priced is not None:  # the placements each executed move was decided with
            rows = [None if k in retried else w.row for k, w in enumerate(decoded)]
            priced.commit(rows, executed)
        if hoped:
            _confirm(context, problems, hoped, progress)
        p = progress
        still = [i for i in active if p.illegal[i] is None and not p.solved[i] and not p.trigger[i]]
        on_done(len(active) - len(still))
        active = still
    return active, False


def _execute_window(
    context: PlanContext,
    problem: Problem,
    i: int,
    progress: Progress,
    seen: State,
    win: DecodedWindow,
    perceived: bool,
) -> tuple[tuple[Move, ...], bool]:
    """Execute problem ``i``'s decoded window ``win`` (decoded against ``seen``) in the world,
    with a cost source only up to the first move it rules out in its own state; returns the
    moves tried and whether the window predicts the goal that a new image must confirm
    (``perceived``)."""
    domain, costs = context.domain, context.costs
    progress.windows[i] += 1
    progress.misread[i] += seen != progress.states[i]
    planned = win.moves
    if costs is not None and context.source is None and context.config.own_state_costs:
        feasible, _ = cost_checks(domain, problem, costs, context.indices[i])
        verify = partial(costs.verify, context.indices[i])  # the cost source's check ahead
        planned = own_state_prefix(domain, problem, progress.states[i], planned, feasible, verify)
        progress.cut[i] += len(planned) < len(win.moves)
    tried, progress.states[i], progress.illegal[i], looped = execute(
        domain, problem, progress.states[i], planned, progress.visited[i]
    )
    if looped and context.fallback and progress.trigger[i] is None:
        progress.trigger[i] = "cycle"  # the windows revisit a state: the fallback takes over
    progress.moves[i].extend(tried)
    if not perceived:  # decoded on the world: the world reached the goal
        progress.solved[i] = win.reached and len(planned) == len(win.moves)
    elif domain.is_goal(problem, seen):
        progress.solved[i] = True  # the image already showed the goal (no move was decoded)
    elif win.reached and progress.illegal[i] is None:
        return tried, True
    return tried, False


def _confirm(
    context: PlanContext, problems: Sequence[Problem], hoped: list[int], progress: Progress
) -> None:
    """Look again at the ``hoped`` problems: each is done when a new image shows its goal."""
    now = [progress.states[i] for i in hoped]
    looked = context.source([context.indices[i] for i in hoped], now)
    seen_now, _ = crisp_states(looked, now)
    for i, seen in zip(hoped, seen_now, strict=True):
        progress.solved[i] = context.domain.is_goal(problems[i], seen)


def _fall_back_all(
    context: PlanContext, problems: Sequence[Problem], progress: Progress, timed_out: bool
) -> None:
    """The complete fallback search for every problem the windows left unsolved (and
    executable), from the world state they reached."""
    for i, p in enumerate(problems):
        if not progress.solved[i] and progress.illegal[i] is None:
            why = progress.trigger[i] or ("time_limit" if timed_out else "windows")
            progress.trigger[i] = why
            found = fall_back(
                context.domain,
                p,
                progress.states[i],
                context.config,
                costs=context.costs,
                index=context.indices[i],
                deadline=context.deadline,
            )
            progress.searched[i] = found
            if found.from_start:  # the windows' moves led nowhere: the plan starts over
                progress.moves[i] = []
            progress.moves[i].extend(found.moves)
            progress.solved[i] = found.status is SearchStatus.SOLVED


def _shorten_all(domain: Domain, problems: Sequence[Problem], progress: Progress) -> None:
    """Cut cycles and redundant moves out of every plan that reaches its goal."""
    for i, p in enumerate(problems):
        if progress.solved[i] and progress.illegal[i] is None:
            progress.moves[i] = list(shorten(domain, p, progress.moves[i]))


def _improve_all(context: PlanContext, problems: Sequence[Problem], progress: Progress) -> None:
    """The anytime improvement of every plan found (`PlannerConfig.improve_s`), for the
    problems of at most ``config.improve_up_to`` entities."""
    config = context.config
    small = config.improve_up_to
    for i, p in enumerate(problems):
        if progress.solved[i] and progress.illegal[i] is None and (small is None or p.n <= small):
            better, progress.improved[i] = improve(
                context.domain,
                p,
                progress.moves[i],
                config.improve_nodes,
                config.improve_s,
                context.deadline,
            )
            progress.moves[i] = list(better)


def _result(
    domain: Domain,
    problems: Sequence[Problem],
    i: int,
    progress: Progress,
    elapsed: float,
    stopped: bool,
    limit: float | None,
) -> PlanResult:
    """Problem ``i``'s result, its stats from ``progress``; ``elapsed``: the run's seconds;
    ``stopped``: whether the run stopped at its time limit (``limit`` seconds)."""
    p, searched = problems[i], progress.searched
    moves, windows, illegal = progress.moves[i], progress.windows[i], progress.illegal[i]
    stats = {
        "windows": windows,
        "time_s": elapsed / len(problems),
        "batch_time_s": elapsed,
        "misread_windows": progress.misread[i],  # windows decoded against a state not the world's
    }
    status = PlanStatus.SOLVED if progress.solved[i] else PlanStatus.NO_PLAN
    exhausted = i in searched and searched[i].status is SearchStatus.UNSOLVABLE
    if stopped and not progress.solved[i] and illegal is None and not exhausted:
        left = domain.lower_bound(p, progress.states[i])
        stats["time_limit"] = (
            f"stopped at the {limit:g} s time limit after {windows} "
            f"windows and {len(moves)} moves; at least {left:g} more moves needed"
        )
    if illegal is not None:
        status, stats["illegal"] = PlanStatus.INVALID, illegal
    if progress.safe[i]:
        stats["safe_moves"] = progress.safe[i]
    if progress.cut[i]:
        stats["own_state_cuts"] = progress.cut[i]
    if i in progress.improved:
        stats["improve"] = progress.improved[i]
    if i in searched:
        stats["fallback"] = {"trigger": progress.trigger[i], **searched[i].stats()}
        if searched[i].status is SearchStatus.UNSOLVABLE:
            status = PlanStatus.UNSOLVABLE
    return PlanResult(status, Plan(tuple(moves)), p, None, stats)


def plan_batch(
    problems: Sequence[Problem],
    config: PlannerConfig = PlannerConfig(),
    seed: int = 0,
    progress: Callable[[int], None] | None = None,
    beliefs: BeliefSource | None = None,
    costs: CostSource | None = None,
    on_result: Callable[[int, PlanResult], None] | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> list[PlanResult]:
    """Plan every problem (all of one domain). ``progress(k)``: k more problems finished;
    ``on_result(i, result)`` as problem i's result is final (after its shape group's program,
    or after it alone when not batched): what an interrupted caller keeps. ``deadline``: a
    command's (`task.deadline`), at which planning stops as at ``config.time_limit_s``.

    Returns one PlanResult per problem, in order; ``stats["time_s"]`` is the wall time per
    problem (the batch's time divided among its problems when batched). ``beliefs`` gives
    every window soft initial and goal supports (planning from perception, `task.beliefs`);
    ``costs`` every window move costs (the arm in the objective, `task.costs`).
    The windows run on ``config.device`` (TampError when this machine lacks it).
    """
    if not problems:
        return []
    names = {p.domain for p in problems}
    if len(names) > 1:
        raise TampError(f"plan_batch needs problems of one domain, got {sorted(names)}")
    domain = get_domain(problems[0].domain)
    if resolve_goal_loss(domain, config.goal_loss) not in domain.goal_losses:
        raise ProblemError(
            f"unknown goal loss for {domain.name} {one_of(config.goal_loss, domain.goal_losses)}"
        )
    torch_device(config.device)  # refused in one line where this machine lacks it
    generator = torch.Generator().manual_seed(seed)  # CPU: the same draws on every device
    # cost sources and window beliefs that do not inherit `CostSourceBase` and
    # `WindowBeliefsBase` are wrapped here, once
    source = belief_source(beliefs)
    shared = PlanContext(domain, config, generator, source=source, costs=cost_source(costs))
    report = progress or (lambda k: None)
    final = on_result or (lambda i, result: None)
    if not config.batched:
        alone = []
        for i, p in enumerate(problems):
            ran = _run(shared, [p], [i], report, deadline)
            alone.append(ran[0])
            final(i, alone[-1])
        return alone
    # one tensor program per shape key (the domain's: sizes that pad alike), per-key times
    results: list[PlanResult | None] = [None] * len(problems)
    keys = [domain.shape_key(p) for p in problems]
    for key in sorted(set(keys)):
        group = [i for i, k in enumerate(keys) if k == key]
        subset = [problems[i] for i in group]
        planned = _run(shared, subset, group, report, deadline)
        for i, result in zip(group, planned, strict=True):
            results[i] = result
            final(i, result)
    return results


def plan(
    problem: Problem,
    config: PlannerConfig = PlannerConfig(),
    seed: int = 0,
    beliefs: BeliefSource | None = None,
    costs: CostSource | None = None,
    deadline: Deadline = NO_DEADLINE,
) -> PlanResult:
    """Plan one problem (``beliefs``: soft inputs from perception; ``costs``: move costs;
    ``deadline``: a command's; see `plan_batch`)."""
    return plan_batch([problem], config, seed, beliefs=beliefs, costs=costs, deadline=deadline)[0]
