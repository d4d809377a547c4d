"""The arm a plan is priced for (`Arm`), as its planner knows it now: its IK solver, where it
stands, what its executor can do besides the top-down grasp and what it failed so far. Given
to the arm's cost source, `tamp.arm.costs.ArmCosts`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from motion.ik import IKSolver
from tamp.arm.failures import FailedMove
from tamp.scene import Pose
from task.domains.base import State
from task.problem import Move


@dataclass(frozen=True)
class Arm:
    """The arm a plan is priced for, as its planner knows it now: the IK ``solver``, where it
    stands (``q_now``, (J,)), what its executor can do besides the top-down grasp over the
    highest stack (``grasps``: the grasp families of its geometric fallback, with which a pick
    or place only those reach is not ruled out, `ArmCosts`; ``check``: the executor's own check
    of a move among poses, `ArmCosts.verify`; None: none), and what it failed so far
    (``avoid``: plain state -> `failed_key`s of the moves that failed there; ``failed``: the
    moves it failed by where, ruled out wherever they would be the same, `FailedMove`)."""

    solver: IKSolver
    q_now: object
    grasps: tuple[str, ...] = ()
    check: Callable[[Mapping[str, Pose], Move], bool] | None = None
    avoid: Mapping[State, set] | None = None
    failed: Sequence[FailedMove] = ()
