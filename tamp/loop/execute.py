"""Execute one relational move as a pick-and-place and detect how it failed.

Failure detection uses signals a real robot has: the finger opening against the block width,
contact force on both fingers (from whatever they touch: a fingertip sensor cannot tell what it
holds), a check after the lift and after the transit (are the fingers still held apart by a
block-wide object?), and a post-place check of the observed block pose. Every pose comes from
``observe``: the motion-capture oracle with ``observe="state"``, the depth camera with
``observe="camera"`` (`tamp.loop.observe.Observer.poses`). When the camera cannot see a block
the move needs, even from home, the move fails as ``unobservable``. The simulator's ground
truth is not read here (an episode locks it; `tamp.loop.score` alone scores). With the ``weld``
grasp, what is welded is the block between the closed fingers (`Simulator.attach`), not the
block the move names: a hand closed on nothing, or on the wrong block, holds what it holds.

Each phase tells the simulator which contacts it is meant to make (`tamp.sim.base.Expected`:
the arm on the block it handles; the held block on what it leaves and what it is put onto), so
the experimenter's contact scoring counts every other touch of the arm or the carried block.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from motion.guard import CollisionModel, GuardConfig, PickPlaceWorld, at_rest, guard_pick_place
from motion.ik import IKSolver
from motion.pick_place import Phase, PickPlaceConfig, PickPlaceRequest, plan_pick_place
from motion.trajectory import JointTrajectory
from perception.errors import PerceptionError
from tamp.obstacles import ceiling
from tamp.outcome import Failure
from tamp.scene import PlacedMove, Pose, SceneConfig, place_pose, top_z
from tamp.sim.base import Expected, Simulator, lost_hold
from tamp.sim.harness import Harness
from task.errors import member
from task.problem import TABLE, Move


class CollisionMode(enum.StrEnum):
    """What the executor does with the arm's collision model: PLAN, check every trajectory and
    reroute blocked free-space phases with the motion planner; CHECK, a predicted collision
    fails the move; OFF, run unchecked."""

    PLAN = "plan"
    CHECK = "check"
    OFF = "off"


# what the top-down executor failed with that the geometric room's grasps may still make
GEO_RETRIED = frozenset({Failure.IK_INFEASIBLE, Failure.COLLISION, Failure.NO_CLEARANCE})


@dataclass(frozen=True)
class ExecConfig:
    """Thresholds of the failure checks, and the pick-and-place settings."""

    motion: PickPlaceConfig = PickPlaceConfig()
    width_tol: float = 0.007  # m: a held block keeps the fingers at its width +- this
    min_force: float = 0.2  # N: both fingers must push at least this on a freshly closed grasp
    place_tol_xy: float = 0.015  # m: post-place check
    place_tol_z: float = 0.008  # m
    max_tracking: float = 0.3  # rad: beyond this the arm is blocked
    collision: CollisionMode = CollisionMode.PLAN  # a `CollisionMode` or its name
    margin: float = 0.01  # m: a trajectory passing closer than this to anything is a collision
    guard: GuardConfig = GuardConfig()
    slot_tries: int = 3  # free table slots a move to the table tries before it fails
    # collision "plan": a move the top-down grasps cannot make (no IK, a collision, no
    # clearance) is checked and run by the executor's `Fallback`, the geometric room
    # (`tamp.loop.geo_fallback.GeoFallback`, which the episode builds): side and tilted grasps too,
    # the transit at the corridor's height; False: top-down only
    geo_fallback: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "collision", member(CollisionMode, self.collision, "collision mode")
        )


@dataclass(frozen=True)
class ExecutionResult:
    """The outcome of one move: ok, or the failure kind and the evidence behind it."""

    move: Move
    ok: bool
    failure: Failure | None = None
    evidence: dict = field(default_factory=dict)
    sim_time_s: float = 0.0
    wall_time_s: float = 0.0
    ik_time_s: float = 0.0
    check_time_s: float = 0.0  # collision checks of the planned trajectories
    path_time_s: float = 0.0  # the motion planner's runs, detours found or not
    path_rad: float = 0.0  # joint-space length (rad) of the arm phases started: sum of |dq|
    rerouted: tuple[str, ...] = ()  # phases started on a motion-planner detour
    planner_runs: int = 0  # motion-planner runs over every grasp and slot tried
    planner_failures: int = 0  # ... of which found no collision-free detour

    def to_json(self) -> dict:
        """The move's record as plain JSON values (`tamp.episode_report.EpisodeReport`)."""
        return {
            "move": str(self.move),
            "ok": self.ok,
            "failure": self.failure.value if self.failure else None,
            "evidence": self.evidence,
            "sim_time_s": round(self.sim_time_s, 3),
            "wall_time_s": round(self.wall_time_s, 3),
            "ik_time_s": round(self.ik_time_s, 4),
            "rerouted": list(self.rerouted),
            "planner_runs": self.planner_runs,
            "planner_failures": self.planner_failures,
        }


