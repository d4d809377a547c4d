"""Decode optimised soft windows into crisp moves, checked against the true symbolic state.

At each step the single strongest applied move mass ``g_t(x, y)`` is a move when it reaches the
confidence threshold (otherwise the step is a STAY). Each decoded move is checked against the
crisp state reached so far; decoding stops at the first illegal one, so only legal moves are
ever returned. Among a problem's restarts the best decoded window is kept.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from torch import Tensor

from task.domains.base import Domain, State
from task.problem import Move, Problem


@dataclass(frozen=True)
class DecodedWindow:
    moves: tuple[Move, ...]
    state: State  # crisp state after the moves
    reached: bool  # the goal holds in ``state``
    complete: bool  # every confident step decoded to a legal move
    loss: float  # the soft objective of the restart it came from
    remaining: int  # the domain's admissible lower bound on moves still needed from ``state``

    def key(self) -> tuple:
        """Sort key: the goal reached in fewest moves; else some progress, then the least
        estimated total (moves + remaining), then the most moves, then the soft objective."""
        g = len(self.moves)
        if self.reached:
            return (0, g, 0, 0, self.loss)
        return (1, g == 0, g + self.remaining, -g, not self.complete, self.loss)


def target_name(problem: Problem, column: int, n: int) -> str:
    """Name of padded target column ``column`` (entities occupy 0..n-1, fixed targets n..)."""
    return problem.entities[column] if column < n else problem.fixed[column - n]


def decode_row(
    domain: Domain,
    problem: Problem,
    state: State,
    gates: Tensor,
    threshold: float,
    loss: float,
) -> DecodedWindow:
    """Decode one rollout row. gates: (T, N, Y) applied move mass of that row."""
    n = gates.shape[1]
    best, flat = gates.flatten(1).max(-1)  # (T,), (T,)
    moves: list[Move] = []
    complete = True
    for value, index in zip(best.tolist(), flat.tolist(), strict=True):
        if value < threshold:
            continue  # a STAY step
        x, y = divmod(index, gates.shape[2])
        move = None
        if x < problem.n and not n > y >= problem.n:  # padding is never a legal move
            move = Move(problem.entities[x], target_name(problem, y, n))
        if move is None or domain.check_move(problem, state, move) is not None:
            complete = False
            break
        state = domain.apply_move(problem, state, move)
        moves.append(move)
        if domain.is_goal(problem, state):
            break
    reached = domain.is_goal(problem, state)
    remaining = 0 if reached else domain.lower_bound(problem, state)
    return DecodedWindow(tuple(moves), state, reached, complete, loss, remaining)


def decode_best(
    domain: Domain,
    problems: Sequence[Problem],
    states: Sequence[State],
    gates: Tensor,
    losses: Tensor,
    restarts: int,
    threshold: float,
) -> list[DecodedWindow]:
    """Best decoded window per problem. gates: (P * R, T, N, Y) with restarts adjacent."""
    gates, losses = gates.cpu(), losses.cpu().tolist()
    out = []
    for i, (problem, state) in enumerate(zip(problems, states, strict=True)):
        rows = range(i * restarts, (i + 1) * restarts)
        windows = [decode_row(domain, problem, state, gates[r], threshold, losses[r]) for r in rows]
        out.append(min(windows, key=DecodedWindow.key))
    return out
