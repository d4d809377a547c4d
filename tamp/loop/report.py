"""What an episode reports: its `tamp.outcome.EpisodeStatus`, why it stopped (the geometric
episode's vocabulary too), and `EpisodeReport`, what happened;
`Progress` is the tally an episode keeps while it runs, which becomes its report."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

from tamp.loop.execute import ExecutionResult
from tamp.outcome import EpisodeStatus
from task.problem import Move


@dataclass(frozen=True)
class EpisodeReport:
    """What happened in one episode; ``reached_goal`` is scored on simulator ground truth."""

    problem: str
    sim: str
    status: EpisodeStatus
    reached_goal: bool
    moves: tuple[ExecutionResult, ...]
    plans: tuple[tuple[str, ...], ...]  # every plan made, as move strings
    replans: int
    faults: tuple[str, ...]  # injected faults, e.g. "drop@3" (move index)
    # moves not scored clean on ground truth (`tamp.loop.score.MoveScore`): another block
    # changed support, or the true state before or after was unreadable (``unreadable`` of them)
    disturbed: int
    sim_time_s: float
    wall_time_s: float
    plan_time_s: float
    initial_plan_solved: bool = False  # the first task plan reached the goal symbolically
    reason: str = ""
    first_plan: tuple[Move, ...] = ()  # the first task plan's moves (camera: its first window)
    steps: tuple = ()  # a given plan: one `tamp.loop.given.StepReport` per step
    # scoring: what the arm, the hand or the block held in it touched in the simulator that
    # the move was not meant to touch (`tamp.sim.base.Expected`): block, obstacle or "table",
    # "held:" + name for the held block's contacts -> physics steps in contact; `collided` is
    # True when anything was touched
    touched: dict = field(default_factory=dict)
    unreadable: int = 0  # moves after which (or before which) the true state formed no state
    # ground-truth reads answered, by grant (`tamp.sim.truth.GRANTS`), e.g. {"scoring": 12}
    truth_reads: dict = field(default_factory=dict)

    @property
    def collided(self) -> bool:
        return bool(self.touched)

    def to_json(self) -> dict:
        out = dataclasses.asdict(self)
        out["status"] = self.status.value
        out["first_plan"] = [str(m) for m in self.first_plan]
        out["moves"] = [
            {
                "move": str(r.move),
                "ok": r.ok,
                "failure": r.failure.value if r.failure else None,
                "evidence": r.evidence,
                "sim_time_s": round(r.sim_time_s, 3),
                "wall_time_s": round(r.wall_time_s, 3),
                "ik_time_s": round(r.ik_time_s, 4),
                "rerouted": list(r.rerouted),
                "planner_runs": r.planner_runs,
                "planner_failures": r.planner_failures,
            }
            for r in self.moves
        ]
        return out


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
        self, problem: str, sim: str, reached: bool, sim_time: float, wall0: float
    ) -> EpisodeReport:
        """The EpisodeReport; ``wall0`` is the episode's start on ``time.perf_counter``."""
        return EpisodeReport(
            problem,
            sim,
            self.status,
            reached,
            tuple(self.moves),
            tuple(self.plans),
            self.replans,
            tuple(self.faults),
            self.disturbed,
            sim_time,
            time.perf_counter() - wall0,
            self.plan_time,
            self.first_solved,
            self.reason,
            self.first_plan,
            unreadable=self.unreadable,
        )