Observe = Callable[[], dict[str, Pose]]  # every block's pose; PerceptionError: one is unseen


class Fallback(Protocol):
    """Another way to make a move the top-down grasps could not (one of `GEO_RETRIED`), given
    to the executor by whoever builds it (the episode: `tamp.loop.geo_fallback.GeoFallback`, every
    grasp family of the geometric room), so this module imports no room of its own."""

    def check(self, placing: Placing, q_now, seed: int = 0) -> bool:
        """Whether it finds the motion of ``placing`` from the arm at ``q_now``, nothing
        run."""
        ...

    def run(
        self,
        sim: Simulator,
        placing: Placing,
        config: ExecConfig,
        seed: int = 0,
        drop_at: float | None = None,
        observe: Observe | None = None,
    ) -> ExecutionResult:
        """Check ``placing`` from the arm's configuration now and run it when it passes
        (``drop_at``: the fault, `tamp.sim.harness.Harness`); the place checked on the poses
        ``observe`` gives after it."""
        ...


@dataclass(frozen=True)
class Placing:
    """One move as the executor makes it: ``move`` with ``target``, the pose its block is put
    at, among the blocks at ``poses`` on ``scene``'s table."""

    move: Move
    target: Pose
    poses: Mapping[str, Pose]
    scene: SceneConfig


@dataclass(frozen=True)
class ExecTools:
    """What the executor works with, built once by its caller (the episode): the IK
    ``solver``, the ``scene`` the moves are made in, the arm's ``collision`` model
    (`robots.collision.PandaCollision`, which checks the planned phases unless
    `ExecConfig.collision` is "off"; None: unchecked) and the ``fallback`` for the moves the
    top-down grasps cannot make (`Fallback`: the geometric room's,
    `tamp.loop.geo_fallback.GeoFallback`; None: top-down only)."""

    solver: IKSolver
    scene: SceneConfig = SceneConfig()
    collision: CollisionModel | None = None
    fallback: Fallback | None = None


def obstacle_boxes(scene: SceneConfig):
    """The scene's fixed obstacles as boxes of the arm's collision model."""
    from robots.collision import Box

    return tuple(Box(o.name, o.centre, o.half, o.yaw) for o in scene.obstacles)


def _supports(move: Move, poses: dict[str, Pose], scene: SceneConfig) -> tuple[str, str]:
    """What the picked block stands on, as observed, and what it goes onto (block names or
    "table")."""
    pick = poses[move.entity]
    below = [
        k
        for k, p in poses.items()
        if k != move.entity
        and np.linalg.norm(p.xy - pick.xy) <= scene.tol_xy
        and abs(pick.xyz[2] - p.xyz[2] - scene.block_size) <= 2 * scene.tol_z
    ]
    return below[0] if below else "table", "table" if move.target == TABLE else move.target


def _world(move: Move, poses: dict[str, Pose], target: Pose, scene: SceneConfig):
    """The collision world of a move: the observed blocks as boxes, the scene's obstacles,
    what the picked block stands on and what it goes onto (block names or "table")."""
    from robots.collision import Box

    half = (scene.block_size / 2,) * 3
    blocks = tuple(Box(k, p.xyz, half, p.yaw) for k, p in poses.items())
    fixed = obstacle_boxes(scene)
    below, onto = _supports(move, poses, scene)
    placed = Box(move.entity, target.xyz, half, target.yaw)
    return PickPlaceWorld(blocks + fixed, move.entity, below, onto, placed, scene.block_size)


