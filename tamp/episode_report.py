"""`EpisodeReport`: what one episode returns, in both stacks.

The Blocksworld loop (`tamp.loop.episode.Episode`) and the geometric episode
(`tamp.geo.episode.run_geo_episode`) report in this one type, each field with one name and one
spelling: ``sim``, ``planner``, ``status`` (`tamp.outcome.EpisodeStatus`), ``reason``,
``reached_goal`` (scored on ground truth), ``moves``, ``replans``, ``plan_time_s``,
``sim_time_s``, ``wall_time_s``, ... The fields only one stack fills keep their defaults in the
other (the loop's ``disturbed`` and ``steps``; the geometric episode's ``plan_stats`` and
``pose_errors``), so `EpisodeReport.to_json` has the same top-level keys whichever episode ran.

A move record is the stack's own (`tamp.loop.execute.ExecutionResult`,
`tamp.geo.episode.MoveRecord`): each has ``move``, ``ok``, ``failure``
(`tamp.outcome.Failure` or None), ``evidence`` and ``to_json()``. This module imports nothing
of either stack.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from tamp.outcome import EpisodeStatus, Failure


@dataclass(frozen=True)
class EpisodeReport:
    """What happened in one episode; ``reached_goal`` is scored on simulator ground truth."""

    problem: str  # the problem's or the scene's name
    sim: str
    status: EpisodeStatus
    reached_goal: bool
    moves: tuple[Any, ...]  # one record per move attempted (see the module docstring)
    plans: tuple[tuple[str, ...], ...]  # every plan made, as move strings
    replans: int
    faults: tuple[str, ...]  # injected faults, e.g. "drop@3" (move index)
    # moves not scored clean on ground truth (`tamp.loop.score.MoveScore`): another block
    # changed support, or the true state before or after was unreadable (``unreadable`` of them)
    disturbed: int
    sim_time_s: float
    wall_time_s: float
    plan_time_s: float  # every planner call of the episode
    initial_plan_solved: bool = False  # the first task plan reached the goal symbolically
    reason: str = ""
    # the first plan's moves (`task.problem.Move`; geometric: `tamp.geo.types.GeoMove`; the
    # loop's camera observation: its first window)
    first_plan: tuple[Any, ...] = ()
    steps: tuple = ()  # a given plan: one `tamp.loop.given.StepReport` per step
    # scoring: what the arm, the hand or the object held in it touched in the simulator that
    # the move was not meant to touch (`tamp.sim.base.Expected`): object, obstacle or "table",
    # "held:" + name for the held object's contacts -> physics steps in contact; `collided` is
    # True when anything was touched
    touched: dict = field(default_factory=dict)
    unreadable: int = 0  # moves after which (or before which) the true state formed no state
    # ground-truth reads answered, by grant (`tamp.sim.truth.GRANTS`), e.g. {"scoring": 12}
    truth_reads: dict = field(default_factory=dict)
    # the planner that ran: the loop's "soft" (the soft-T_P planner) or "motion-aware" (with
    # the arm's move costs); geometric: a `tamp.modes.GeoPlanner` value
    planner: str = ""
    observation: str = "state"  # the pose sensor: "state" (motion capture) or "camera"
    plan_times_s: tuple[float, ...] = ()  # geometric: per planner call
    plan_stats: tuple[dict, ...] = ()  # geometric: each planner call's stats
    arm_path_rad: float = 0.0  # geometric: the arm's joint path run
    # geometric, camera: the estimates' errors against ground truth (scored, never acted on)
    pose_errors: dict = field(default_factory=dict)

    @property
    def collided(self) -> bool:
        return bool(self.touched)

    @property
    def collisions(self) -> int:
        """Things the arm or the held object touched unexpectedly."""
        return len(self.touched)

    @property
    def motion_failures(self) -> int:
        """Moves whose check or run failed (a move that ran but gave other facts than planned,
        ``unexpected``, is none)."""
        return sum(m.failure not in (None, Failure.UNEXPECTED) for m in self.moves)

    @property
    def plan_length(self) -> int:
        """Moves of the first plan (0: none)."""
        return len(self.first_plan)

    @property
    def solved_clean(self) -> bool:
        """Reached without a motion failure and without a collision."""
        return self.reached_goal and self.motion_failures == 0 and not self.collided

    def to_json(self) -> dict:
        """The report as plain JSON values: every field, enums as their values, each move by
        its record's ``to_json()``, and the counts ``collisions``, ``motion_failures`` and
        ``plan_length``."""
        out = dataclasses.asdict(self)
        out["status"] = self.status.value
        out["first_plan"] = [str(m) for m in self.first_plan]
        out["moves"] = [r.to_json() for r in self.moves]
        out["collisions"] = self.collisions
        out["motion_failures"] = self.motion_failures
        out["plan_length"] = self.plan_length
        return out
