"""The interface a planning domain supplies, and the tensor encoding shared by relational domains.

A domain is one file in ``task/domains/`` that provides its soft gates (``soft_legality``,
``consistency``), its crisp legality and apply, and its PDDL mapping. The rollout, optimiser,
decoder and replanning windows (``task.rollout``, ``task.optimize``, ``task.decode``,
``task.planner``) are shared and never change per domain.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import torch
from torch import Tensor

from task.problem import Action, Move, Problem

State = tuple[str, ...]  # crisp support of each entity, in problem.entities order


@dataclass(frozen=True)
class SoftBatch:
    """Padded tensors for B problems with at most N entities and K fixed targets.

    Columns are ``N`` entity slots followed by ``K`` fixed targets, so the table sits at column
    ``N`` for every problem whatever its size. Padded entities rest on the first fixed target,
    may only STAY and are never targets.
    """

    F0: Tensor  # (B, N, Y) crisp initial supports, one-hot rows
    entity_mask: Tensor  # (B, N) bool, real entities
    action_mask: Tensor  # (B, N, A) bool, A = Y + 1, last column STAY
    goal: Tensor  # (B, N, Y) one-hot goal atoms, zero rows for entities the goal leaves free

    @property
    def n(self) -> int:
        return self.F0.shape[1]

    def repeat(self, r: int) -> SoftBatch:
        """Each problem ``r`` times in a row (restarts): (B, ...) -> (B * r, ...)."""
        return SoftBatch(*(t.repeat_interleave(r, dim=0) for t in self.astuple()))

    def astuple(self) -> tuple[Tensor, Tensor, Tensor, Tensor]:
        return (self.F0, self.entity_mask, self.action_mask, self.goal)


def encode_supports(
    problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype = torch.float32
) -> SoftBatch:
    """One-hot support tensors for problems whose targets are entities + fixed targets."""
    n = max(p.n for p in problems)
    k = len(problems[0].fixed)
    b, y = len(problems), n + k
    F0 = torch.zeros(b, n, y, dtype=dtype)
    goal = torch.zeros(b, n, y, dtype=dtype)
    entity = torch.zeros(b, n, dtype=torch.bool)
    target = torch.zeros(b, y, dtype=torch.bool)
    for i, (p, s) in enumerate(zip(problems, states, strict=True)):
        col = {name: j for j, name in enumerate(p.entities)}
        col.update({name: n + j for j, name in enumerate(p.fixed)})
        F0[i, torch.arange(n), n] = 1.0  # padding rests on the first fixed target
        for x, sup in enumerate(s):
            F0[i, x] = 0.0
            F0[i, x, col[sup]] = 1.0
        for x, sup in p.goal:
            goal[i, col[x], col[sup]] = 1.0
        entity[i, : p.n] = True
        target[i, : p.n] = True
        target[i, n:] = True
    not_self = ~torch.eye(n, y, dtype=torch.bool)  # (N, Y)
    moves = entity[:, :, None] & target[:, None, :] & not_self  # (B, N, Y)
    stay = torch.ones(b, n, 1, dtype=torch.bool)
    return SoftBatch(F0, entity, torch.cat([moves, stay], dim=-1), goal)


class Domain(Protocol):
    """What a domain file provides. Tensors are batch first; see the glossary in ``task``."""

    name: str

    def encode(
        self, problems: Sequence[Problem], states: Sequence[State], dtype: torch.dtype
    ) -> SoftBatch: ...

    def soft_legality(self, F: Tensor, batch: SoftBatch) -> Tensor:
        """Soft legality of every move(x -> y): (B, N, Y) -> (B, N, Y) in [0, 1]."""
        ...

    def consistency(self, F: Tensor, batch: SoftBatch) -> Tensor:
        """The domain's T_P consistency operator (one application), (B, N, Y) -> (B, N, Y)."""
        ...

    def cycle_loss(self, F: Tensor, batch: SoftBatch) -> Tensor:
        """Penalty on direct two-cycles in the relation, (B, N, Y) -> (B,)."""
        ...

    def goal_loss(self, F: Tensor, batch: SoftBatch, kind: str) -> Tensor:
        """Goal term of the objective, (B, N, Y) -> (B,); ``kind`` names the variant."""
        ...

    def initial_state(self, problem: Problem) -> State: ...

    def check_move(self, problem: Problem, state: State, move: Move) -> str | None:
        """None when ``move`` is legal in ``state``, else a one-line reason."""
        ...

    def apply_move(self, problem: Problem, state: State, move: Move) -> State: ...

    def is_goal(self, problem: Problem, state: State) -> bool: ...

    def lower_bound(self, problem: Problem, state: State) -> int:
        """An admissible lower bound on the moves still needed to reach the goal."""
        ...

    def to_actions(
        self, problem: Problem, moves: Sequence[Move], strict: bool = True
    ) -> tuple[Action, ...]:
        """The domain's PDDL actions for a sequence of relational moves (its PDDL mapping);
        ``strict=False`` also translates illegal moves, for a validator to find."""
        ...
