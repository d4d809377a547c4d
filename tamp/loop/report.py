"""What an episode reports: `Progress` is the tally a loop episode keeps while it runs, which
becomes its `EpisodeReport` (`tamp.episode_report`: the one report type of both stacks,
re-exported here), with its `tamp.outcome.EpisodeStatus`."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from tamp.episode_report import EpisodeReport
from tamp.loop.execute import ExecutionResult
from tamp.outcome import EpisodeStatus
from task.problem import Move

__all__ = ["EpisodeReport", "Progress"]


@dataclass
class Progress:
    """What one run of an episode has done so far; ``stop`` ends it with a status."""

    state: tuple[str, ...] | None  # the last observed symbolic state
    first_solved: bool  # the first task plan reached the goal symbolically
    first_plan: tuple[Move, ...] = ()  # the first task plan's moves
    moves: list[ExecutionResult] = field(default_factory=list)
    plans: list[tuple[str, ...]] = field(default_factory=list)
    faults: list[str] = field(default_factory=list)
    queue: list[Move] = field(default_factory=list)  # the planned moves still to execute
    planned: tuple[str, ...] | None = None  # the state the queue was planned from, advanced
    replans: int = 0
    disturbed: int = 0  # moves not scored clean (`tamp.loop.score.MoveScore`)
    unreadable: int = 0  # ... of which the true state was unreadable
    tidies: int = 0
    stalls: int = 0  # camera: windows in a row that decoded no move
    plan_time: float = 0.0
    status: EpisodeStatus = EpisodeStatus.GOAL_REACHED
    reason: str = ""
    stopped: bool = False

    def stop(self, status: EpisodeStatus, reason: str) -> None:
        self.status, self.reason, self.stopped = status, reason, True

    def report(
        self,
        problem: str,
        sim: str,
        reached: bool,
        sim_time: float,
        wall0: float,
        planner: str = "",
        observation: str = "state",
    ) -> EpisodeReport:
        """The EpisodeReport; ``wall0`` is the episode's start on ``time.perf_counter``;
        ``planner``: the planner that ran, ``observation``: the pose sensor."""
        return EpisodeReport(
            problem=problem,
            sim=sim,
            status=self.status,
            reached_goal=reached,
            moves=tuple(self.moves),
            plans=tuple(self.plans),
            replans=self.replans,
            faults=tuple(self.faults),
            disturbed=self.disturbed,
            sim_time_s=sim_time,
            wall_time_s=time.perf_counter() - wall0,
            plan_time_s=self.plan_time,
            initial_plan_solved=self.first_solved,
            reason=self.reason,
            first_plan=self.first_plan,
            unreadable=self.unreadable,
            planner=planner,
            observation=observation,
        )
