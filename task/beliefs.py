"""Soft beliefs from outside the planner: planning from perception instead of a crisp state.

By default a window starts from the one-hot encoding of the crisp state and aims at the
problem's goal atoms. A `BeliefSource` replaces both with soft support matrices (from images,
say) and may expose parameters of its own (perception weights), which the window's Adam then
updates together with the action logits, at their own learning rate, on the planning loss
plus the source's penalty (KL anchors). The crisp side never changes: decoded moves are still
checked against the true symbolic state and the goal test is the problem's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from torch import Tensor

from task.domains.base import State


class WindowBeliefs(Protocol):
    """The soft inputs of one planning window for P problems (all of one size N)."""

    lr: float  # Adam learning rate of ``parameters()`` (the paper: 1e-4 for perception)

    def compute(self) -> tuple[Tensor, Tensor, Tensor]:
        """(F0, goal, penalty): (P, N, Y) soft initial supports, (P, N, Y) soft goal supports,
        (P,) extra loss. Called at every Adam step, so it may recompute from images."""
        ...

    def parameters(self) -> list[Tensor]:
        """Tensors to optimise with the logits; empty when the beliefs are frozen."""
        ...


class BeliefSource(Protocol):
    """Makes the beliefs of a window for the problems ``indices`` (positions in the list given
    to `task.planner.plan_batch`) in their current crisp ``states``."""

    def __call__(self, indices: Sequence[int], states: Sequence[State]) -> WindowBeliefs: ...
