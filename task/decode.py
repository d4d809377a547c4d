"""Decode optimised soft windows into crisp moves, checked against a crisp state.

At each step the single strongest applied move mass ``g_t(x, y)`` is a move when it reaches the
confidence threshold (otherwise the step is a STAY). Each decoded move is checked against the
crisp state reached so far (the planner passes the true state, or under the perceived protocol
the state read from the current image); decoding stops at the first illegal one, so only legal
moves are returned. Among a problem's restarts the best decoded window is kept.

With ``prefix`` (`task.config.PlannerConfig.rank_prefixes`, for domains ranked by their lower
bound) a window is cut to its best prefix first: the least moves + lower bound after them, then
the fewest *buried* moves (a move that leaves the bound where it was and puts an entity on
another entity rather than on a fixed target, such as a block on a block that is not its goal),
then the most moves. The bound drops by at most one a move, so this keeps the moves up to the
first one that makes no progress: a 5-move window whose third move wastes a move executes two
moves, and the next window plans again from there. With ``park`` (`PlannerConfig.park_free`) a
*parking* move (the bound unchanged, the entity put on a fixed target: a block to the table)
costs nothing in that sum: the bound counts a block that must move once, while a block that is
in the way and whose place is not ready moves twice, first to the table.

Without the crisp check (``check=False``, `task.config.PlannerConfig.crisp_check`) the first
illegal move is kept as the window's last move, and the restart with the lowest soft objective
wins (ranking restarts by their crisp replay would be the check again); the planner then finds
the move illegal in the world and the plan is inexecutable.

`proof_stop` reads a window while Adam optimises it and ends it early once its decode is
provably a shortest way to the goal.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, replace

from torch import Tensor

from task.config import PlannerConfig
from task.costs import IMPOSSIBLE
from task.domains.base import Domain, State
from task.problem import Problem
from task.rollout import Rollout


@dataclass(frozen=True)
class DecodedWindow:
    moves: tuple
    state: State  # crisp state after the moves
    reached: bool  # the goal holds in ``state``
    complete: bool  # every confident step decoded to a legal move
    loss: float  # the soft objective of the restart it came from
    remaining: float  # the domain's admissible lower bound from ``state`` (inf: a dead end)
    illegal: str | None = None  # check=False: why the last move is illegal in ``state``
    estimated: float | None = None  # the domain's ranking estimate (None: ``remaining``)
    revisit: bool = False  # ``state`` was already visited earlier in the plan (a loop)
    motion: float = 0.0  # the move costs of ``moves`` (`task.costs`; 0 without a cost source)
    buried: int = 0  # moves that left the bound unchanged, putting an entity on an entity
    row: int = 0  # the restart row of its problem it was decoded from (0 <= row < R)

    def key(self) -> tuple:
        """Sort key: the goal reached in fewest moves; else not a dead end (an infinite lower
        bound ranks last, whatever moved), then not back to a state the plan already visited,
        then some progress, then the least estimated total
        (moves + the domain's optional `estimate`, else its lower bound, less the parking moves
        under ``park``), then the fewest buried moves, then the most moves, then the least move
        cost, then the soft objective."""
        g = len(self.moves)
        if self.reached:
            return (0, g, self.motion, 0, 0, self.loss)
        dead = math.isinf(self.remaining)
        rest = self.remaining if self.estimated is None else self.estimated
        return (
            1,
            dead,
            self.revisit,
            g == 0,
            g + rest,
            self.buried,
            -g,
            self.motion,
            not self.complete,
            self.loss,
        )


@dataclass(frozen=True)
class WindowStart:
    """Where one problem's window starts, as the decoder reads it: the ``problem``, the crisp
    ``state`` its moves are checked against, the states its plan already passed through
    (``seen``: a window that ends in one is a ``revisit``) and whether parking moves rank free
    (``park``, `PlannerConfig.parks`)."""

    problem: Problem
    state: State
    seen: Collection[State] = ()
    park: bool = False


@dataclass(frozen=True)
class DecodeRule:
    """How a window is decoded: the confidence ``threshold`` a step's move mass must reach,
    the ``restarts`` (R) rows of each problem (adjacent in the batch), the crisp ``check``
    (False keeps the first illegal move and ranks restarts by the soft objective alone) and
    ``prefix`` (rank each window by its best prefix; see the module docstring)."""

    threshold: float
    restarts: int = 1
    check: bool = True
    prefix: bool = False

    @classmethod
    def of(cls, config: PlannerConfig) -> DecodeRule:
        """The rule of a planner's settings (`PlannerConfig.threshold`, ``restarts``,
        ``crisp_check``, ``rank_prefixes``)."""
        return cls(config.threshold, config.restarts, config.crisp_check, config.rank_prefixes)


def decode_row(
    domain: Domain,
    start: WindowStart,
    gates: Tensor,
    loss: float,
    rule: DecodeRule,
    costs: Tensor | None = None,
) -> DecodedWindow:
    """Decode one rollout row from ``start``. gates: (T, N, A - 1) applied move mass of that
    row; ``loss``: its soft objective; costs: (N, A - 1) its move costs (`task.costs`), summed
    over the decoded moves; a move costing `task.costs.IMPOSSIBLE` or more is refused like an
    illegal one. ``rule.prefix`` and ``start.park``: rank its prefixes (see the module
    docstring).

    ``rule.check=False`` keeps the first illegal move (last in ``moves``, reason in
    ``illegal``)."""
    problem, state, check = start.problem, start.state, rule.check
    n = gates.shape[1]
    best, flat = gates.flatten(1).max(-1)  # (T,), (T,)
    moves: list = []
    complete, illegal, motion = True, None, 0.0
    if domain.is_goal(problem, state):  # nothing to do (a perceived state may already be it)
        return DecodedWindow((), state, True, True, loss, 0)
    trail: list[tuple[State, float]] = []  # (state, move cost so far) after each move
    for value, index in zip(best.tolist(), flat.tolist(), strict=True):
        if value < rule.threshold:
            continue  # a STAY step
        row, col = divmod(index, gates.shape[2])
        move = domain.decode(problem, row, col, n)  # None: padding, never a legal move
        reason = "padding" if move is None else domain.check_move(problem, state, move)
        if reason is None and costs is not None and float(costs[row, col]) >= IMPOSSIBLE:
            reason = f"the cost source rules {move} out (cost {float(costs[row, col]):.3g})"
        if reason is not None:
            complete = False
            if not check and move is not None:
                moves.append(move)
                illegal = reason
            break
        state = domain.apply_move(problem, state, move)
        moves.append(move)
        motion += 0.0 if costs is None else float(costs[row, col])
        trail.append((state, motion))
        if domain.is_goal(problem, state):
            break
    reached = domain.is_goal(problem, state)
    estimate = domain.has_estimate  # the domain's own inadmissible ranking estimate
    if rule.prefix and check and not estimate and moves and not reached:
        return _best_prefix(domain, start, moves, trail, complete, loss)
    remaining = 0 if reached else domain.lower_bound(problem, state)
    estimated = None if reached or not estimate else domain.estimate(problem, state)
    return DecodedWindow(
        moves=tuple(moves),
        state=state,
        reached=reached,
        complete=complete,
        loss=loss,
        remaining=remaining,
        illegal=illegal,
        estimated=estimated,
        revisit=state in start.seen,
        motion=motion,
    )


def _best_prefix(
    domain: Domain,
    start: WindowStart,
    moves: Sequence,
    trail: Sequence[tuple[State, float]],
    complete: bool,
    loss: float,
) -> DecodedWindow:
    """The best prefix (see the module docstring) of a window that makes ``moves`` from
    ``start``, passing through ``trail`` (the state and the move cost so far after each)."""
    problem, seen, park = start.problem, start.seen, start.park
    before = domain.lower_bound(problem, start.state)
    best, buried, parked = None, 0, 0
    for k, (move, (state, motion)) in enumerate(zip(moves, trail, strict=True), start=1):
        bound = domain.lower_bound(problem, state)
        fixed = getattr(move, "target", None) in problem.fixed
        buried += bound >= before and not fixed
        parked += park and bound == before and fixed
        window = DecodedWindow(
            moves=tuple(moves[:k]),
            state=state,
            reached=False,
            complete=complete,
            loss=loss,
            remaining=bound,
            illegal=None,
            estimated=bound - parked,
            revisit=state in seen,
            motion=motion,
            buried=buried,
        )
        if best is None or window.key() < best.key():
            best = window
        before = bound
    return best


def decode_best(
    domain: Domain,
    starts: Sequence[WindowStart],
    gates: Tensor,
    losses: Tensor,
    rule: DecodeRule,
    costs: Tensor | None = None,
) -> list[DecodedWindow]:
    """Best decoded window per problem, one per ``starts`` (a window that ends in a state
    its ``seen`` holds ranks below every window that does not). gates: (P * R, T, N, A - 1),
    restarts adjacent (``rule.restarts``); losses: (P * R,) the rows' soft objectives.
    ``rule.check=False``: illegal moves are kept and the lowest soft objective wins.
    ``costs``: (P * R, N, A - 1) move costs (`task.costs`). Each window names the restart
    row it came from (``row``)."""
    gates, losses = gates.cpu(), losses.cpu().tolist()
    costs = None if costs is None else costs.detach().cpu()
    restarts = rule.restarts
    out = []
    for i, start in enumerate(starts):
        windows = []
        for k, r in enumerate(range(i * restarts, (i + 1) * restarts)):
            c = None if costs is None else costs[r]
            window = decode_row(domain, start, gates[r], losses[r], rule, c)
            windows.append(replace(window, row=k))
        out.append(min(windows, key=DecodedWindow.key if rule.check else _soft_objective))
    return out


def _soft_objective(window: DecodedWindow) -> float:
    """Restart ranking without the crisp check: the soft objective alone."""
    return window.loss


NEAR_GOAL = 10.0  # `proof_stop` decodes a restart early only when its soft goal cross-entropy at
# the decode temperature is below this (a cheap filter: it can delay a stop,
# never make one wrong; far rows read 30 to 1000, rows that reach it about 0)


def proof_stop(
    domain: Domain,
    starts: Sequence[WindowStart],
    config: PlannerConfig,
    proven: dict[int, DecodedWindow],
) -> Callable[[Rollout], bool] | None:
    """The early stop of a window (`PlannerConfig.proof_every`; `task.planner` passes it to
    the window's optimisation): the rollout is read as the decoder reads it, and a problem
    whose best window reaches the goal in as many moves as the domain's admissible lower
    bound from the window's start state is done: no further Adam step could decode a shorter
    way to the goal. That window is kept in ``proven`` (later reads and the final decode are
    not used for it: a problem's plan does not depend on whether the others of its batch are
    proven too). The stop is True once every problem is proven. None (no reads) when no
    problem can be (its bound exceeds the longest window) or without the crisp check. Only the
    restarts near the goal in the rollout (`NEAR_GOAL`) are decoded, the best of them by the
    decoder's ranking (`DecodedWindow.key`)."""
    longest = max(config.horizons())
    bounds = [domain.lower_bound(start.problem, start.state) for start in starts]
    hopeful = [i for i, bound in enumerate(bounds) if bound <= longest]
    if not hopeful or not config.crisp_check or not config.proof_every:
        return None
    r = config.restarts
    rule = replace(DecodeRule.of(config), check=True)

    def stop(roll: Rollout) -> bool:
        near = (roll.goal < NEAR_GOAL).view(len(starts), r).tolist()  # (P, R)
        todo = [i for i in hopeful if i not in proven and any(near[i])]
        if not todo:
            return False
        gates, losses = roll.gates.cpu(), roll.loss.cpu().tolist()
        priced = None if roll.costs is None else roll.costs.detach().cpu()  # (B, N, Y)
        for i in todo:
            windows = []
            for k in (k for k in range(r) if near[i][k]):
                row = i * r + k
                c = None if priced is None else priced[row]
                window = decode_row(domain, starts[i], gates[row], losses[row], rule, c)
                windows.append(replace(window, row=k))
            best = min(windows, key=DecodedWindow.key)
            if best.reached and len(best.moves) <= bounds[i]:
                proven[i] = best
        return len(proven) == len(starts)

    return stop
