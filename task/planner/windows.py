"""One receding window of the planner (`task.planner`): encode the problems' states, optimise
the action logits with Adam (`task.optimize`), decode the moves against a crisp state and execute
the legal ones on the world; a part of a big problem in a window of its own
(`PlannerConfig.safe_from`, `task.domains.base.window_part`), and the domain's safe moves taken
without one; with a cost source, a window cut before a move the source rules out in its own
state (`own_state_prefix`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import torch

from task.beliefs import BeliefSource, WindowBeliefs
from task.config import PlannerConfig
from task.costs import CostSource, WindowCosts
from task.decode import DecodedWindow, decode_best, proof_stop
from task.domains.base import Domain, SoftBatch, State, window_part
from task.errors import TampError
from task.optimize import optimise_window
from task.problem import Move, Problem
from task.rollout import check_deadline

PROOF_PROBLEMS = 1  # windows of at most this many problems are read early (`_proofs`): a read
# costs about a third of an Adam step, and a window stops only once all its problems are proven,
# which in a batch of many rarely happens (PlanBench's 150 4-block problems in one batch: 8%
# more CPU with reads, none stopped early)


def run_window(
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
    again = run_window(
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


def crisp_states(
    beliefs: WindowBeliefs | None, world: Sequence[State]
) -> tuple[Sequence[State], bool]:
    """The states a window decodes against and whether they are perceived (not the world)."""
    crisp = getattr(beliefs, "crisp_states", None)
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
        windows = run_window(
            domain, *pick[:2], here, generator, None, pick[2], None, deadline, parked
        )
        for k, window in zip(ks, windows, strict=True):
            decoded[k] = window
    return decoded


def next_window(
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
    crisp, perceived = crisp_states(beliefs, now)
    priced = None
    if costs is not None:
        priced = costs([indices[i] for i in active], crisp, config.restarts)
    check_deadline(deadline)
    views = [problems[i] for i in active], list(crisp), [visited[i] for i in active]
    parks = [config.parks(p) for p in views[0]]
    if source is None and costs is None:
        decoded = _part_windows(domain, *views, config, generator, deadline, parks)
    else:
        decoded = run_window(
            domain, *views[:2], config, generator, beliefs, views[2], priced, deadline, parks
        )
    retried = _retry_frozen(
        domain, problems, active, crisp, config, generator, beliefs, visited, decoded, deadline
    )
    return decoded, priced, retried, crisp, perceived
