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
from functools import partial

import torch

from task.beliefs import BeliefSource
from task.config import PlannerConfig, torch_device
from task.costs import CostSource
from task.deadline import NO_DEADLINE, Deadline
from task.domains import get_domain
from task.domains.base import Domain, resolve_goal_loss
from task.errors import ProblemError, TampError, one_of
from task.planner.fallback import cost_checks, fall_back, fallback_on
from task.planner.windows import (
    crisp_states,
    execute,
    next_window,
    own_state_prefix,
    take_safe,
)
from task.problem import Plan, PlanResult, PlanStatus, Problem
from task.rollout import OutOfTime
from task.symbolic.lazy_search import (
    LazyResult,
    SearchStatus,
    improve,
)
from task.symbolic.shorten import shorten


def _run(
    domain: Domain,
    problems: Sequence[Problem],
    config: PlannerConfig,
    generator: torch.Generator,
    on_done: Callable[[int], None],
    source: BeliefSource | None = None,
    indices: Sequence[int] = (),
    costs: CostSource | None = None,
    until: Deadline = NO_DEADLINE,
) -> list[PlanResult]:
    """Plan all ``problems`` together; ``on_done(k)`` reports k newly finished problems.
    ``until``: a caller's deadline (a command's), kept as well as ``config.time_limit_s``.

    ``indices``: the problems' positions in the caller's list (what ``source`` and ``costs``
    are told). ``config.time_limit_s`` holds inside a window too: a window the limit cuts
    short is abandoned (none of its moves are kept). With the fallback on, the windows stop at
    ``config.window_share`` of the limit, the fallback searching in the rest."""
    start = time.perf_counter()
    limit = config.time_limit_s
    ends = [t for t in (None if limit is None else start + limit, until.at) if t is not None]
    deadline = min(ends) if ends else None
    if limit is None:
        limit = until.limit_s  # what the messages name
    fallback = fallback_on(config, source, costs)
    windows_end = deadline
    if deadline is not None and fallback:
        windows_end = start + config.window_share * (deadline - start)
    states = [domain.initial_state(p) for p in problems]  # the world
    visited = [{s} for s in states]  # per problem, every world state its plan passed through
    moves: list[list] = [[] for _ in problems]
    windows, misread = [0] * len(problems), [0] * len(problems)
    solved = [domain.is_goal(p, s) for p, s in zip(problems, states, strict=True)]
    illegal: list[str | None] = [None] * len(problems)
    active = [i for i in range(len(problems)) if not solved[i]]
    on_done(len(problems) - len(active))
    timed_out = False
    trigger: list[str | None] = [None] * len(problems)  # why the fallback takes over
    safe = [0] * len(problems)  # moves taken without a window (`PlannerConfig.safe_from`)
    own_state = costs is not None and source is None and config.own_state_costs
    check_ahead = getattr(costs, "verify", None)  # the cost source's optional check ahead
    cut = [0] * len(problems)  # windows cut before a move priced out in its own state
    for _ in range(config.max_windows):
        if source is None and costs is None:
            active = take_safe(
                domain, problems, active, states, moves, visited, solved, safe, config
            )
        if not active:
            break
        try:
            decoded, priced, retried, crisp, perceived = next_window(
                domain,
                problems,
                active,
                states,
                indices,
                visited,
                config,
                generator,
                source,
                costs,
                windows_end,
            )
        except OutOfTime:
            timed_out = True  # stop with the moves so far; each unsolved problem says so
            break
        hoped = []  # perceived: windows that predict the goal, for a new image to confirm
        executed = []
        for i, seen, win in zip(active, crisp, decoded, strict=True):
            windows[i] += 1
            misread[i] += seen != states[i]
            planned = win.moves
            if own_state:  # each move after the first priced where it starts
                feasible, _ = cost_checks(domain, problems[i], costs, indices[i])
                verify = None if check_ahead is None else partial(check_ahead, indices[i])
                planned = own_state_prefix(
                    domain, problems[i], states[i], planned, feasible, verify
                )
                cut[i] += len(planned) < len(win.moves)
            tried, states[i], illegal[i], looped = execute(
                domain, problems[i], states[i], planned, visited[i]
            )
            if looped and fallback and trigger[i] is None:
                trigger[i] = "cycle"  # the windows revisit a state: the fallback takes over
            moves[i].extend(tried)
            executed.append(tried)
            if not perceived:  # decoded on the world: the world reached the goal
                solved[i] = win.reached and len(planned) == len(win.moves)
            elif domain.is_goal(problems[i], seen):
                solved[i] = True  # the image already showed the goal (no move was decoded)
            elif win.reached and illegal[i] is None:
                hoped.append(i)
        if priced is not None:  # the placements each executed move was decided with
            rows = [None if k in retried else w.row for k, w in enumerate(decoded)]
            priced.commit(rows, executed)
        if hoped:  # look again: done when the new image shows the goal
            looked = source([indices[i] for i in hoped], [states[i] for i in hoped])
            seen_now, _ = crisp_states(looked, [states[i] for i in hoped])
            for i, seen in zip(hoped, seen_now, strict=True):
                solved[i] = domain.is_goal(problems[i], seen)
        still = [i for i in active if illegal[i] is None and not solved[i] and not trigger[i]]
        on_done(len(active) - len(still))
        active = still
    searched: dict[int, LazyResult] = {}
    for i, p in enumerate(problems):
        if fallback and not solved[i] and illegal[i] is None:
            trigger[i] = trigger[i] or ("time_limit" if timed_out else "windows")
            searched[i] = fall_back(domain, p, states[i], costs, indices, i, config, deadline)
            if searched[i].from_start:  # the windows' moves led nowhere: the plan starts over
                moves[i] = []
            moves[i].extend(searched[i].moves)
            solved[i] = searched[i].status is SearchStatus.SOLVED
    if config.shorten and source is None and costs is None:
        for i, p in enumerate(problems):
            if solved[i] and illegal[i] is None:
                moves[i] = list(shorten(domain, p, moves[i]))
    improved: dict[int, dict] = {}
    if config.improve_s > 0 and source is None and costs is None:
        small = config.improve_up_to
        for i, p in enumerate(problems):
            if solved[i] and illegal[i] is None and (small is None or p.n <= small):
                better, improved[i] = improve(
                    domain, p, moves[i], config.improve_nodes, config.improve_s, deadline
                )
                moves[i] = list(better)
    on_done(len(active))
    elapsed = time.perf_counter() - start
    late = deadline is not None and start + elapsed >= deadline  # the fallback ran out of time
    results = []
    for i, p in enumerate(problems):
        stats = {
            "windows": windows[i],
            "time_s": elapsed / len(problems),
            "batch_time_s": elapsed,
            "misread_windows": misread[i],  # windows decoded against a state not the world's
        }
        status = PlanStatus.SOLVED if solved[i] else PlanStatus.NO_PLAN
        exhausted = i in searched and searched[i].status is SearchStatus.UNSOLVABLE
        if (timed_out or late) and not solved[i] and illegal[i] is None and not exhausted:
            left = domain.lower_bound(p, states[i])
            stats["time_limit"] = (
                f"stopped at the {limit:g} s time limit after {windows[i]} "
                f"windows and {len(moves[i])} moves; at least {left:g} more moves needed"
            )
        if illegal[i] is not None:
            status, stats["illegal"] = PlanStatus.INVALID, illegal[i]
        if safe[i]:
            stats["safe_moves"] = safe[i]
        if cut[i]:
            stats["own_state_cuts"] = cut[i]
        if i in improved:
            stats["improve"] = improved[i]
        if i in searched:
            stats["fallback"] = {"trigger": trigger[i], **searched[i].stats()}
            if searched[i].status is SearchStatus.UNSOLVABLE:
                status = PlanStatus.UNSOLVABLE
        results.append(PlanResult(status, Plan(tuple(moves[i])), p, None, stats))
    return results


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
    report = progress or (lambda k: None)
    final = on_result or (lambda i, result: None)
    if not config.batched:
        alone = []
        for i, p in enumerate(problems):
            ran = _run(domain, [p], config, generator, report, beliefs, [i], costs, deadline)
            alone.append(ran[0])
            final(i, alone[-1])
        return alone
    # one tensor program per shape key (the domain's: sizes that pad alike), per-key times
    results: list[PlanResult | None] = [None] * len(problems)
    keys = [domain.shape_key(p) for p in problems]
    for key in sorted(set(keys)):
        group = [i for i, k in enumerate(keys) if k == key]
        subset = [problems[i] for i in group]
        planned = _run(domain, subset, config, generator, report, beliefs, group, costs, deadline)
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