def _expected(phase: str, block: str, supports: tuple[str, str]) -> Expected:
    """The contacts ``phase`` of the move of ``block`` is meant to make (contact scoring): the
    arm on the block throughout; once it is held, the block on what it leaves while lifted and
    on what it goes onto while lowered, nothing in transit."""
    rests = {"lift": supports[0], "transit": None, "lower": supports[1]}
    if phase not in rests:
        return Expected(block)
    return Expected(block, block, frozenset({rests[phase]} - {None}))


def _back_off(sim: Simulator, phases: tuple[Phase, ...], on_frame, expected: Expected) -> None:
    """After a failure at the block: open the gripper and undo the descent (a safe pose)."""
    sim.detach()
    q = sim.arm_q()
    hold = JointTrajectory.hold(q, 0.3, sim.dt)
    sim.run(hold, "open", on_frame=on_frame, expected=expected)
    phase = next(ph for ph in phases if ph.name == "descend")
    up = at_rest(phase).trajectory  # the descent may start moving (it passes from the approach)
    back = JointTrajectory(
        up.times, up.positions[::-1].copy(), -up.velocities[::-1], up.accelerations[::-1]
    )
    if np.abs(back.positions[0] - q).max() < 0.05:
        sim.run(back, "open", on_frame=on_frame, expected=expected)


def _plan(tools: ExecTools, move, poses, q_now, config, seed, times):
    """(target pose, phases, IK time, rerouted phases) of the move, or (Failure, IK time,
    evidence); adds to ``times`` (check s, planner s, path rad, planner runs, failures). A move
    whose motion fails tries the quarter-turned grasp (a neighbour touching the block on one
    side leaves the other pair of faces free), and a table placement the next free slots (up
    to ``config.slot_tries``)."""
    scene, collision = tools.scene, tools.collision
    ik, last = 0.0, None
    tries = range(config.slot_tries if move.target == TABLE else 1)
    pick = poses[move.entity]
    clear_z = top_z({k: v for k, v in poses.items() if k != move.entity}, scene)
    for rank, turn in ((r, t) for r in tries for t in (False, True)):
        target = place_pose(move, poses, scene, rank)
        if target is None:
            return last or (Failure.NO_FREE_SLOT, ik, {"slots": len(scene.slots)})
        request = PickPlaceRequest(
            pick.xyz,
            pick.yaw,
            target.xyz,
            target.yaw,
            clear_z,
            pick_ceiling=ceiling(pick.xyz, scene.obstacles),
            place_ceiling=ceiling(target.xyz, scene.obstacles),
            turn=turn,
        )
        planned = plan_pick_place(tools.solver, q_now, request, config.motion)
        ik += planned.ik_time_s
        if not planned.ok:
            last = (Failure(planned.failure), ik, planned.evidence)
            continue
        if collision is None or config.collision is CollisionMode.OFF:
            return target, planned.phases, ik, ()
        world = _world(move, poses, target, scene)
        guard = replace(config.guard, plan=config.collision is CollisionMode.PLAN)
        checked = guard_pick_place(planned.phases, collision, world, guard, seed)
        times[0] += checked.check_time_s
        times[1] += checked.plan_time_s
        times[3] += checked.planner_runs
        times[4] += "planner" in checked.evidence  # the detour the planner found no way for
        if checked.ok:
            return target, checked.phases, ik, checked.rerouted
        last = (Failure.COLLISION, ik, checked.evidence)
    return last


def _geo(sim, fallback: Fallback, placing: Placing, config, seed, drop_at, observe):
    """``placing`` checked and run by ``fallback``; the place checked on the poses ``observe``
    gives after it (a block the camera cannot see then: ``unobservable``)."""
    try:
        return fallback.run(sim, placing, config, seed, drop_at, observe)
    except PerceptionError as err:
        return ExecutionResult(placing.move, False, Failure.UNOBSERVABLE, {"seen": str(err)})


def _geo_retries(failure: Failure, config: ExecConfig, fallback: Fallback | None) -> bool:
    """Whether ``fallback`` retries a top-down move that failed with ``failure``: one of
    `GEO_RETRIED`, with a fallback given and on, and the collision model planning detours."""
    return (
        fallback is not None
        and failure in GEO_RETRIED
        and config.geo_fallback
        and config.collision is CollisionMode.PLAN
    )


