"""Move costs from outside the planner: the arm inside the planning objective.

A `CostSource` gives every planning window a cost ``c(x, y)`` for each move of an entity ``x``
onto a target ``y`` in the window's start state, for example the arm's joint-space motion and
reach of each candidate pick-and-place (`tamp.arm.costs`, computed through pytorch-kinematics).
The planner adds the expected cost of the committed move mass to its loss,

    L_motion = lambda_motion * sum_t sum_(x, y) g_t(x, y) c(x, y)

(`task.config.PlannerConfig.lambda_motion`), and ranks restarts that are equally good at task
level (validity, then length) by the crisp cost of their decoded moves. The costs may depend
on continuous parameters of the source (placements), which the window's Adam then optimises
with the action logits at the source's own learning rate. Such parameters belong to one
restart row of one window: each row optimises its own copy from the source's start values (so
a row is optimised as it would be alone, `task.optimize`), and after decoding the planner tells
the window which row each problem's committed moves came from (`WindowCosts.commit`), so the
source can execute every move with the values it was decided with. The soft machinery never
leaves `task`; the costs come in as a tensor. The costs are those of the window's start state
for every step of the window (later steps see the same matrix): an approximation the next
window corrects, as it starts from the state the executed moves reached.

A source may also check moves ahead: ``verify(index, state, move) -> bool`` says
whether the move of problem ``index`` can be carried out where it starts (the arm's executor
check on the poses the source predicts there, `tamp.arm.costs.ArmCosts.verify`). The receding
windows call it on each move they keep (`task.planner.windows.own_state_prefix`), ending the
window before the first it fails; the source then rules that move out in that state, so the
next window decodes another. A cheap matrix for every move, an exact check for the few the
windows choose: motion feasibility checked lazily, and a failure fed back, before anything
runs. A source that records the moves committed to it may drop them again, ``forget(index)``,
when the planner's fallback starts a problem's plan over from its initial state; only a source
that can (``can_forget``) lets the fallback start over.

The cost sources of this repository inherit `CostSourceBase`, which gives these members their
defaults (every move passes the check ahead; nothing to forget, so no start over); a user's own
`CostSource` that does not inherit it is wrapped once where it enters the planner
(`cost_source`, in `task.planner.plan_batch`), its own ``verify`` and ``forget`` kept.

Shapes: P problems in the window (all of one size N, `Y` targets each), R restart rows per
problem, adjacent in the batch (row ``p * R + r`` is restart r of problem p).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import Protocol

import torch
from torch import Tensor

from task.domains.base import State
from task.errors import TampError

# a move costing this much or more is one the source says cannot be executed (the arm cannot
# reach it, it failed there before): the decoder refuses it like an illegal move
IMPOSSIBLE = 10.0


class WindowCosts(Protocol):
    """The move costs of one planning window for P problems (all of one size N), R restart
    rows each."""

    lr: float  # Adam learning rate of ``parameters()``

    def compute(self) -> Tensor:
        """The cost of moving entity x onto target y: (P, N, Y), every restart row of a
        problem priced alike, or (P * R, N, Y), one matrix per row (restarts adjacent), when
        it depends on per-row ``parameters()``. Called at every Adam step, so it may depend on
        ``parameters()`` differentiably; a row's costs must depend on that row's values only."""
        ...

    def parameters(self) -> list[Tensor]:
        """Continuous variables to optimise with the logits (placements), fresh for this
        window, their leading axis one entry per restart row (P * R); may be empty."""
        ...

    def commit(self, rows: Sequence[int | None], moves: Sequence[tuple]) -> None:
        """The planner executes ``moves[p]`` (in order) for window problem p, decoded from its
        restart row ``rows[p]`` (0 <= row < R; None: from a retry planned without these costs).
        A source with parameters records that row's values as the ones the moves are executed
        with; one without has nothing to record."""
        ...


class CostSource(Protocol):
    """Makes the costs of a window for the problems ``indices`` (positions in the list given to
    `task.planner.plan_batch`) in their current crisp ``states``, planned with ``restarts`` (R)
    restart rows each."""

    def __call__(
        self, indices: Sequence[int], states: Sequence[State], restarts: int
    ) -> WindowCosts: ...


class CostSourceBase(ABC):
    """A `CostSource` with the defaults of its optional members: every move passes the check
    ahead (`verify`) and there is nothing to forget (`forget`, ``can_forget`` False). The
    planner calls these members directly; cost sources inherit this class, or are wrapped in
    it where they enter the planner (`cost_source`)."""

    # whether `forget` drops the moves committed to the source: only then may the planner's
    # fallback start a plan over from the initial state (the source's moves would be stale)
    can_forget: bool = False

    @abstractmethod
    def __call__(
        self, indices: Sequence[int], states: Sequence[State], restarts: int
    ) -> WindowCosts: ...

    def verify(self, index: int, state: State, move) -> bool:
        """Whether the move of problem ``index`` can be carried out where it starts, in
        ``state`` (the check ahead of the receding windows,
        `task.planner.windows.own_state_prefix`); by default every move can."""
        return True

    def forget(self, index: int) -> None:
        """Drop the moves committed for problem ``index`` (the fallback started its plan over
        from the initial state); by default there is nothing to drop."""
        return None


class _Given(CostSourceBase):
    """A `CostSource` that does not inherit `CostSourceBase`, wrapped: its own ``verify`` and
    ``forget`` where it has them, else the defaults."""

    def __init__(self, given: CostSource) -> None:
        self.given = given
        self._verify = getattr(given, "verify", None)  # the one look at its optional members
        self._forget = getattr(given, "forget", None)
        self.can_forget = self._forget is not None

    def __call__(
        self, indices: Sequence[int], states: Sequence[State], restarts: int
    ) -> WindowCosts:
        return self.given(indices, states, restarts)

    def verify(self, index: int, state: State, move) -> bool:
        return True if self._verify is None else bool(self._verify(index, state, move))

    def forget(self, index: int) -> None:
        if self._forget is not None:
            self._forget(index)


def cost_source(costs: CostSource | None) -> CostSourceBase | None:
    """``costs`` as a `CostSourceBase` (None stays None): itself when it inherits the class,
    else wrapped once, its optional members looked up here and nowhere else."""
    if costs is None or isinstance(costs, CostSourceBase):
        return costs
    return _Given(costs)


def finite_costs(costs: Tensor) -> Tensor:
    """``costs`` (any shape) when every value is a number, else TampError (one line): a NaN or
    infinite cost would steer the optimiser nowhere and the planner would report a solvable
    problem as unsolvable. Rule a move out with a finite cost at or above `IMPOSSIBLE`."""
    if not bool(torch.isfinite(costs).all()):
        bad = costs[~torch.isfinite(costs)].flatten()[0].item()  # the first non-finite value
        raise TampError(
            f"move costs from the cost source must be finite numbers, got {bad} in a matrix of "
            f"shape {tuple(costs.shape)} (rule a move out with a cost >= IMPOSSIBLE = {IMPOSSIBLE})"
        )
    return costs
