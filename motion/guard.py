"""Collision-check a planned pick-and-place before it runs, and route blocked free-space phases
around obstacles with the joint-space motion planner.

Each arm phase is checked against the world as it is during that phase (arm, fingers and, once
grasped, the held object against the table, the blocks and the obstacles; the object a box of
any size, held where its grasp puts it, see `PickPlaceWorld`), with the contacts the move needs
allowed: the open fingers around the object they pick (descend, retreat), the held object on
what it leaves (lift) and on what it is placed onto (lower). A blocked free-space phase
(``approach`` or ``transit``) is replanned with `motion.rrt.plan_path` and timed along the new
path with ruckig; a blocked vertical phase, or a free-space phase the planner cannot route, is a
``collision`` failure with the contact as evidence. A detour starts and ends at rest, so the
vertical phases next to it, which may have been timed to pass into the free-space phase
without stopping (`motion.pick_place`), are re-timed along the same path to stop there.

The collision model is anything with `robots.collision.PandaCollision`'s ``set_boxes``,
``hold``, ``valid`` and ``check_path``; this module never imports a simulator. A model that
also has ``valid_batch`` (`motion.sphere_check.Screened`: a conservative sphere model beside
the meshes) screens each phase first, every densified configuration in one batch: where the
spheres find the whole phase free the meshes would too (they never say "free" where the meshes
find a contact), and only a phase the spheres flag goes to the mesh model's ``check_path``,
which has the final word. The motion planner searches with the same batch check
(`motion.rrt.plan_path` ``valid_batch``), and its detour is checked again like any phase.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Protocol

import numpy as np

from motion.pick_place import Phase
from motion.trajectory import APPROACH, TRANSIT, SpeedLimits, polyline_segment, thin

if TYPE_CHECKING:
    from motion.grasps import Grasp
    from motion.rrt import PathPlannerConfig
    from robots.collision import Box, PathCheck

FREE_SPACE = ("approach", "transit")  # phases the motion planner may reroute


class CollisionModel(Protocol):
    margin: float  # m

    def set_boxes(self, boxes: Sequence[Box]) -> None: ...
    def hold(self, size: float | None = ..., half=..., pose=...) -> None: ...
    def valid(self, q, fingers: float = ..., ignore=...) -> bool: ...
    def check_path(
        self, path, fingers: float = ..., ignore=..., max_step: float = ...
    ) -> PathCheck: ...


@dataclass(frozen=True)
class GuardConfig:
    """``plan``: reroute blocked free-space phases with the motion planner (else a blocked phase
    fails); ``max_step``: joint step (rad) between checked configurations."""

    plan: bool = True
    max_step: float = 0.02
    speed: SpeedLimits = TRANSIT  # a detour's speed limits (the free-space phases')
    rrt: PathPlannerConfig | None = None  # None: motion.rrt's defaults
    open_width: float = 0.04  # m per finger, open
    plan_pad: float = 0.01  # m added to the model's margin while the motion planner searches
    # m, the margin of the vertical phases: a block lifted from beside a touching neighbour
    # slides along it, which is no collision
    vertical_margin: float = 0.002
    # rad (the largest joint's move): a free-space phase that starts where the arm stands
    # within the margin of something but clear of it at ``vertical_margin`` (where the last
    # move left it, tracking included) is checked at that margin this near its start, so the
    # arm may move off; MoveIt's start-state fix moves such a start to a valid state nearby
    escape: float = 0.15
    dt: float = 0.002


@dataclass(frozen=True)
class PickPlaceWorld:
    """What the move changes: the boxes before it (blocks and obstacles), the picked block's
    name, what it stands on and what it is placed onto (box names, or "table"), the placed box,
    and the block edge (the fingers close to half of it each).

    Any other held object: ``half``, its half extents (3,) m, and ``grasp``, how the hand
    holds it (`MotionResult.grasp`: the grasp the move was planned with). The held box then
    rides at the inverse of the grasp's TCP pose in the TCP frame, and the fingers close to
    half the grasp's width each; ``half`` None: the cube of edge ``block``; ``grasp`` None:
    the object centred at the TCP, turned with the hand (top-down), the fingers at ``block``
    / 2 each."""

    boxes: tuple[Box, ...]
    picked: str
    picked_from: str
    placed_on: str
    placed: Box
    block: float
    half: tuple[float, float, float] | None = None
    grasp: Grasp | None = None


@dataclass(frozen=True)
class Guarded:
    """The phases to run (rerouted where needed), or the ``collision`` failure and evidence."""

    ok: bool
    phases: tuple[Phase, ...]
    failure: str | None = None
    evidence: dict = field(default_factory=dict)
    rerouted: tuple[str, ...] = ()  # phases replaced by a motion-planner detour
    check_time_s: float = 0.0
    plan_time_s: float = 0.0
    planner_runs: int = 0  # motion-planner runs, whether or not they found a detour


def _situation(name: str, world: PickPlaceWorld, open_width: float):
    """Boxes, whether the object is held, finger opening and allowed contacts during ``name``."""
    before = tuple(world.boxes)
    without = tuple(b for b in before if b.name != world.picked)
    grip = (world.block if world.grasp is None else world.grasp.width) / 2
    return {
        "approach": (before, False, open_width, ()),
        "descend": (before, False, open_width, (("hand", world.picked),)),
        "lift": (without, True, grip, (("held", world.picked_from),)),
        "transit": (without, True, grip, ()),
        "lower": (without, True, grip, (("held", world.placed_on),)),
        "retreat": ((*without, world.placed), False, open_width, (("hand", world.picked),)),
    }[name]


def hold_picked(model: CollisionModel, world: PickPlaceWorld | None) -> None:
    """Put ``world``'s picked object in the model's hand as the grasp holds it (see
    `PickPlaceWorld`); None: empty the hand."""
    if world is None:
        model.hold(None)
    elif world.half is None and world.grasp is None:
        model.hold(world.block)
    else:
        half = world.half if world.half is not None else (world.block / 2,) * 3
        pose = None if world.grasp is None else np.linalg.inv(world.grasp.matrix)
        model.hold(half=tuple(half), pose=pose)


def path_clear(
    path: np.ndarray,
    model: CollisionModel,
    world: PickPlaceWorld,
    phase: str,
    config: GuardConfig = GuardConfig(),
) -> bool:
    """Whether the joint path ``path`` (K, J), not yet a timed phase, is clear as the guard
    checks phase ``phase`` of the move in ``world``: its boxes, held object, fingers and
    allowed contacts, a vertical phase at the vertical margin (a screen for paths a planner
    considers before it plans them, `tamp.geo.postures`). Leaves the model set for it."""
    boxes, held, fingers, ignore = _situation(phase, world, config.open_width)
    model.set_boxes(boxes)
    hold_picked(model, world if held else None)
    low = model.margin if phase in FREE_SPACE else _low(model, config)
    with _margin(model, low):
        return _check_path(model, path, fingers, ignore, config.max_step).ok


def _check_path(model: CollisionModel, path: np.ndarray, fingers: float, ignore, step: float):
    """``model.check_path(path, fingers, ignore, step)`` (a `robots.collision.PathCheck`),
    screened by ``model.valid_batch`` when the model has one: a path the conservative batch
    check finds free is free (its ``checks``: the configurations screened)."""
    screen = getattr(model, "valid_batch", None)
    if screen is not None:
        from robots.collision import PathCheck, densify  # the model's own module: loaded

        _, qs, _ = densify(path, np.full(len(path), fingers), step)  # (N, J)
        if screen(qs, fingers, ignore).all():
            return PathCheck(True, None, None, None, len(qs))
    return model.check_path(path, fingers, ignore, step)


@contextmanager
def _margin(model: CollisionModel, value: float):
    """The model's margin set to ``value`` for the block, restored after."""
    before, model.margin = model.margin, value
    try:
        yield
    finally:
        model.margin = before


