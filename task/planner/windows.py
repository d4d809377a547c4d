"""One receding window of the planner (`task.planner`): encode the problems' states, optimise
the action logits with Adam (`task.optimize`), decode the moves against a crisp state and execute
the legal ones on the world; a part of a big problem in a window of its own
(`PlannerConfig.safe_from`, `task.domains.base.window_part`), and the domain's safe moves taken
without one; with a cost source, a window cut before a move the source rules out in its own
state (`own_state_prefix`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import torch

from task.beliefs import WindowBeliefsBase
from task.config import PlannerConfig
from task.costs import WindowCosts
from task.decode import DecodedWindow, DecodeRule, WindowStart, decode_best, proof_stop
from task.domains.base import Domain, SoftBatch, State, window_part
from task.errors import TampError
from task.optimize import Window, optimise_window
from task.planner.context import PlanContext, Progress
from task.problem import Move, Problem
from task.rollout import check_deadline

PROOF_PROBLEMS = 1  # windows of at most this many problems are read early (`_proofs`): a read
# costs about a third of an Adam step, and a window stops only once all its problems are proven,
# which in a batch of many rarely happens (PlanBench's 150 4-block problems in one batch: 8%
# more CPU with reads, none stopped early)


def run_window(
    context: PlanContext,
    starts: Sequence[WindowStart],
    beliefs: WindowBeliefsBase | None = None,
    costs: WindowCosts | None = None,
) -> list[DecodedWindow]:
    """The decoded window of each problem from its start (`decode_best`), planned with the
    context's settings and cut short at its ``windows_end``; a window of one problem
    (`PROOF_PROBLEMS`), without beliefs and move costs, may stop early
    (`task.decode.proof_stop`). Each start's ``park``: whether parking moves rank free
    (`PlannerConfig.parks` of its problem; a part of a problem (`_part_windows`) keeps its
    whole problem's)."""
    domain, config = context.domain, context.config
    problems, states = [s.problem for s in starts], [s.state for s in starts]
    device = torch.device(config.device)  # checked by `plan_batch` (`torch_device`)
    batch = on_device(domain.encode(problems, states, torch.float32), device)
    batch = batch.repeat(config.restarts)
    horizons = torch.tensor(config.horizons(), device=device).repeat(len(problems))  # (B,)
    steps = torch.arange(int(horizons.max()), device=device) < horizons[:, None]  # (B, T)
    proven: dict[int, DecodedWindow] = {}
    stop = None
    priced_ok = costs is None or config.proof_costs
    if len(problems) <= PROOF_PROBLEMS and beliefs is None and priced_ok:
        stop = proof_stop(domain, starts, config, proven)
    window = Window(domain, batch, steps, config, beliefs, costs, context.windows_end)
    _, roll = optimise_window(window, context.generator, stop)
    if len(proven) == len(problems):
        return [proven[i] for i in range(len(problems))]
    decoded = decode_best(domain, starts, roll.gates, roll.loss, DecodeRule.of(config), roll.costs)
    return [proven.get(i, window) for i, window in enumerate(decoded)]


def on_device(batch: SoftBatch, device: torch.device) -> SoftBatch:
    """``batch`` with every tensor, its ``static`` ones too, on ``device`` (domains encode on
    the CPU; the window's optimisation and rollout then run where the batch is)."""
    static = {k: v.to(device) for k, v in batch.static.items()}
    return SoftBatch(*(t.to(device) for t in batch.astuple()), static=static)


def _retry_frozen(
    context: PlanContext,
    starts: Sequence[WindowStart],
    beliefs: WindowBeliefsBase | None,
    decoded: list[DecodedWindow],
) -> set[int]:
    """Windows that decoded no move under adapted beliefs are planned again from their
    ``starts`` with the beliefs' frozen ``fallback`` (`task.beliefs`, without move costs); a
    retry that moves replaces the window in place. Returns the positions of the replaced
    windows."""
    stuck = [k for k, w in enumerate(decoded) if not w.moves and not w.reached]
    if beliefs is None or not stuck:
        return set()
    frozen = beliefs.fallback(stuck)
    if frozen is None:
        return set()
    again = run_window(context, [starts[k] for k in stuck], frozen)
    replaced = set()
    for k, window in zip(stuck, again, strict=True):
        if window.moves or window.reached:
            decoded[k] = window
            replaced.add(k)
    return replaced


def crisp_states(
    beliefs: WindowBeliefsBase | None, world: Sequence[State]
) -> tuple[Sequence[State], bool]:
    """The states a window decodes against and whether they are perceived (not the world)."""
    crisp = None if beliefs is None else beliefs.crisp_states
    if crisp is None:
        return world, False
    if len(crisp) != len(world):
        raise TampError(f"beliefs give {len(crisp)} crisp states for {len(world)} problems")
    return tuple(crisp), True


def execute(
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


def own_state_prefix(
    domain: Domain,
    problem: Problem,
    state: State,
    moves: Sequence[Move],
    feasible: Callable[[State, Move], bool],
    verify: Callable[[State, Move], bool] | None = None,
) -> tuple[Move, ...]:
    """The window ``moves`` from the world ``state`` up to (not including) the first move
    after the first that is legal in the state it starts from but that ``feasible`` (the cost
    source's verdict there, `task.planner.fallback.cost_checks`) rules out
    (`PlannerConfig.own_state_costs`). The window's cost matrix priced every step in its start
    state, where such a move may still have been illegal (priced 0, so the decoder kept it):
    the next window starts before it and prices it where it would be made. The first move
    was priced in its own state by the decoder and is kept; an illegal move is left to
    `execute`, which names it. ``verify`` (the cost source's check ahead,
    `task.costs.CostSource`): each legal move, the first too, is also checked where it starts,
    and the window ends before the first that fails (none kept when the first fails: the
    source has ruled it out there, and the next window from the same state decodes another)."""
    for k, move in enumerate(moves):
        if domain.check_move(problem, state, move) is not None:
            break
        if k > 0 and not feasible(state, move):
            return tuple(moves[:k])
        if verify is not None and not verify(state, move):
            return tuple(moves[:k])
        state = domain.apply_move(problem, state, move)
    return tuple(moves)


def take_safe(
    context: PlanContext,
    problems: Sequence[Problem],
    active: Sequence[int],
    progress: Progress,
) -> list[int]:
    """The ``active`` problems that `PlannerConfig.takes_safe` take their domain's safe moves
    (`Domain.safe_moves`) in the world, as executed moves (recorded in ``progress``); returns
    those still active (not at the goal). Only without beliefs and a cost source (the
    caller's check)."""
    domain, config = context.domain, context.config
    if not domain.has_safe_moves:
        return list(active)
    states, solved = progress.states, progress.solved
    still = []
    for i in active:
        if config.takes_safe(problems[i]):
            for move in domain.safe_moves(problems[i], states[i]):
                states[i] = domain.apply_move(problems[i], states[i], move)
                progress.visited[i].add(states[i])
                progress.moves[i].append(move)
                progress.safe[i] += 1
            solved[i] = domain.is_goal(problems[i], states[i])
        if not solved[i]:
            still.append(i)
    return still


def _part_windows(context: PlanContext, starts: Sequence[WindowStart]) -> list[DecodedWindow]:
    """The decoded windows from ``starts`` without beliefs and move costs: the problems that
    `PlannerConfig.takes_safe` plan the part still to be planned, cut to what their windows'
    moves reach (`task.domains.base.window_part`), with the part's settings
    (`PlannerConfig.for_parts`), each keeping its whole problem's ``park``; the others plan
    as they are. One `run_window` per settings."""
    config = context.config
    part_config = config.for_parts()
    groups: dict[PlannerConfig, list[int]] = {}
    views = list(starts)
    for k, start in enumerate(starts):
        here = part_config if config.takes_safe(start.problem) else config
        if config.takes_safe(start.problem):
            depth = max(here.horizons())
            problem, state, seen = window_part(
                context.domain, start.problem, start.state, start.seen, depth
            )
            views[k] = WindowStart(problem, state, seen, start.park)
        groups.setdefault(here, []).append(k)
    decoded: list[DecodedWindow | None] = [None] * len(starts)
    for here, ks in groups.items():
        windows = run_window(replace(context, config=here), [views[k] for k in ks])
        for k, window in zip(ks, windows, strict=True):
            decoded[k] = window
    return decoded


def next_window(
    context: PlanContext,
    problems: Sequence[Problem],
    active: Sequence[int],
    progress: Progress,
):
    """One window of the ``active`` problems from their world states (in ``progress``): the
    decoded windows, the window's costs (None without a source), the positions of the windows
    a frozen-belief retry replaced, the crisp states decoded against and whether they are
    perceived. Raises `task.rollout.OutOfTime` when the context's ``windows_end`` passes
    before the window is decoded."""
    config, deadline, indices = context.config, context.windows_end, context.indices
    check_deadline(deadline)
    now = [progress.states[i] for i in active]
    source = context.source
    beliefs = None if source is None else source([indices[i] for i in active], now)
    crisp, perceived = crisp_states(beliefs, now)
    priced = None
    if context.costs is not None:
        priced = context.costs([indices[i] for i in active], crisp, config.restarts)
    check_deadline(deadline)
    starts = [
        WindowStart(problems[i], state, progress.visited[i], config.parks(problems[i]))
        for i, state in zip(active, crisp, strict=True)
    ]
    if context.plain:
        decoded = _part_windows(context, starts)
    else:
        decoded = run_window(context, starts, beliefs, priced)
    retried = _retry_frozen(context, starts, beliefs, decoded)
    return decoded, priced, retried, crisp, perceived
