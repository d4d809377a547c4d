"""Move costs in `tamp.api`: `FixedCosts`, one window's constant cost matrix, and
`CostFunction`, a `task.costs.CostSource` from a function of a problem and a crisp state."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from task.costs import CostSourceBase
from task.problem import Problem

if TYPE_CHECKING:  # heavy modules load when a function needs them
    from torch import Tensor


@dataclass(frozen=True, eq=False)
class FixedCosts:
    """A `WindowCosts` with a constant matrix: ``matrix`` (P, N, Y) is the cost of moving
    entity x onto target y (targets: the entities, then the table) for each of the window's P
    problems; no continuous parameters. Costs at or above `IMPOSSIBLE` rule a move out."""

    matrix: Tensor
    lr: float = 0.0

    def compute(self) -> Tensor:
        return self.matrix  # (P, N, Y)

    def parameters(self) -> list[Tensor]:
        return []

    def commit(self, rows: Sequence[int | None], moves: Sequence[tuple]) -> None:
        return None


@dataclass(frozen=True, eq=False)
class CostFunction(CostSourceBase):
    """A `CostSource` from a function: ``price(problem, state)`` returns the (N, Y) tensor of
    costs of every move from the crisp ``state`` (Blocksworld: a tuple of each entity's support)
    of ``problems[i]``, where ``i`` is the problem's position in the list given to the planner
    (one problem: ``problems=(problem,)``). Every window is priced in its start state; a
    differentiable ``price`` lets gradients flow from the planner's loss into its inputs."""

    price: Callable[[Problem, object], Tensor]
    problems: tuple[Problem, ...]

    def __call__(self, indices: Sequence[int], states: Sequence[object], restarts: int):
        import torch

        rows = [self.price(self.problems[i], s) for i, s in zip(indices, states, strict=True)]
        return FixedCosts(torch.stack(rows))  # (P, N, Y)