def _low(model: CollisionModel, config: GuardConfig) -> float:
    """The margin of the vertical phases and of a start the arm may leave: the model's margin
    or ``config.vertical_margin``, whichever is smaller."""
    return min(model.margin, config.vertical_margin)


def _escapes(model: CollisionModel, q0: np.ndarray, fingers: float, ignore, config) -> bool:
    """Whether the arm at ``q0`` stands within the model's margin of something but clear of it
    at ``config.vertical_margin`` (a free-space phase may move off, `GuardConfig.escape`)."""
    if config.escape <= 0 or model.valid(q0, fingers, ignore):
        return False
    with _margin(model, _low(model, config)):
        return model.valid(q0, fingers, ignore)


def _check_leaving(model: CollisionModel, path: np.ndarray, fingers, ignore, config, near: bool):
    """``path`` (K, J) checked at the model's margin; with ``near`` (the arm stands within it
    at the start, `_escapes`) its samples within ``config.escape`` of the start, up to the first
    beyond, are checked at ``config.vertical_margin`` and the rest at the margin."""
    if not near:
        return _check_path(model, path, fingers, ignore, config.max_step)
    beyond = np.abs(path - path[0]).max(axis=1) > config.escape  # (K,)
    k = int(np.argmax(beyond)) if beyond.any() else len(path) - 1
    with _margin(model, _low(model, config)):
        found = _check_path(model, path[: k + 1], fingers, ignore, config.max_step)
    if not found.ok or k == len(path) - 1:
        return found
    return _check_path(model, path[k:], fingers, ignore, config.max_step)