def motion_check(
    tools: ExecTools,
    move: Move,
    poses: dict[str, Pose],
    q_now,
    config: ExecConfig = ExecConfig(),
    seed: int = 0,
) -> Failure | None:
    """What `execute_move` would find before the arm moves, with the blocks at ``poses`` and
    the arm at ``q_now``, nothing run: None when it finds the move's motion (top-down, each
    phase guarded, or with ``tools.fallback`` every other grasp), else the failure it would
    report. A planned move checked ahead, on the poses its plan predicts
    (`tamp.arm.costs.ArmCosts.verify`)."""
    times = [0.0, 0.0, 0.0, 0, 0]
    planned = _plan(tools, move, poses, q_now, config, seed, times)
    if not (isinstance(planned, tuple) and isinstance(planned[0], Failure)):
        return None
    fallback = tools.fallback
    if _geo_retries(planned[0], config, fallback):
        target = place_pose(move, poses, tools.scene)
        found = target is not None and fallback.check(
            Placing(move, target, poses, tools.scene), q_now, seed
        )
        if found:
            return None
    return planned[0]


def placed_elsewhere(move: Move, target: Pose) -> dict:
    """``{"placed_at": (x, y)}`` when ``move`` named a table place (`tamp.slots.PlacedMove`)
    and the executor put the block on another one, ``target`` (the next free slot: the
    top-down hand could not reach the named one, or it was taken), else ``{}``: evidence of a
    move that went through but not where its plan had it (`tamp.loop.episode`)."""
    at = move.at if isinstance(move, PlacedMove) else None
    if at is None or float(np.hypot(*np.subtract(target.xy, at))) <= 1e-6:
        return {}
    return {"placed_at": (round(float(target.xyz[0]), 4), round(float(target.xyz[1]), 4))}


def failed_pick(done: ExecutionResult) -> bool:
    """Whether ``done`` failed to pick its block with every grasp, before the arm moved: the
    top-down pick (its IK or its approach and descent) and every grasp of the geometric
    fallback (`tamp.loop.geo_fallback.run_geo`: each one's failure on the pick side), whatever the
    place. False without that fallback's verdict: the top-down pick alone hovers over the
    highest stack anywhere, which other moves change."""
    from tamp.geo.check import PICK_PHASES, PICK_WAYPOINTS

    ev, geo = done.evidence, done.evidence.get("geo")
    top = ev.get("waypoint") in PICK_WAYPOINTS or ev.get("phase") in PICK_PHASES
    return not done.ok and top and isinstance(geo, dict) and geo.get("sides") == ["pick"]


@dataclass
class _Tally:
    """One `execute_move`'s running totals and the result it ends with: ``times`` (collision
    checks s, motion planner s, path run rad, planner runs, planner failures) and the
    rerouted phases ``started``, from the simulator time ``sim0`` and the wall time
    ``wall0``."""

    sim: Simulator
    move: Move
    sim0: float
    wall0: float = field(default_factory=time.perf_counter)
    times: list = field(default_factory=lambda: [0.0, 0.0, 0.0, 0, 0])
    started: list[str] = field(default_factory=list)

    def result(
        self, failure: Failure | None = None, ik_time: float = 0.0, **evidence
    ) -> ExecutionResult:
        times = self.times
        return ExecutionResult(
            self.move,
            failure is None,
            failure,
            evidence,
            sim_time_s=self.sim.time - self.sim0,
            wall_time_s=time.perf_counter() - self.wall0,
            ik_time_s=ik_time,
            check_time_s=times[0],
            path_time_s=times[1],
            path_rad=times[2],
            rerouted=tuple(self.started),
            planner_runs=times[3],
            planner_failures=times[4],
        )


def _after_top_down(first: ExecutionResult, again: ExecutionResult, moved: dict):
    """The geometric fallback's result ``again`` after the top-down tries (``first``, their
    times): its outcome and path, ``moved`` added to its evidence, the times of both."""
    return replace(
        again,
        evidence={**again.evidence, **moved},
        sim_time_s=first.sim_time_s,
        wall_time_s=first.wall_time_s,
        ik_time_s=first.ik_time_s,
        check_time_s=first.check_time_s + again.check_time_s,
        path_time_s=first.path_time_s,
        planner_runs=first.planner_runs,
        planner_failures=first.planner_failures,
    )


