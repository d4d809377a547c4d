"""Is a move feasible for the arm? IK of every waypoint and a collision check of every phase.

`check_move(scene, move, tools)` decides one `GeoMove` in a world state: the object must be
clear and the place free and supported (else ``not_clear`` / ``unsupported``); then for the
move's grasp, or each candidate grasp of the object in turn (`grasp_order`: top-down first,
the one with the most room beside its fingers first), it plans the pick-and-place
(`motion.pick_place.plan_pick_place`) and guards it (`motion.guard.guard_pick_place`) against
the obstacles, the regions' walls and floors and the other objects as boxes, the held object
included. The first grasp that passes wins. Before the full plan, one batched IK call solves
the grasp and place poses of every candidate grasp and checks the arm there for collisions
(`quick_check`): a grasp that fails there fails the full check too, so it is skipped cheaply.
With `Tools` ``postures``, once every grasp failed, those that collided are tried again in
other postures of the arm (`tamp.geo.postures`: the IK branch as a choice).

Transit height: the hand carries the object over what stands near its way (objects and fixed
boxes within `CORRIDOR` of the straight line from pick to place), not over the highest stack
anywhere; when the guard finds that path blocked it tries again over everything (the safe
height of `tamp.loop`).

Failures (``MoveCheck.failure``, members of `tamp.outcome.Failure`, the executors' vocabulary):
``not_clear`` (something rests on the object), ``unsupported`` (the place overlaps something
or would not rest on its target), ``no_grasp`` (no candidate grasp fits the gripper),
``ik_infeasible``, ``no_clearance`` (a ceiling leaves the hand no room), ``collision``. Each
grasp tried leaves a `GraspTry` saying whether it failed on the pick side (independent of the
place) or the place side, which the search's failure memory keys on.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from motion.grasps import Grasp, object_frame
from motion.grasps import grasps as make_grasps
from motion.guard import GuardConfig, PickPlaceWorld, guard_pick_place, hold_picked
from motion.ik import IKSolver, pose_yaw
from motion.pick_place import (
    Phase,
    PickPlaceConfig,
    PickPlaceRequest,
    plan_pick_place,
    waypoint_targets,
)
from robots.panda import PANDA
from tamp.geo.places import free, placed_solid
from tamp.geo.postures import POSTURE_GRASPS, plan_postures
from tamp.geo.types import TABLE, GeoMove, moved
from tamp.obstacles import ceiling
from tamp.outcome import Failure
from tamp.world.geometry import Solid, fixed_solids, footprint_gap, of_movable
from tamp.world.relations import read_facts
from tamp.world.schema import Movable, Scene

CORRIDOR = 0.12  # m, things this near the pick-to-place line set the transit height
FINGER = 0.012  # m, a finger pad's thickness, for ordering grasps by the room beside them
STROKE = 0.08  # m, the Panda's widest opening
PICK_PHASES = ("approach", "descend")  # guard phases that do not depend on the place
PICK_WAYPOINTS = ("pre_grasp", "grasp")  # IK waypoints that do not depend on the place
# the failures a check finds (`tamp.outcome.Failure`, the executors' vocabulary)
FAILURES = (
    Failure.NOT_CLEAR,
    Failure.UNSUPPORTED,
    Failure.NO_GRASP,
    Failure.IK_INFEASIBLE,
    Failure.NO_CLEARANCE,
    Failure.COLLISION,
)


@dataclass(frozen=True)
class GraspTry:
    """One grasp tried: its name, the failure (None: it worked) and on which ``side`` it
    failed: ``"pick"`` (reaching or closing on the object, whatever the place) or ``"place"``
    (anything from the lift on)."""

    grasp: str
    failure: Failure | None
    side: str = ""
    where: str = ""  # the phase or IK waypoint that failed
    other: str = ""  # what the arm or the held object hit (a box name, "table" or a link)
    quick: bool = False  # decided by `quick_check` alone


@dataclass(frozen=True)
class MoveCheck:
    """The verdict on one move: ``ok`` with the ``grasp`` that works and its guarded phases
    (``motion``, ready to run), or the ``failure`` (one of `FAILURES`, that of the last grasp
    tried) and its ``evidence``. ``tried``: every grasp tried, in order."""

    ok: bool
    grasp: Grasp | None = None
    failure: Failure | None = None
    motion: tuple[Phase, ...] = ()
    evidence: dict = field(default_factory=dict)
    tried: tuple[GraspTry, ...] = ()
    time_s: float = 0.0


class Tools:
    """What a check needs, built once: the IK solver, the arm's collision model (a private
    PyBullet client, closed by `close` or on leaving a ``with`` block, screened by the sphere
    model for the motion planner's batches: `motion.sphere_check.Screened`), the pick-and-place and
    guard settings, the grasp families to try, and ``q`` (J,), the arm configuration moves are
    planned from (home unless told). ``guard.plan`` False: a blocked phase fails the move
    rather than being rerouted by the motion planner (the search's default: fast).
    ``postures`` > 0: a grasp that collides in the arm's nearest posture is tried again in
    others found from that many seeds (`tamp.geo.postures`), after every grasp failed in
    its nearest one; 0 (the search's default): never."""

    def __init__(
        self,
        solver: IKSolver | None = None,
        collision=None,
        q=None,
        pick_place: PickPlaceConfig = PickPlaceConfig(),
        guard: GuardConfig = GuardConfig(plan=False),
        margin: float = 0.01,
        choices: tuple[str, ...] = ("top", "side", "tilt"),
        quick: bool = True,
        postures: int = 0,
    ) -> None:
        self.solver = solver or IKSolver()
        if collision is None:
            from motion.sphere_check import Screened
            from robots.collision import PandaCollision

            # the mesh model has the final word; the motion planner's batched validity checks
            # (a blocked free-space phase rerouted at execution) screen with the spheres first
            collision = Screened(PandaCollision(margin))
        self.collision = collision
        self.q = np.asarray(PANDA.q_home if q is None else q, dtype=np.float64)
        self.pick_place, self.guard, self.choices, self.quick = pick_place, guard, choices, quick
        self.postures = postures  # seeds of other arm postures for a colliding grasp (0: none)
        self.checks = 0  # check_move calls
        self.check_time_s = 0.0

    def close(self) -> None:
        if self.collision is not None:
            self.collision.close()
            self.collision = None

    def __enter__(self) -> Tools:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def candidate_grasps(o: Movable, choices: tuple[str, ...] = ("top", "side", "tilt")):
    """The grasps of object ``o`` of the families in ``choices`` (`motion.grasps.grasps`)."""
    return make_grasps(o.kind, o.half, choices)


def grasp_order(scene: Scene, o: Movable, grasps) -> tuple[Grasp, ...]:
    """``grasps`` cheapest first: top-down, then side, then tilted; within a family, the one
    whose finger pads have the most room to the neighbouring objects first."""
    family = {"top": 0, "side": 1, "tilt": 2}
    others = [of_movable(x) for x in scene.objects if x.name != o.name]

    def room(g: Grasp) -> float:
        axis = (object_frame(o.pose.xyz, o.pose.yaw) @ g.matrix)[:3, 1]  # fingers close along y
        yaw = math.atan2(axis[1], axis[0])
        gaps = [math.inf]
        for sign in (-1.0, 1.0):
            at = np.asarray(o.pose.xyz) + sign * (g.width / 2 + FINGER) * axis
            pad = Solid("pad", False, tuple(at), (FINGER, FINGER, o.half[2]), yaw)
            gaps += [footprint_gap(pad, s) for s in others if s.top > pad.bottom]
        return min(gaps)

    def key(g: Grasp):
        return (min((v for k, v in family.items() if g.name.startswith(k)), default=3), -room(g))

    return tuple(sorted(grasps, key=key))


def support_box(scene: Scene, target: str) -> str:
    """The collision-model box (or ``"table"``) an object resting on ``target`` touches."""
    if target == TABLE or target in {o.name for o in scene.objects}:
        return "table" if target == TABLE else target
    r = scene.region(target)
    if r.floor > 0:
        return f"{r.name}:floor"
    return r.on or "table"


def boxes(scene: Scene):
    """Every object (a cylinder: its bounding box), obstacle, wall and floor as `Box`es."""
    from robots.collision import Box

    out = [Box(o.name, o.pose.xyz, o.half, o.pose.yaw) for o in scene.objects]
    out += [Box(s.name, s.centre, s.half, s.yaw) for s in fixed_solids(scene)]
    return tuple(out)


def transit_heights(scene: Scene, obj: str, pick, place) -> tuple[float, ...]:
    """The tops (m) transit must clear: over what stands within `CORRIDOR` of the pick-to-place
    line, then over everything (only when that is higher). Overhead boards are ceilings, not
    things to clear."""
    a, b = np.asarray(pick[:2]), np.asarray(place[:2])
    solids = [of_movable(x) for x in scene.objects if x.name != obj]
    solids += [s for s in fixed_solids(scene) if s.bottom < 0.05]
    near, every = 0.0, 0.0
    for s in solids:
        every = max(every, s.top)
        if _segment_distance(np.asarray(s.centre[:2]), a, b) <= CORRIDOR + max(s.half[:2]):
            near = max(near, s.top)
    return (near,) if every <= near + 1e-6 else (near, every)


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def pick_place_request(o: Movable, move: GeoMove, grasp: Grasp, clear_z: float, scene: Scene):
    """The `PickPlaceRequest` of moving ``o`` as ``move`` says, held by ``grasp``, its transit
    over ``clear_z``, under the ceilings over the pick and the place."""
    place = move.place
    common = (
        o.pose.xyz,
        o.pose.yaw,
        place.xyz,
        place.yaw,
        clear_z,
        ceiling(o.pose.xyz, scene.obstacles),
        ceiling(place.xyz, scene.obstacles),
    )
    return PickPlaceRequest(*common, grasp=grasp, half=o.half)


def pick_place_world(scene: Scene, o: Movable, move: GeoMove, grasp: Grasp, support: str):
    """The guard's `motion.guard.PickPlaceWorld` of moving ``o`` as ``move`` says, held by
    ``grasp``, from ``support`` (a `support_box` name)."""
    from robots.collision import Box

    placed = Box(o.name, move.place.xyz, o.half, move.place.yaw)
    onto = support_box(scene, move.place.target)
    return PickPlaceWorld(
        boxes(scene), o.name, support, onto, placed, grasp.width, half=o.half, grasp=grasp
    )


def quick_check(scene: Scene, move: GeoMove, tools: Tools, grasps, q_now=None) -> dict:
    """The cheap half of a check, for every grasp in ``grasps`` at once: one batched IK call
    for the grasp and place TCP poses and a collision test of the arm at each (the open hand
    around the object at the grasp, the held object at the place). Returns grasp name ->
    None (passes) or (failure, side, evidence). A grasp this rules out fails `check_move` too
    (the full plan solves these poses and checks these configurations among others)."""
    o = scene.object(move.obj)
    q = tools.q if q_now is None else np.asarray(q_now, dtype=np.float64)
    hand = pose_yaw(tools.solver.fk(q)[0])
    heights = transit_heights(scene, o.name, o.pose.xyz, move.place.xyz)
    targets = []
    for g in grasps:
        wp = waypoint_targets(
            pick_place_request(o, move, g, heights[0], scene), hand, tools.pick_place
        )
        targets += [wp[1], wp[4]]  # grasp, place
    found = tools.solver.solve(np.stack(targets), q)  # (2G,)
    support = support_box(scene, dict(read_facts(scene).supports).get(o.name, TABLE))
    model = tools.collision
    out = {}
    before = model.margin
    try:
        model.margin = min(before, tools.guard.vertical_margin)  # as the guard's vertical phases
        for k, g in enumerate(grasps):
            at_grasp, at_place = 2 * k, 2 * k + 1
            if not found.ok[at_grasp]:
                out[g.name] = (Failure.IK_INFEASIBLE, "pick", {"waypoint": "grasp"})
                continue
            if not found.ok[at_place]:
                out[g.name] = (Failure.IK_INFEASIBLE, "place", {"waypoint": "place"})
                continue
            world = pick_place_world(scene, o, move, g, support)
            model.set_boxes(world.boxes)
            model.hold(None)
            ignore = (("hand", o.name),)
            hits = model.contacts(found.q[at_grasp], tools.guard.open_width, ignore)
            if hits:
                out[g.name] = (Failure.COLLISION, "pick", _contact("descend", hits[0]))
                continue
            model.set_boxes(tuple(b for b in world.boxes if b.name != o.name))
            hold_picked(model, world)
            grip = g.width / 2
            hits = model.contacts(found.q[at_place], grip, (("held", world.placed_on),))
            place = (Failure.COLLISION, "place", _contact("lower", hits[0])) if hits else None
            out[g.name] = place
    finally:
        model.margin = before
        model.hold(None)
    return out


def _contact(phase: str, hit) -> dict:
    return {
        "phase": phase,
        "part": hit.part,
        "other": hit.other,
        "distance_m": round(hit.distance, 4),
    }


def check_move(
    scene: Scene,
    move: GeoMove,
    tools: Tools,
    grasps=None,
    q_now=None,
    seed: int = 0,
    full: bool = True,
    quick: bool | None = None,
) -> MoveCheck:
    """Decide ``move`` in ``scene`` (see the module docstring). ``grasps``: the candidates to
    try (default: ``move.grasp`` when set, else `candidate_grasps` in `grasp_order`);
    ``q_now`` (J,): where the arm starts (default ``tools.q``); ``seed`` seeds the motion
    planner when ``tools.guard.plan`` reroutes blocked phases. ``full`` False: the verdict of
    `quick_check` alone (ok with the first grasp it passes, no phases), the cheap test a search
    expands with before the full check has the final word. ``quick``: whether the full check
    runs `quick_check` first (None: ``tools.quick``); for one grasp it only repeats what the
    full plan decides anyway."""
    t0 = time.perf_counter()
    tools.checks += 1

    def verdict(**kw) -> MoveCheck:
        elapsed = time.perf_counter() - t0
        tools.check_time_s += elapsed
        return MoveCheck(time_s=elapsed, **kw)

    o = scene.object(move.obj)
    facts = read_facts(scene)
    if ("clear", o.name) not in facts.atoms:
        above = sorted(a[1] for a in facts.atoms if a[0] == "on" and a[2] == o.name)
        return verdict(ok=False, failure=Failure.NOT_CLEAR, evidence={"under": above})
    if not _supported(scene, move):
        solid = placed_solid(o, move.place)
        where = [round(v, 4) for v in solid.centre]
        return verdict(
            ok=False, failure=Failure.UNSUPPORTED, evidence={"place": move.place.name, "at": where}
        )
    if grasps is None:
        grasps = (move.grasp,) if move.grasp is not None else candidate_grasps(o, tools.choices)
        grasps = grasp_order(scene, o, grasps)
    grasps = tuple(g for g in grasps if g.width <= STROKE + 1e-9)  # a move's own grasp too
    if not grasps:
        evidence = {"object": o.name, "kind": o.kind}
        return verdict(ok=False, failure=Failure.NO_GRASP, evidence=evidence)
    q = tools.q if q_now is None else np.asarray(q_now, dtype=np.float64)
    support = support_box(scene, dict(facts.supports).get(o.name, TABLE))
    quick = tools.quick if quick is None else quick
    quick = quick_check(scene, move, tools, grasps, q) if quick or not full else {}
    tried, last = [], (Failure.COLLISION, {})
    heights = transit_heights(scene, o.name, o.pose.xyz, move.place.xyz)
    attempt = _Move(scene, o, move, support, heights)
    for g in grasps:
        early = quick.get(g.name)
        if early is not None:
            tried.append(_failed(g.name, *early, quick=True))
            last = (early[0], {"grasp": g.name, **early[2]})
            continue
        if not full:
            tried.append(GraspTry(g.name, None, quick=True))
            return verdict(ok=True, grasp=g, tried=tuple(tried), evidence={"quick": True})
        result = _plan_grasp(attempt, g, tools, q, seed)
        if isinstance(result, tuple):  # the phases that work
            tried.append(GraspTry(g.name, None))
            return verdict(ok=True, grasp=g, motion=result, tried=tuple(tried))
        tried.append(_failed(g.name, result["failure"], result["side"], result["evidence"]))
        last = (result["failure"], {"grasp": g.name, **result["evidence"]})
    if full and tools.postures > 0:  # the colliding grasps again, in other postures
        collided = [t.grasp for t in tried if t.failure is Failure.COLLISION]
        found = _in_postures(attempt, [g for g in grasps if g.name in collided], tools, q, seed)
        if found is not None:
            g, phases = found
            tried.append(GraspTry(g.name, None, where="posture"))
            return verdict(
                ok=True, grasp=g, motion=phases, tried=tuple(tried), evidence={"posture": True}
            )
    return verdict(ok=False, failure=last[0], evidence=last[1], tried=tuple(tried))


@dataclass(frozen=True)
class _Move:
    """The move `check_move` tries grasps of: ``move`` of object ``o`` in ``scene``, from the
    ``support`` box it stands on, its transit at each of ``heights`` (m) in turn."""

    scene: Scene
    o: Movable
    move: GeoMove
    support: object
    heights: Sequence[float]


def _plan_grasp(attempt: _Move, g, tools, q, seed):
    """The guarded phases of the move with grasp ``g`` (a tuple), or a dict with the failure,
    its side and evidence; the transit goes over the near things, then over everything."""
    failure = None
    for clear_z in attempt.heights:
        request = pick_place_request(attempt.o, attempt.move, g, clear_z, attempt.scene)
        planned = plan_pick_place(tools.solver, q, request, tools.pick_place)
        if not planned.ok:
            bad = planned.evidence.get("waypoint", "")
            side = "pick" if bad in PICK_WAYPOINTS else "place"
            why = Failure(planned.failure)  # the motion layer's name of it
            failure = {"failure": why, "side": side, "evidence": planned.evidence}
            continue
        world = pick_place_world(attempt.scene, attempt.o, attempt.move, g, attempt.support)
        guarded = guard_pick_place(planned.phases, tools.collision, world, tools.guard, seed)
        if guarded.ok:
            return guarded.phases
        side = "pick" if guarded.evidence.get("phase") in PICK_PHASES else "place"
        failure = {"failure": Failure.COLLISION, "side": side, "evidence": guarded.evidence}
        if side == "pick":
            break  # the transit height changes nothing before the lift
    return failure


def _failed(grasp: str, failure: Failure, side: str, evidence: dict, quick=False) -> GraspTry:
    """The record of grasp ``grasp`` failing on ``side`` (pick or place), where its
    ``evidence`` says (a phase or a waypoint) and against what."""
    where = evidence.get("phase", evidence.get("waypoint", ""))
    return GraspTry(grasp, failure, side, where, evidence.get("other", ""), quick=quick)


def _in_postures(attempt: _Move, collided, tools, q, seed):
    """The first of the ``collided`` grasps (at most `POSTURE_GRASPS`) whose move works in
    another arm posture (`plan_postures`), with its phases; None when none does."""
    scene, o, move = attempt.scene, attempt.o, attempt.move
    for g in collided[:POSTURE_GRASPS]:
        world = pick_place_world(scene, o, move, g, attempt.support)
        requests = [pick_place_request(o, move, g, z, scene) for z in attempt.heights]
        phases = plan_postures(world, requests, tools, q, seed)
        if phases is not None:
            return g, phases
    return None


def _supported(scene: Scene, move: GeoMove) -> bool:
    """The place overlaps nothing and the object would rest on its target there."""
    if not free(scene, move.obj, move.place):
        return False
    after = moved(scene, move.obj, move.place.pose)
    return dict(read_facts(after).supports).get(move.obj) == move.place.target