def _guard_phase(
    phase: Phase, model: CollisionModel, fingers: float, ignore, config: GuardConfig, seed: int
):
    """One arm phase against the model's current boxes and held block: (the phase to run, or a
    rerouted one, or None), the evidence of a collision, check and planning seconds."""
    start = time.perf_counter()
    free = phase.name in FREE_SPACE
    path = thin(phase.trajectory.positions, config.max_step)
    # a free-space phase may leave where the arm stands within the margin (`GuardConfig.escape`)
    near = free and _escapes(model, path[0], fingers, ignore, config)
    # the vertical phases move straight up or down beside blocks the move touches
    with _margin(model, model.margin if free else _low(model, config)):
        found = _check_leaving(model, path, fingers, ignore, config, near)
    t_check = time.perf_counter() - start
    if found.ok:
        return phase, {}, t_check, 0.0
    evidence = {
        "phase": phase.name,
        "part": found.contact.part,
        "other": found.contact.other,
        "distance_m": round(found.contact.distance, 4),
        "q": [round(v, 3) for v in found.q],
    }
    if not free or not config.plan:
        return None, evidence, t_check, 0.0
    from motion.rrt import PathPlannerConfig, path_trajectory, plan_path

    # checked every ~0.02 rad (resolution x the joint box's 13 rad diagonal), as is the rest
    rrt = replace(config.rrt or PathPlannerConfig(resolution=0.0015, simplify_time=5.0), seed=seed)
    q = phase.trajectory.positions  # (S, J)

    low = _low(model, config)  # about the start, when it may leave

    def valid(x: np.ndarray) -> bool:
        if model.valid(x, fingers, ignore):
            return True
        if not near or np.abs(x - q[0]).max() > config.escape:
            return False
        with _margin(model, low):
            return model.valid(x, fingers, ignore)

    batch = None
    if getattr(model, "valid_batch", None) is not None:

        def batch(x: np.ndarray) -> np.ndarray:
            ok = model.valid_batch(x, fingers, ignore)
            if near:
                again = ~ok & (np.abs(x - q[0]).max(axis=1) <= config.escape)
                if again.any():
                    with _margin(model, low):
                        ok[again] = model.valid_batch(x[again], fingers, ignore)
            return ok

    # plan with a wider berth: the planner checks only every ~0.02 rad
    with _margin(model, model.margin + config.plan_pad):
        found_path = plan_path(q[0], q[-1], valid, config=rrt, valid_batch=batch)
    if not found_path.ok:
        evidence |= {"planner": found_path.failure, "checks": found_path.checks}
        return None, evidence, t_check, found_path.time_s
    trajectory = path_trajectory(found_path.path, config.dt, limits=config.speed)
    detour = thin(trajectory.positions, config.max_step)
    again = _check_leaving(model, detour, fingers, ignore, config, near)
    if not again.ok:  # the planner checks at its own resolution; this is the final word
        evidence |= {"planner": "detour_collides", "detour_other": again.contact.other}
        return None, evidence, t_check, found_path.time_s
    return (
        Phase(phase.name, trajectory, phase.gripper, config.speed),
        {},
        t_check,
        found_path.time_s,
    )