def _no_block(sim: Simulator) -> dict:
    """A welded grasp's miss: the gripper block-wide, but no one block touches both fingers
    (`lost_hold`'s evidence)."""
    r = sim.gripper()
    return {"finger_width": round(r.width, 4), "weld": "no block between fingers"}


def execute_move(
    sim: Simulator,
    move: Move,
    observe: Observe,
    tools: ExecTools,
    config: ExecConfig = ExecConfig(),
    seed: int = 0,
    harness: Harness = Harness(),
) -> ExecutionResult:
    """Pick ``move.entity`` where it is observed and place it on ``move.target``.

    ``tools``: the IK solver, the scene, the arm's collision model and the fallback for the
    moves the top-down grasps cannot make (`ExecTools`); ``seed`` seeds the motion planner.
    ``harness``: the fault injected (``drop_at`` in [0, 1] opens the gripper at that fraction
    of the transit) and the recorders called as frames and phases pass (`Harness`).
    """
    scene, fallback = tools.scene, tools.fallback
    drop_at, on_frame, on_phase = harness.drop_at, harness.on_frame, harness.on_phase
    tally = _Tally(sim, move, sim.time)
    times, started, result = tally.times, tally.started, tally.result
    try:
        poses = observe()
    except PerceptionError as err:
        return result(Failure.UNOBSERVABLE, when="before the pick", seen=str(err))
    planned = _plan(tools, move, poses, sim.arm_q(), config, seed, times)
    if isinstance(planned, tuple) and isinstance(planned[0], Failure):
        if _geo_retries(planned[0], config, fallback):
            target = place_pose(move, poses, scene)
            if target is not None:
                placing = Placing(move, target, poses, scene)
                again = _geo(sim, fallback, placing, config, seed, drop_at, observe)
                if again.ok or again.path_rad > 0:  # it made the move, or it ran and failed
                    first = result(planned[0], planned[1])  # the top-down tries' times
                    moved = placed_elsewhere(move, target) if again.ok else {}
                    return _after_top_down(first, again, moved)
                planned[2]["geo"] = again.evidence
        return result(planned[0], planned[1], **planned[2])
    target, phases, ik, rerouted = planned
    supports, handling = _supports(move, poses, scene), Expected(move.entity)
    worst = 0.0
    for phase in phases:
        release = None
        if phase.name == "transit" and drop_at is not None:
            release = drop_at * phase.trajectory.duration
        if phase.name == "open":
            sim.detach()
        if phase.name in rerouted:
            started.append(phase.name)
        q = phase.trajectory.positions  # (S, J)
        times[2] += float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum())
        expected = _expected(phase.name, move.entity, supports)
        if on_phase is not None:
            on_phase(sim, phase)
        worst = max(worst, sim.run(phase.trajectory, phase.gripper, release, on_frame, expected))
        if worst > config.max_tracking:
            _back_off(sim, phases, on_frame, handling)
            return result(Failure.TRACKING, ik, phase=phase.name, error_rad=round(worst, 3))
        width = config.motion.block_size
        lost = lost_hold(sim, phase.name, width, config, on_frame, handling, _no_block)
        if lost is not None and lost[0] is Failure.GRASP_MISSED:
            _back_off(sim, phases, on_frame, handling)
            return result(Failure.GRASP_MISSED, ik, **lost[1])
        if lost is not None:
            injected = release is not None  # the fault injection opened the gripper
            return result(Failure.DROPPED, ik, after=phase.name, injected=injected, **lost[1])
    try:
        seen = observe()[move.entity]
    except PerceptionError as err:
        return result(Failure.UNOBSERVABLE, ik, when="after the place", seen=str(err))
    dxy = float(np.linalg.norm(seen.xy - np.asarray(target.xyz[:2])))
    dz = abs(seen.xyz[2] - target.xyz[2])
    if dxy > config.place_tol_xy or dz > config.place_tol_z:
        return result(
            Failure.MISPLACED,
            ik,
            off_xy_m=round(dxy, 4),
            off_z_m=round(dz, 4),
            target=[round(v, 4) for v in target.xyz],
        )
    return result(None, ik, tracking_rad=round(worst, 4), **placed_elsewhere(move, target))
