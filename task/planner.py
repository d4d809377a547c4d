"""Receding-window planning: optimise a window, decode, execute the legal moves, replan.

``plan_batch`` plans many problems in one tensor program per window and problem size (restarts
as extra rows; the code pads and masks, so any mix of sizes also works in one program);
problems that reach their goal leave the batch.
With ``PlannerConfig(batched=False)`` the same code runs one problem at a time, so the speed-up
of batching can be measured.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import torch

from task.beliefs import BeliefSource, WindowBeliefs
from task.config import PlannerConfig
from task.decode import decode_best
from task.domains import get_domain
from task.domains.base import Domain, State
from task.errors import TampError
from task.optimize import optimise_window
from task.problem import Plan, PlanResult, PlanStatus, Problem


def _window(
    domain: Domain,
    problems: Sequence[Problem],
    states: Sequence[State],
    config: PlannerConfig,
    generator: torch.Generator,
    beliefs: WindowBeliefs | None = None,
):
    batch = domain.encode(problems, states, torch.float32).repeat(config.restarts)
    horizons = torch.tensor(config.horizons()).repeat(len(problems))  # (B,)
    steps = torch.arange(int(horizons.max())) < horizons[:, None]  # (B, T)
    _, roll = optimise_window(domain, batch, steps, config, generator, beliefs)
    return decode_best(
        domain, problems, states, roll.gates, roll.loss, config.restarts, config.threshold
    )


def _run(
    domain: Domain,
    problems: Sequence[Problem],
    config: PlannerConfig,
    generator: torch.Generator,
    on_done: Callable[[int], None],
    source: BeliefSource | None = None,
    indices: Sequence[int] = (),
) -> list[PlanResult]:
    """Plan all ``problems`` together; ``on_done(k)`` reports k newly finished problems.

    ``indices``: the problems' positions in the caller's list (what ``source`` is told)."""
    start = time.perf_counter()
    states = [domain.initial_state(p) for p in problems]
    moves: list[list] = [[] for _ in problems]
    windows = [0] * len(problems)
    active = [i for i, p in enumerate(problems) if not domain.is_goal(p, states[i])]
    on_done(len(problems) - len(active))
    for _ in range(config.max_windows):
        if not active:
            break
        now = [states[i] for i in active]
        beliefs = None if source is None else source([indices[i] for i in active], now)
        decoded = _window(domain, [problems[i] for i in active], now, config, generator, beliefs)
        still = []
        for i, win in zip(active, decoded, strict=True):
            windows[i] += 1
            moves[i].extend(win.moves)
            states[i] = win.state
            if not win.reached:
                still.append(i)
        on_done(len(active) - len(still))
        active = still
    on_done(len(active))
    elapsed = time.perf_counter() - start
    results = []
    for i, p in enumerate(problems):
        reached = domain.is_goal(p, states[i])
        stats = {
            "windows": windows[i],
            "time_s": elapsed / len(problems),
            "batch_time_s": elapsed,
        }
        status = PlanStatus.SOLVED if reached else PlanStatus.NO_PLAN
        results.append(PlanResult(status, Plan(tuple(moves[i])), p, None, stats))
    return results


def plan_batch(
    problems: Sequence[Problem],
    config: PlannerConfig = PlannerConfig(),
    seed: int = 0,
    progress: Callable[[int], None] | None = None,
    beliefs: BeliefSource | None = None,
) -> list[PlanResult]:
    """Plan every problem (all of one domain). ``progress(k)``: k more problems finished.

    Returns one PlanResult per problem, in order; ``stats["time_s"]`` is the wall time per
    problem (the batch's time divided among its problems when batched). ``beliefs`` gives
    every window soft initial and goal supports (planning from perception, `task.beliefs`).
    """
    if not problems:
        return []
    names = {p.domain for p in problems}
    if len(names) > 1:
        raise TampError(f"plan_batch needs problems of one domain, got {sorted(names)}")
    domain = get_domain(problems[0].domain)
    generator = torch.Generator().manual_seed(seed)
    report = progress or (lambda k: None)
    if not config.batched:
        return [
            _run(domain, [p], config, generator, report, beliefs, [i])[0]
            for i, p in enumerate(problems)
        ]
    # one tensor program per problem size: no padding work, and per-size times in the stats
    results: list[PlanResult | None] = [None] * len(problems)
    for n in sorted({p.n for p in problems}):
        group = [i for i, p in enumerate(problems) if p.n == n]
        subset = [problems[i] for i in group]
        planned = _run(domain, subset, config, generator, report, beliefs, group)
        for i, result in zip(group, planned, strict=True):
            results[i] = result
    return results


def plan(
    problem: Problem,
    config: PlannerConfig = PlannerConfig(),
    seed: int = 0,
    beliefs: BeliefSource | None = None,
) -> PlanResult:
    """Plan one problem (``beliefs``: soft inputs from perception, see `plan_batch`)."""
    return plan_batch([problem], config, seed, beliefs=beliefs)[0]