def at_rest(phase: Phase, step: float = 0.002) -> Phase:
    """``phase`` re-timed rest to rest along the same path (its samples ``step`` rad apart as
    knots), with the limits it was timed with (`motion.trajectory.APPROACH` when unknown); the
    phase itself when it already starts and ends at rest."""
    trajectory = phase.trajectory
    if not np.abs(trajectory.velocities[[0, -1]]).any():
        return phase
    limits = phase.limits or APPROACH
    knots = thin(trajectory.positions, step)  # (K, J)
    if len(knots) < 2:
        return phase
    dt = float(trajectory.times[1] - trajectory.times[0])
    return replace(phase, trajectory=polyline_segment(knots, dt, limits=limits))


def guard_pick_place(
    phases: Sequence[Phase],
    model: CollisionModel,
    world: PickPlaceWorld,
    config: GuardConfig = GuardConfig(),
    seed: int = 0,
) -> Guarded:
    """Check every arm phase of a pick-and-place (see the module docstring); ``seed`` seeds
    the motion planner, so the same scene and seed give the same detour."""
    out, rerouted, t_check, t_plan, runs = [], [], 0.0, 0.0, 0
    for phase in phases:
        if phase.name in ("close", "open"):  # standstills
            out.append(phase)
            continue
        boxes, held, fingers, ignore = _situation(phase.name, world, config.open_width)
        model.set_boxes(boxes)
        hold_picked(model, world if held else None)
        run, evidence, checked, planned = _guard_phase(phase, model, fingers, ignore, config, seed)
        t_check, t_plan = t_check + checked, t_plan + planned
        runs += (run is not None and run is not phase) or "planner" in evidence
        if run is None:
            return Guarded(
                ok=False,
                phases=(),
                failure="collision",
                evidence=evidence,
                rerouted=tuple(rerouted),
                check_time_s=t_check,
                plan_time_s=t_plan,
                planner_runs=runs,
            )
        out.append(run)
        if run is not phase:
            rerouted.append(phase.name)
    for k, phase in enumerate(out):  # a detour stops at its ends: so must its neighbours
        if phase.name in rerouted:
            for n in (k - 1, k + 1):
                if 0 <= n < len(out) and out[n].name not in ("close", "open"):
                    out[n] = at_rest(out[n])
    return Guarded(
        ok=True,
        phases=tuple(out),
        failure=None,
        evidence={},
        rerouted=tuple(rerouted),
        check_time_s=t_check,
        plan_time_s=t_plan,
        planner_runs=runs,
    )


def guard_free_move(
    trajectory,
    model: CollisionModel,
    boxes: Sequence[Box],
    config: GuardConfig = GuardConfig(),
    seed: int = 0,
):
    """An empty-handed free-space move (fingers open, e.g. the trip home to look again)
    checked against ``boxes`` and rerouted by the motion planner when blocked: the
    `JointTrajectory` to run, or None when no collision-free way was found."""
    model.set_boxes(boxes)
    model.hold(None)
    phase = Phase("approach", trajectory, "open")
    run, _, _, _ = _guard_phase(phase, model, config.open_width, (), config, seed)
    return None if run is None else run.trajectory
