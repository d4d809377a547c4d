"""Soft beliefs from outside the planner: planning from perception instead of a crisp state.

By default a window starts from the one-hot encoding of the crisp state and aims at the
problem's goal atoms. A `BeliefSource` replaces both with soft support matrices (from images,
say) and may expose parameters of its own (perception weights), which the window's Adam then
updates together with the action logits, at their own learning rate, on the planning loss
plus the source's penalty (KL anchors).

Two crisp protocols. By default (the paper's) decoded moves are checked against the true
symbolic state and a problem is done when the true state satisfies its goal. Beliefs that
expose ``crisp_states`` (the perceived protocol: a robot without an oracle) make the planner
decode against those states instead, apply the decoded moves to the true state (the world),
end the plan as inexecutable at the first move that is illegal there (that move kept, last),
and finish a problem when a crisp state read after its moves satisfies the goal.

The window beliefs of this repository inherit `WindowBeliefsBase`, which gives the optional
members their defaults (the true states; no frozen beliefs to retry a stuck window with); a
source's beliefs that do not are wrapped once where the source enters the planner
(`belief_source`, in `task.planner.plan_batch`), their own members kept.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import Protocol

from torch import Tensor

from task.domains.base import State


class WindowBeliefs(Protocol):
    """The soft inputs of one planning window for P problems (all of one size N)."""

    lr: float  # Adam learning rate of ``parameters()`` (the paper: 1e-4 for perception)
    # the crisp state of each problem that decoding checks moves against and that the goal is
    # tested on; None (or no such attribute): the true states, the paper's protocol
    crisp_states: Sequence[State] | None

    def compute(self) -> tuple[Tensor, Tensor, Tensor]:
        """(F0, goal, penalty): (P, N, Y) soft initial supports, (P, N, Y) soft goal supports,
        (P,) extra loss. Called at every Adam step, so it may recompute from images."""
        ...

    def parameters(self) -> list[Tensor]:
        """Tensors to optimise with the logits; empty when the beliefs are frozen."""
        ...

    # Optional (`WindowBeliefsBase`): ``fallback(rows) -> WindowBeliefs | None``, frozen
    # beliefs for the problems at ``rows`` (positions in this window), with which the planner
    # retries a window that decoded no move under adapted beliefs: adapting perception must
    # never leave a problem stuck where the frozen reading plans on.


class BeliefSource(Protocol):
    """Makes the beliefs of a window for the problems ``indices`` (positions in the list given
    to `task.planner.plan_batch`) in their current crisp ``states``; None: the planner's own
    encoding of the true states."""

    def __call__(self, indices: Sequence[int], states: Sequence[State]) -> WindowBeliefs | None: ...


class WindowBeliefsBase(ABC):
    """A `WindowBeliefs` with the defaults of its optional members: ``crisp_states`` None
    (decode against the true states) and no `fallback`. The planner reads these members
    directly; window beliefs inherit this class, or are wrapped in it where their source
    enters the planner (`belief_source`)."""

    lr: float
    crisp_states: Sequence[State] | None = None

    @abstractmethod
    def compute(self) -> tuple[Tensor, Tensor, Tensor]: ...

    @abstractmethod
    def parameters(self) -> list[Tensor]: ...

    def fallback(self, rows: Sequence[int]) -> WindowBeliefsBase | None:
        """Frozen beliefs for the problems at ``rows`` to retry a stuck window with; by default
        None: the window is not retried."""
        return None


class _Given(WindowBeliefsBase):
    """Window beliefs that do not inherit `WindowBeliefsBase`, wrapped: their own
    ``crisp_states`` and ``fallback`` where they have them, else the defaults."""

    def __init__(self, given: WindowBeliefs) -> None:
        self.given, self.lr = given, given.lr
        self.crisp_states = getattr(given, "crisp_states", None)  # the one look at them
        self._fallback = getattr(given, "fallback", None)

    def compute(self) -> tuple[Tensor, Tensor, Tensor]:
        return self.given.compute()

    def parameters(self) -> list[Tensor]:
        return self.given.parameters()

    def fallback(self, rows: Sequence[int]) -> WindowBeliefsBase | None:
        return None if self._fallback is None else window_beliefs(self._fallback(rows))


def window_beliefs(beliefs: WindowBeliefs | None) -> WindowBeliefsBase | None:
    """``beliefs`` as a `WindowBeliefsBase`: themselves when they inherit it, else wrapped;
    None stays None (a source's answer for "plan from the true state")."""
    if beliefs is None or isinstance(beliefs, WindowBeliefsBase):
        return beliefs
    return _Given(beliefs)


class _Source:
    """A `BeliefSource` whose windows' beliefs are all `WindowBeliefsBase` (`window_beliefs`)."""

    def __init__(self, source: BeliefSource) -> None:
        self.source = source

    def __call__(self, indices: Sequence[int], states: Sequence[State]) -> WindowBeliefsBase | None:
        return window_beliefs(self.source(indices, states))


def belief_source(source: BeliefSource | None) -> BeliefSource | None:
    """``source`` (None stays None) made to give `WindowBeliefsBase` beliefs: where a belief
    source enters the planner, so that the optional members are looked up once, there."""
    if source is None or isinstance(source, _Source):
        return source
    return _Source(source)
