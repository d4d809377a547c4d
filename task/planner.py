"""Receding-window planning: optimise a window, decode, execute the legal moves, replan.

``plan_batch`` plans many problems in one tensor program per window and problem size (restarts
as extra rows; the code pads and masks, so any mix of sizes also works in one program);
problems that reach their goal leave the batch.
With ``PlannerConfig(batched=False)`` the same code runs one problem at a time, so the speed-up
of batching can be measured.

Each window decodes against a crisp state (the true one, or under the perceived protocol of
`task.beliefs` the one read from the current image), then applies its moves to the true state,
the world. A move illegal there ends the plan as inexecutable (`PlanStatus.INVALID`, the move
kept last so that `task.symbolic.validate` names it); with the crisp check on and the true
protocol that never happens. Under the perceived protocol a window that predicts the goal is
confirmed by one more reading (a new image, no optimisation), so a perfect reading gives
exactly the true protocol's plans.

With ``PlannerConfig(improve_s=...)`` a plan found (without beliefs and move costs) is handed to
an anytime improvement (`task.symbolic.lazy_search.improve`): A* on the domain's lower bound,
cut at the plan's length, returns a shorter plan when one exists within its budget, a shortest
one.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import replace

import torch

from task.beliefs import BeliefSource, WindowBeliefs
from task.config import PlannerConfig, torch_device
from task.costs import IMPOSSIBLE, CostSource, WindowCosts
from task.decode import DecodedWindow, decode_best, proof_stop
from task.domains import get_domain
from task.domains.base import Domain, SoftBatch, State, resolve_goal_loss, window_part
from task.errors import ProblemError, TampError, one_of
from task.optimize import optimise_window
from task.problem import Move, Plan, PlanResult, PlanStatus, Problem
from task.rollout import OutOfTime, check_deadline
from task.symbolic.lazy_search import (
    LazyResult,
    SearchStatus,
    improve,
    lazy_best_first,
    lazy_greedy,
)
from task.symbolic.shorten import merge_runs, shorten

PROOF_PROBLEMS = 1  # windows of at most this many problems are read early (`_proofs`): a read
# costs about a third of an Adam step, and a window stops only once all its problems are proven,
# which in a batch of many rarely happens (PlanBench's 150 4-block problems in one batch: 8%
# more CPU with reads, none stopped early)


def _window(
    domain: Domain,
    problems: Sequence[Problem],
    states: Sequence[State],
    config: PlannerConfig,
    generator: torch.Generator,
    beliefs: WindowBeliefs | None = None,
    visited: Sequence[set] | None = None,
    costs: WindowCosts | None = None,
    deadline: float | None = None,
    parks: Sequence[bool] | None = None,
):
    """The decoded window of each problem (`decode_best`); a window of one problem
    (`PROOF_PROBLEMS`), without beliefs and move costs, may stop early
    (`task.decode.proof_stop`).
    ``parks``: per problem, whether parking moves rank free (default `PlannerConfig.parks`
    of the problems given; a part of a problem (`_part_windows`) keeps its whole problem's)."""
    parks = [config.parks(p) for p in problems] if parks is None else list(parks)
    device = torch.device(config.device)  # checked by `plan_batch` (`torch_device`)
    batch = on_device(domain.encode(problems, states, torch.float32), device)
    batch = batch.repeat(config.restarts)
    horizons = torch.tensor(config.horizons(), device=device).repeat(len(problems))  # (B,)
    steps = torch.arange(int(horizons.max()), device=device) < horizons[:, None]  # (B, T)
    proven: dict[int, DecodedWindow] = {}
    stop = None
    priced_ok = costs is None or config.proof_costs
    if len(problems) <= PROOF_PROBLEMS and beliefs is None and priced_ok and visited:
        stop = proof_stop(domain, problems, states, config, visited, proven, parks)
    _, roll = optimise_window(
        domain, batch, steps, config, generator, beliefs, costs, deadline, stop
    )
    if len(proven) == len(problems):
        return [proven[i] for i in range(len(problems))]
    decoded = decode_best(
        domain,
        problems,
        states,
        roll.gates,
        roll.loss,
        config.restarts,
        config.threshold,
        config.crisp_check,
        visited,
        roll.costs,
        config.rank_prefixes,
        parks,
    )
    return [proven.get(i, window) for i, window in enumerate(decoded)]


def on_device(batch: SoftBatch, device: torch.device) -> SoftBatch:
    """``batch`` with every tensor, its ``static`` ones too, on ``device`` (domains encode on
    the CPU; the window's optimisation and rollout then run where the batch is)."""
    static = {k: v.to(device) for k, v in batch.static.items()}
    return SoftBatch(*(t.to(device) for t in batch.astuple()), static=static)


def _retry_frozen(
    domain, problems, active, crisp, config, generator, beliefs, visited, decoded, deadline
) -> set[int]:
    """Windows that decoded no move under adapted beliefs are planned again with the beliefs'
    frozen ``fallback`` (`task.beliefs`, without move costs); a retry that moves replaces the
    window in place. Returns the positions of the replaced windows."""
    fallback = getattr(beliefs, "fallback", None)
    stuck = [k for k, w in enumerate(decoded) if not w.moves and not w.reached]
    if fallback is None or not stuck:
        return set()
    again = _window(
        domain,
        [problems[active[k]] for k in stuck],
        [crisp[k] for k in stuck],
        config,
        generator,
        fallback(stuck),
        [visited[active[k]] for k in stuck],
        deadline=deadline,
    )
    replaced = set()
    for k, window in zip(stuck, again, strict=True):
        if window.moves or window.reached:
            decoded[k] = window
            replaced.add(k)
    return replaced


def _crisp_states(
    beliefs: WindowBeliefs | None, world: Sequence[State]
) -> tuple[Sequence[State], bool]:
    """The states a window decodes against and whether they are perceived (not the world)."""
    crisp = getattr(beliefs, "crisp_states", None)
    if crisp is None:
        return world, False
    if len(crisp) != len(world):
        raise TampError(f"beliefs give {len(crisp)} crisp states for {len(world)} problems")
    return tuple(crisp), True


def _execute(
    domain: Domain, problem: Problem, state: State, moves: Sequence[Move], visited: set
) -> tuple[tuple[Move, ...], State, str | None, bool]:
    """Apply ``moves`` to the world ``state`` until one is illegal there; each state reached
    joins ``visited``.

    Returns the moves tried (an illegal one last), the world state after the legal ones, why
    the illegal one is illegal (None when all were legal) and whether a state reached had been
    visited before (the windows cycle)."""
    done, looped = [], False
    for move in moves:
        done.append(move)
        reason = domain.check_move(problem, state, move)
        if reason is not None:
            return tuple(done), state, f"{move}: {reason}", looped
        state = domain.apply_move(problem, state, move)
        looped = looped or state in visited
        visited.add(state)
    return tuple(done), state, None, looped


def _fallback_on(
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


def _cost_checks(domain: Domain, problem: Problem, costs: CostSource, index: int):
    """``feasible(state, move)`` from a cost source: a move is ruled out where its price
    reaches `task.costs.IMPOSSIBLE` (as the decoder rules it out), one pricing per state, and
    the priced windows by state (their ``commit`` records the moves the fallback chose)."""
    windows: dict[State, WindowCosts] = {}
    ruled_out: dict[State, set[Move]] = {}

    def feasible(state: State, move: Move) -> bool:
        if state not in ruled_out:
            windows[state] = costs([index], [state], 1)
            with torch.no_grad():
                matrix = windows[state].compute()[0]  # (N, A - 1) action columns of row 0
            rows = matrix.shape[0]
            ruled_out[state] = {
                domain.decode(problem, r, c, rows)
                for r, c in (~(matrix < IMPOSSIBLE)).nonzero().tolist()  # NaN too
            }
        return move not in ruled_out[state]

    return feasible, windows


def _fall_back(
    domain: Domain,
    problem: Problem,
    state: State,
    costs: CostSource | None,
    indices: Sequence[int],
    i: int,
    config: PlannerConfig,
    deadline: float | None,
) -> LazyResult:
    """The complete fallback search for problem ``i`` from its world ``state``, over the moves
    the cost source does not rule out (`task.symbolic.lazy_search`). A plan found is committed
    to the cost source move by move (restart row 0 of a one-row window priced in the state
    the move starts from). ``config.fallback_search`` picks the search: A* on the lower bound,
    or greedy on the domain's ``estimate`` (else its lower bound).

    When A* spends its ``fallback_nodes`` with time left, a greedy search goes on from the
    same state with as many again (the states priced so far stay priced): longer plans, but
    one within the budget where A* at 15-20 slotted blocks found none. When that runs out too
    and ``state`` is not the initial state, a greedy search from the initial state may find a
    plan that drops the windows' moves (``from_start``; only without a cost source or with
    one that can ``forget`` the moves committed to it); the last search there is, it runs
    until the ``deadline`` when there is one, not for ``fallback_nodes``. Before all that,
    where such a start over is possible, A* may look from the initial state for
    ``config.restart_probe`` expansions, and its plan is taken when it finds one: windows
    that packed a region in a bad order left a state from which A* spent the whole deadline
    (36 s, packed variant 18) where from the initial state it finds the shortest plan in 30
    expansions (greedy there took 19,314). When no plan exists
    from ``state``, the initial state is searched too: UNSOLVABLE only when neither has a plan
    within these choices (the windows may have led into a dead end). A plan found has its runs
    of one block's moves merged (`task.symbolic.shorten.merge_runs`, each merged move checked
    feasible) before it is committed."""
    feasible, windows = (
        (None, {}) if costs is None else _cost_checks(domain, problem, costs, indices[i])
    )
    search = lazy_greedy if config.fallback_search == "greedy" else lazy_best_first

    def late() -> bool:
        return deadline is not None and time.perf_counter() >= deadline

    start = domain.initial_state(problem)
    forget = getattr(costs, "forget", None)  # a cost source that can drop committed moves
    can_forget = costs is None or forget is not None
    probing = config.restart_probe > 0 and search is lazy_best_first
    if probing and state != start and can_forget:
        nodes = config.restart_probe
        probe = lazy_best_first(domain, problem, start, feasible, nodes, deadline)
        if probe.status is SearchStatus.SOLVED:
            if forget is not None:
                forget(indices[i])
            why = f"from the initial state, A* within {nodes} expansions: {probe.reason}"
            return _commit(
                domain,
                problem,
                start,
                replace(probe, from_start=True, reason=why),
                feasible,
                windows,
                costs,
            )
    found = search(domain, problem, state, feasible, config.fallback_nodes, deadline)
    if search is lazy_best_first and found.status is SearchStatus.BUDGET and not late():
        greedy = lazy_greedy(domain, problem, state, feasible, config.fallback_nodes, deadline)
        found = _after(found, greedy, f"A* {found.reason}; then greedy: {greedy.reason}")
    if found.status is SearchStatus.BUDGET and state != start and can_forget and not late():
        last = config.fallback_nodes if deadline is None else sys.maxsize  # the time left
        again = lazy_greedy(domain, problem, start, feasible, last, deadline)
        if again.status is SearchStatus.SOLVED:
            if forget is not None:
                forget(indices[i])
            why = f"{found.reason}; from the initial state, greedy: {again.reason}"
            state, found = start, _after(found, again, why, from_start=True)
    if found.status is SearchStatus.UNSOLVABLE and state != start:
        left = max(1, config.fallback_nodes - found.expanded)
        again = search(domain, problem, start, feasible, left, deadline)
        if again.status is not SearchStatus.UNSOLVABLE:
            why = (
                "the windows reached a state from which no plan exists within these choices, "
                f"and from the initial state the search ended {again.status.value}"
            )
            return replace(found, status=SearchStatus.DEAD_END, reason=why)
        found = replace(found, reason=found.reason + ", from the initial state too")
    return _commit(domain, problem, state, found, feasible, windows, costs)


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


def _take_safe(
    domain: Domain,
    problems: Sequence[Problem],
    active: Sequence[int],
    states: list[State],
    moves: list[list],
    visited: Sequence[set],
    solved: list[bool],
    safe: list[int],
    config: PlannerConfig,
) -> list[int]:
    """The ``active`` problems that `PlannerConfig.takes_safe` take their domain's safe moves
    (`Domain.safe_moves`) in the world, as executed moves; returns those still active (not
    at the goal). Only without beliefs and a cost source (the caller's check)."""
    take = getattr(domain, "safe_moves", None)
    if take is None:
        return list(active)
    still = []
    for i in active:
        if config.takes_safe(problems[i]):
            for move in take(problems[i], states[i]):
                states[i] = domain.apply_move(problems[i], states[i], move)
                visited[i].add(states[i])
                moves[i].append(move)
                safe[i] += 1
            solved[i] = domain.is_goal(problems[i], states[i])
        if not solved[i]:
            still.append(i)
    return still


def _part_windows(
    domain: Domain,
    problems: list[Problem],
    states: list[State],
    visited: list[set],
    config: PlannerConfig,
    generator: torch.Generator,
    deadline: float | None,
    parks: Sequence[bool],
) -> list[DecodedWindow]:
    """The decoded windows of ``problems`` without beliefs and move costs: those that
    `PlannerConfig.takes_safe` plan the part still to be planned, cut to what their windows'
    moves reach (`task.domains.base.window_part`), with the part's settings
    (`PlannerConfig.for_parts`); the others plan as they are. One `_window` per settings."""
    part_config = config.for_parts()
    groups: dict[PlannerConfig, list[int]] = {}
    views = list(problems), list(states), list(visited)
    for k, problem in enumerate(problems):
        here = part_config if config.takes_safe(problem) else config
        if config.takes_safe(problem):
            depth = max(here.horizons())
            views[0][k], views[1][k], views[2][k] = window_part(
                domain, problem, states[k], visited[k], depth
            )
        groups.setdefault(here, []).append(k)
    decoded: list[DecodedWindow | None] = [None] * len(problems)
    for here, ks in groups.items():
        pick = [[view[k] for k in ks] for view in views]
        parked = [parks[k] for k in ks]
        windows = _window(domain, *pick[:2], here, generator, None, pick[2], None, deadline, parked)
        for k, window in zip(ks, windows, strict=True):
            decoded[k] = window
    return decoded


def _next_window(
    domain: Domain,
    problems: Sequence[Problem],
    active: Sequence[int],
    states: Sequence[State],
    indices: Sequence[int],
    visited: Sequence[set],
    config: PlannerConfig,
    generator: torch.Generator,
    source: BeliefSource | None,
    costs: CostSource | None,
    deadline: float | None,
):
    """One window of the ``active`` problems from their world ``states``: the decoded windows,
    the window's costs (None without a source), the positions of the windows a frozen-belief
    retry replaced, the crisp states decoded against and whether they are perceived. Raises
    `task.rollout.OutOfTime` when ``deadline`` passes before the window is decoded."""
    check_deadline(deadline)
    now = [states[i] for i in active]
    beliefs = None if source is None else source([indices[i] for i in active], now)
    crisp, perceived = _crisp_states(beliefs, now)
    priced = None
    if costs is not None:
        priced = costs([indices[i] for i in active], crisp, config.restarts)
    check_deadline(deadline)
    views = [problems[i] for i in active], list(crisp), [visited[i] for i in active]
    parks = [config.parks(p) for p in views[0]]
    if source is None and costs is None:
        decoded = _part_windows(domain, *views, config, generator, deadline, parks)
    else:
        decoded = _window(
            domain, *views[:2], config, generator, beliefs, views[2], priced, deadline, parks
        )
    retried = _retry_frozen(
        domain, problems, active, crisp, config, generator, beliefs, visited, decoded, deadline
    )
    return decoded, priced, retried, crisp, perceived


def _run(
    domain: Domain,
    problems: Sequence[Problem],
    config: PlannerConfig,
    generator: torch.Generator,
    on_done: Callable[[int], None],
    source: BeliefSource | None = None,
    indices: Sequence[int] = (),
    costs: CostSource | None = None,
) -> list[PlanResult]:
    """Plan all ``problems`` together; ``on_done(k)`` reports k newly finished problems.

    ``indices``: the problems' positions in the caller's list (what ``source`` and ``costs``
    are told). ``config.time_limit_s`` holds inside a window too: a window the limit cuts
    short is abandoned (none of its moves are kept). With the fallback on, the windows stop at
    ``config.window_share`` of the limit, the fallback searching in the rest."""
    start = time.perf_counter()
    limit = config.time_limit_s
    deadline = None if limit is None else start + limit
    fallback = _fallback_on(config, source, costs)
    windows_end = deadline
    if limit is not None and fallback:
        windows_end = start + config.window_share * limit
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
    for _ in range(config.max_windows):
        if source is None and costs is None:
            active = _take_safe(
                domain, problems, active, states, moves, visited, solved, safe, config
            )
        if not active:
            break
        try:
            decoded, priced, retried, crisp, perceived = _next_window(
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
            tried, states[i], illegal[i], looped = _execute(
                domain, problems[i], states[i], win.moves, visited[i]
            )
            if looped and fallback and trigger[i] is None:
                trigger[i] = "cycle"  # the windows revisit a state: the fallback takes over
            moves[i].extend(tried)
            executed.append(tried)
            if not perceived:
                solved[i] = win.reached  # decoded on the world: the world reached the goal
            elif domain.is_goal(problems[i], seen):
                solved[i] = True  # the image already showed the goal (no move was decoded)
            elif win.reached and illegal[i] is None:
                hoped.append(i)
        if priced is not None:  # the placements each executed move was decided with
            rows = [None if k in retried else w.row for k, w in enumerate(decoded)]
            priced.commit(rows, executed)
        if hoped:  # look again: done when the new image shows the goal
            looked = source([indices[i] for i in hoped], [states[i] for i in hoped])
            seen_now, _ = _crisp_states(looked, [states[i] for i in hoped])
            for i, seen in zip(hoped, seen_now, strict=True):
                solved[i] = domain.is_goal(problems[i], seen)
        still = [i for i in active if illegal[i] is None and not solved[i] and not trigger[i]]
        on_done(len(active) - len(still))
        active = still
    searched: dict[int, LazyResult] = {}
    for i, p in enumerate(problems):
        if fallback and not solved[i] and illegal[i] is None:
            trigger[i] = trigger[i] or ("time_limit" if timed_out else "windows")
            searched[i] = _fall_back(domain, p, states[i], costs, indices, i, config, deadline)
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
    results = []
    for i, p in enumerate(problems):
        stats = {
            "windows": windows[i],
            "time_s": elapsed / len(problems),
            "batch_time_s": elapsed,
            "misread_windows": misread[i],  # windows decoded against a state not the world's
        }
        status = PlanStatus.SOLVED if solved[i] else PlanStatus.NO_PLAN
        if timed_out and not solved[i] and illegal[i] is None:
            left = domain.lower_bound(p, states[i])
            stats["time_limit"] = (
                f"stopped at the {limit:g} s time limit after {windows[i]} "
                f"windows and {len(moves[i])} moves; at least {left:g} more moves needed"
            )
        if illegal[i] is not None:
            status, stats["illegal"] = PlanStatus.INVALID, illegal[i]
        if safe[i]:
            stats["safe_moves"] = safe[i]
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
) -> list[PlanResult]:
    """Plan every problem (all of one domain). ``progress(k)``: k more problems finished.

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
    if not config.batched:
        return [
            _run(domain, [p], config, generator, report, beliefs, [i], costs)[0]
            for i, p in enumerate(problems)
        ]
    # one tensor program per shape key (the domain's: sizes that pad alike), per-key times
    results: list[PlanResult | None] = [None] * len(problems)
    keys = [domain.shape_key(p) for p in problems]
    for key in sorted(set(keys)):
        group = [i for i, k in enumerate(keys) if k == key]
        subset = [problems[i] for i in group]
        planned = _run(domain, subset, config, generator, report, beliefs, group, costs)
        for i, result in zip(group, planned, strict=True):
            results[i] = result
    return results


def plan(
    problem: Problem,
    config: PlannerConfig = PlannerConfig(),
    seed: int = 0,
    beliefs: BeliefSource | None = None,
    costs: CostSource | None = None,
) -> PlanResult:
    """Plan one problem (``beliefs``: soft inputs from perception; ``costs``: move costs; see
    `plan_batch`)."""
    return plan_batch([problem], config, seed, beliefs=beliefs, costs=costs)[0]
