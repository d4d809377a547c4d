"""One move of an upright object as eight phases: approach, descend, close, lift, transit, lower,
open, retreat.

Six TCP waypoints (pre-grasp, grasp, lift, pre-place, place, retreat) are solved in one batched
IK call. Consecutive solutions must be close in joint space (a wrist flip between two
waypoints a few centimetres apart is a bug), so a waypoint whose solution jumps more than
``max_joint_jump`` from the previous one is re-solved seeded with that previous solution, and the
closer valid answer is kept. The vertical phases (descend, lift, lower, retreat) follow the
Cartesian line through IK knots (`motion.trajectory.polyline_segment`); the free-space phases
(approach, transit) are straight joint segments, or, with ``PickPlaceConfig.blend``,
`motion.trajectory.transition` curves that pass into and out of the vertical phases at a
fraction of their speed instead of stopping at the corners (pre-grasp, lift, pre-place). The
arm is at rest where the gripper acts (close, open) and at both ends of the move. The gripper
phases are standstills. An unreachable waypoint is a returned failure (``ik_infeasible``) with
evidence, never an exception; so is a vertical phase that no IK branch keeps on its line
(evidence ``straight: False``: near the arm's base the elbow's limit can part the branches of
the two ends, and a joint segment between them bows centimetres sideways).

Two ways to say how the hand holds the object (`PickPlaceRequest`):

- the default (``grasp`` and ``half`` None): today's top-down grasp of a cube of edge
  ``PickPlaceConfig.block_size`` at its centre, the hand yaw the cube's yaw plus the quarter
  turn nearest the hand (`motion.ik.grasp_yaw`; ``turn`` takes the other pair of faces);
- a `motion.grasps.Grasp` and the object's half extents: the TCP at the grasp is
  ``world_tcp(grasp, pick, pick_yaw)`` and at the place ``world_tcp(grasp, place, place_yaw)``
  (raised by ``place_gap``). The pre-grasp backs off from the grasp along the approach axis
  until the TCP is ``approach_height`` outside the object (`motion.grasps.back_out`), the
  retreat ``approach_height`` from the release point; a vertical approach also rises to hover
  above every stack and stays under a ceiling there, as the default does; an inclined one backs
  off less where a ceiling is lower. Lift and lower are vertical and carry the object's bottom
  ``lift_clearance + hz`` above the highest top (hz: its half height), as the default carries
  the cube. ``half`` alone (no grasp) takes the top-down grasp (`motion.grasps.grasps`) at the
  default's hand yaw, or, where the object is too wide across those faces, the other pair.
  With the top grasp ``top{k}`` of a cube whose yaw the default would choose, both ways give
  the same waypoints.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from motion.errors import MotionError
from motion.grasps import Grasp, back_out, grasps, world_tcp
from motion.ik import IKSolver, grasp_yaw, pose_yaw, top_down_pose
from motion.pick_place.lines import LineEnd, vertical_path
from motion.trajectory import (
    APPROACH,
    TRANSIT,
    JointTrajectory,
    SpeedLimits,
    direction_at,
    pass_speed,
    polyline_segment,
    straight_segment,
    transition,
)

WAYPOINTS = ("pre_grasp", "grasp", "lift", "pre_place", "place", "retreat")
PHASES = ("approach", "descend", "close", "lift", "transit", "lower", "open", "retreat")


@dataclass(frozen=True)
class PickPlaceConfig:
    """Geometry, timing and speeds of a pick-and-place (motion-research notes, sections 3-4)."""

    approach_height: float = 0.10  # m, pre-grasp above the block top, retreat rise (at least:
    # both also hover lift_clearance above the highest stack top)
    lift_clearance: float = 0.06  # m, the held block's bottom clears the highest top by >= this
    place_gap: float = 0.003  # m, release height of the block above its support
    close_time: float = 0.25  # s, standstill while the gripper closes
    open_time: float = 0.15  # s, standstill while the gripper opens
    # fractions of the datasheet limits (motion.trajectory: TRANSIT 80%, APPROACH 50%)
    transit: SpeedLimits = TRANSIT  # free space: approach, transit
    approach: SpeedLimits = APPROACH  # near contact: descend, lift, lower, retreat
    blend: bool = True  # pass through pre-grasp, lift and pre-place without stopping
    pass_share: float = 0.6  # the speed there, as a share of what the vertical phase allows
    dt: float = 0.002  # s, trajectory sampling period
    block_size: float = 0.05  # m, cube edge
    max_joint_jump: float = 0.5  # rad, per-joint change between waypoints that triggers a re-solve
    vertical_step: float = 0.02  # m, IK knot spacing on the vertical moves (straight in space)
    min_approach: float = 0.02  # m, least descent onto a block under a ceiling (no_clearance)
    straight_tolerance: float = 0.005  # m, how far a vertical phase's TCP may stray off its line


@dataclass(frozen=True)
class PickPlaceRequest:
    """Move the object centred at ``pick`` so that its centre ends at ``place`` (base frame, m),
    held as ``grasp`` says (see the module docstring)."""

    pick: tuple[float, float, float]  # object centre now
    pick_yaw: float  # rad, object yaw now
    place: tuple[float, float, float]  # object centre after placing (on top of the target)
    place_yaw: float  # rad, object yaw after placing (the default cube: modulo pi/2)
    clear_z: float  # m, height of the highest stack top that transit must clear
    pick_ceiling: float = math.inf  # m, highest TCP height over the pick point (a shelf above)
    place_ceiling: float = math.inf  # m, ... over the place point
    turn: bool = False  # grasp the other pair of faces (the hand turned a quarter turn)
    grasp: Grasp | None = None  # how the hand holds it (None: top-down, see the module doc)
    half: tuple[float, float, float] | None = None  # m, half extents (None: a block_size cube)


@dataclass(frozen=True)
class Phase:
    """One segment of a move: ``name`` in PHASES, gripper command "open" or "closed" held;
    ``limits``: the speed limits it was timed with (None: a standstill, or unknown)."""

    name: str
    trajectory: JointTrajectory
    gripper: str
    limits: SpeedLimits | None = None


@dataclass(frozen=True)
class MotionResult:
    """Phases in execution order (empty unless ``ok``); ``failure`` is "ik_infeasible" (a
    waypoint, or the straight line into it, out of the arm's reach), "no_clearance" (a ceiling
    leaves the hand no room to come down) or None."""

    ok: bool
    phases: tuple[Phase, ...]
    failure: str | None
    evidence: dict = field(default_factory=dict)
    ik_time_s: float = 0.0  # IK for all waypoints and knots, plus the ruckig timing
    grasp: Grasp | None = None  # the grasp planned with (None: the default top-down cube)


def _xyz(value, name: str) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise MotionError(f"request.{name} = {value!r}; expected three finite floats (x, y, z)")
    return a


def waypoint_targets(
    request: PickPlaceRequest, hand_yaw: float, config: PickPlaceConfig = PickPlaceConfig()
) -> np.ndarray:
    """The six TCP targets (6, 4, 4), in WAYPOINTS order, for a hand now at ``hand_yaw`` (rad;
    it picks the default grasp's yaw, see the module docstring)."""
    grasp, half = request_grasp(request, hand_yaw, config)
    if grasp is None:
        return _cube_targets(request, hand_yaw, config)
    return _grasp_targets(request, grasp, half, config)


def request_grasp(
    request: PickPlaceRequest, hand_yaw: float, config: PickPlaceConfig = PickPlaceConfig()
) -> tuple[Grasp | None, tuple[float, float, float]]:
    """The grasp the move uses (None: the default top-down cube) and the object's half
    extents (3,) m; checks the request's numbers (a malformed one raises MotionError)."""
    _xyz(request.pick, "pick")
    _xyz(request.place, "place")
    for name in ("pick_yaw", "place_yaw", "clear_z"):
        if not math.isfinite(getattr(request, name)):
            raise MotionError(f"request.{name} = {getattr(request, name)}; expected a finite float")
    if request.half is None:
        half = (config.block_size / 2,) * 3
    else:
        half = tuple(float(v) for v in _xyz(request.half, "half"))
        if min(half) <= 0:
            raise MotionError(f"request.half = {request.half!r}; expected half extents > 0 m")
    if request.grasp is not None:
        if request.turn:
            raise MotionError(
                "request.turn applies to the default grasp; with request.grasp set, "
                "choose the turned grasp instead"
            )
        return request.grasp, half
    if request.half is None:
        return None, half
    # the default hand yaw (a quarter-turn choice), taken by the top grasp with that yaw
    yaw = grasp_yaw(request.pick_yaw, hand_yaw) + (math.pi / 2 if request.turn else 0.0)
    k = round((yaw - request.pick_yaw) / (math.pi / 2)) % 4
    tops = {g.name: g for g in grasps("cuboid", half, ("top",))}
    for name in (f"top{k}", f"top{(k + 1) % 4}", f"top{(k + 3) % 4}"):
        if name in tops:
            return tops[name], half
    raise MotionError(
        f"no top-down grasp fits an object of half extents {half} m; set request.grasp"
    )


def _backed(pose: np.ndarray, distance: float, z_hover: float, ceiling: float) -> np.ndarray:
    """``pose`` (4, 4) with the TCP backed off ``distance`` m along its approach (tool z). A
    vertical approach then rises at least to ``z_hover`` and at most to ``ceiling``; an
    inclined one backs off less where it would pass ``ceiling``."""
    a = pose[:3, 2]  # (3,) the approach in the base frame
    out = pose.copy()
    out[:3, 3] = pose[:3, 3] - distance * a
    if a[2] < -1 + 1e-9:  # straight down: as the default path
        out[2, 3] = min(max(out[2, 3], z_hover), ceiling)
    elif a[2] < 0 and out[2, 3] > ceiling:
        out[:3, 3] = pose[:3, 3] - (ceiling - pose[2, 3]) / -a[2] * a
    return out


def _grasp_targets(
    request: PickPlaceRequest, grasp: Grasp, half, config: PickPlaceConfig
) -> np.ndarray:
    """The six TCP targets (6, 4, 4) of a move held by ``grasp`` (see the module docstring)."""
    pick, place = _xyz(request.pick, "pick"), _xyz(request.place, "place")
    hz = half[2]
    highest = max(request.clear_z, pick[2] + hz, place[2] - hz)  # stack tops to clear
    above = grasp.matrix[2, 3]  # m, the TCP over the object's centre (any yaw)
    z_transit = highest + config.lift_clearance + 2 * hz + above
    z_hover = highest + config.lift_clearance  # the empty hand hovers above every stack
    take = world_tcp(grasp, pick, request.pick_yaw)  # (4, 4)
    put = world_tcp(grasp, place, request.place_yaw)
    put[2, 3] += config.place_gap
    lift, pre_place = take.copy(), put.copy()
    lift[2, 3] = min(z_transit, request.pick_ceiling)
    pre_place[2, 3] = min(z_transit, request.place_ceiling)
    out = back_out(grasp, half) + config.approach_height
    pre_grasp = _backed(take, out, z_hover, request.pick_ceiling)
    retreat = _backed(put, config.approach_height, z_hover, request.place_ceiling)
    return np.stack([pre_grasp, take, lift, pre_place, put, retreat])  # (6, 4, 4)


def _cube_targets(
    request: PickPlaceRequest, hand_yaw: float, config: PickPlaceConfig = PickPlaceConfig()
) -> np.ndarray:
    """The default path's six top-down TCP targets (6, 4, 4) (the cube of edge block_size)."""
    pick, place = _xyz(request.pick, "pick"), _xyz(request.place, "place")
    half = config.block_size / 2
    highest = max(request.clear_z, pick[2] + half, place[2] - half)  # stack tops to clear
    z_transit = highest + config.lift_clearance + config.block_size  # TCP = held block centre
    yaw_grasp = grasp_yaw(request.pick_yaw, hand_yaw) + (math.pi / 2 if request.turn else 0.0)
    yaw_place = grasp_yaw(request.place_yaw, yaw_grasp)
    up = np.array([0.0, 0.0, 1.0])
    place_tcp = place + config.place_gap * up
    # the empty hand also hovers above every stack, so approach and retreat sweep nothing
    z_hover = highest + config.lift_clearance
    pre_grasp = pick + (half + config.approach_height) * up
    retreat = place_tcp + config.approach_height * up
    pre_grasp[2], retreat[2] = max(pre_grasp[2], z_hover), max(retreat[2], z_hover)
    # under a shelf the hand stays below its ceiling there; transit then leaves sideways
    top_pick, top_place = request.pick_ceiling, request.place_ceiling
    pre_grasp[2], retreat[2] = min(pre_grasp[2], top_pick), min(retreat[2], top_place)
    xyz_yaw = (
        (pre_grasp, yaw_grasp),
        (pick, yaw_grasp),
        ((pick[0], pick[1], min(z_transit, top_pick)), yaw_grasp),
        ((place[0], place[1], min(z_transit, top_place)), yaw_place),
        (place_tcp, yaw_place),
        (retreat, yaw_place),
    )
    return np.stack([top_down_pose(xyz, yaw) for xyz, yaw in xyz_yaw])  # (6, 4, 4)


def _solve_waypoints(
    solver: IKSolver,
    targets: np.ndarray,
    q_now: np.ndarray,
    max_jump: float,
    seeds: tuple[np.ndarray, np.ndarray] | None = None,
):
    """Batched IK, then re-solve from the previous waypoint where the joint path jumps (one
    Gauss-Newton run from it) or fails (every seed again). ``seeds``: the configurations the
    pick's waypoints (pre-grasp, grasp, lift) and the place's (pre-place, place, retreat) are
    solved from instead of ``q_now``, each side on its own branch (the transit between them
    is free space)."""
    if seeds is None:
        first = solver.solve(targets, q_now)
        starts = {0: q_now}
        ok, q = first.ok.copy(), first.q.copy()  # (W,), (W, J)
        pos_err, rot_err = first.pos_err.copy(), first.rot_err.copy()
    else:
        sides = [solver.solve(targets[:3], seeds[0]), solver.solve(targets[3:], seeds[1])]
        starts = {0: np.asarray(seeds[0], float), 3: np.asarray(seeds[1], float)}
        ok, q, pos_err, rot_err = (
            np.concatenate([getattr(r, a) for r in sides])
            for a in ("ok", "q", "pos_err", "rot_err")
        )
    resolved = []
    for k in range(len(targets)):
        prev = starts[k] if k in starts else q[k - 1]
        jump = float(np.abs(q[k] - prev).max())
        if (ok[k] and jump <= max_jump) or (k not in starts and not ok[k - 1]):
            continue  # fine as it is, or no valid previous solution to seed from
        if ok[k]:  # solved, but on another branch: Gauss-Newton from the previous waypoint
            again = solver.follow(targets[k : k + 1], prev, solver.config.max_iterations)
        else:  # unsolved: every seed again, the previous waypoint's solution first
            again = solver.solve(targets[k : k + 1], prev)
        better = float(np.abs(again.q[0] - prev).max()) < jump
        if again.ok[0] and (not ok[k] or better):
            ok[k], q[k] = True, again.q[0]
            pos_err[k], rot_err[k] = again.pos_err[0], again.rot_err[0]
            resolved.append(WAYPOINTS[k])
    return ok, q, pos_err, rot_err, resolved


class _NotStraight(Exception):
    """No IK path keeps the TCP on the straight line into ``waypoint`` (`vertical_path`)."""

    def __init__(self, waypoint: str):
        super().__init__(waypoint)
        self.waypoint = waypoint


def _dip(solver: IKSolver, positions: np.ndarray) -> float:
    """How far (m) the TCP of a joint path ``positions`` (S, J) passes below the lower of its
    two ends (0 when it never does), sampled every fifth configuration."""
    z = solver.tcp_positions(np.vstack([positions[::5], positions[-1:]]))[:, 2]  # (S',)
    return max(0.0, float(min(z[0], z[-1]) - z.min()))


def _kept_up(solver: IKSolver, q0, q1, config: PickPlaceConfig) -> JointTrajectory:
    """The straight joint segment q0 -> q1 at transit speed, or, where the TCP would sag
    more than 1 mm below its lower end on the way (the hover and transit heights keep the hand
    and the held object above every stack), two segments through the sagging configuration's
    IK solution raised by the sag (rest at the via point)."""
    spec, dt = solver.spec, config.dt
    line = straight_segment(q0, q1, dt, spec, config.transit)
    sag = _dip(solver, line.positions)
    if sag <= 1e-3:
        return line
    z = solver.tcp_positions(line.positions)[:, 2]  # (S,)
    low = line.positions[int(np.argmin(z))]  # (J,)
    pose = solver.fk(low)[0]
    pose[2, 3] += sag
    via = solver.follow(pose[None], low, iterations=20)
    if not via.ok[0]:
        return line
    first = straight_segment(q0, via.q[0], dt, spec, config.transit)
    second = straight_segment(via.q[0], q1, dt, spec, config.transit)
    both = np.vstack([first.positions, second.positions[1:]])
    if _dip(solver, both) >= sag:
        return line
    return JointTrajectory(
        np.concatenate([first.times, first.duration + second.times[1:]]),
        both,
        np.vstack([first.velocities, second.velocities[1:]]),
        np.vstack([first.accelerations, second.accelerations[1:]]),
    )


def _phases(solver: IKSolver, w: dict, pose: dict, config: PickPlaceConfig) -> tuple[Phase, ...]:
    """The eight phases through the waypoint solutions ``w`` (name -> (J,), "now" included;
    updated where a vertical phase ends on another IK solution) and poses ``pose`` (name ->
    (4, 4)). The vertical paths come first, so the free-space phases can pass into them."""
    spec, dt = solver.spec, config.dt
    paths = {}
    # (start, end, whether the start is free): descend and lower start where a free-space
    # phase, planned after them, will end; lift and retreat start where the hand stands
    lines = (
        ("pre_grasp", "grasp", True),
        ("grasp", "lift", False),
        ("pre_place", "place", True),
        ("place", "retreat", False),
    )
    for src, dst, free_start in lines:
        path = vertical_path(
            solver,
            LineEnd(pose[src], w[src]),
            LineEnd(pose[dst], w[dst]),
            config.vertical_step,
            config.straight_tolerance,
            free_start,
        )
        if path is None:
            raise _NotStraight(dst)
        paths[dst] = path
        w[src], w[dst] = path[0], path[-1]  # the phases before and after meet this one
    share = config.pass_share if config.blend else 0.0
    # arclength speeds where descend starts, lift ends and lower starts
    down = pass_speed(paths["grasp"], share, spec, config.approach)
    up = pass_speed(paths["lift"], share, spec, config.approach)
    low = pass_speed(paths["place"], share, spec, config.approach)

    def free(src: str, dst: str, qd0, qd1):
        """The free-space phase src -> dst passing through at joint velocities qd0, qd1, and
        whether it stops at both ends instead: when ruckig finds no curve in the joint limits,
        or the curve takes the hand more than 1 mm below the lower of its two ends (the
        hover and transit heights keep the hand and the held object above every stack)."""
        if qd0.any() or qd1.any():
            try:
                curve = transition(w[src], qd0, w[dst], qd1, dt, spec, config.transit)
            except MotionError:
                curve = None
            if curve is not None and _dip(solver, curve.positions) <= 1e-3:
                return curve, False
        return _kept_up(solver, w[src], w[dst], config), True

    zero = np.zeros(solver.dof)
    approach, still = free("now", "pre_grasp", zero, down * direction_at(paths["grasp"], 0))
    down = 0.0 if still else down
    transit, still = free(
        "lift",
        "pre_place",
        up * direction_at(paths["lift"], -1),
        low * direction_at(paths["place"], 0),
    )
    up, low = (0.0, 0.0) if still else (up, low)
    grasp, place = w["grasp"], w["place"]

    def vertical(name: str, end: str, gripper: str, v0: float = 0.0, v1: float = 0.0) -> Phase:
        """The vertical phase along the path into waypoint ``end``, passing through its ends
        at arclength speeds ``v0`` and ``v1``."""
        path = polyline_segment(paths[end], dt, spec, config.approach, v0, v1)
        return Phase(name, path, gripper, config.approach)

    return (
        Phase("approach", approach, "open", config.transit),
        vertical("descend", "grasp", "open", down),
        Phase("close", JointTrajectory.hold(grasp, config.close_time, dt), "closed"),
        vertical("lift", "lift", "closed", 0.0, up),
        Phase("transit", transit, "closed", config.transit),
        vertical("lower", "place", "closed", low),
        Phase("open", JointTrajectory.hold(place, config.open_time, dt), "open"),
        vertical("retreat", "retreat", "open"),
    )


def plan_pick_place(
    solver: IKSolver,
    q_now,
    request: PickPlaceRequest,
    config: PickPlaceConfig = PickPlaceConfig(),
    seeds: tuple | None = None,
) -> MotionResult:
    """Plan one move from the arm configuration ``q_now`` (J,); see the module docstring.
    ``seeds``: two configurations (J,) to solve the pick's and the place's waypoints from
    instead of ``q_now``: another posture of the arm at the same hand poses (a 7-joint arm
    reaches a pose along a one-parameter family; the nearest one to ``q_now`` may put the
    forearm or wrist into a neighbour where another does not). The approach still starts at
    ``q_now``, and the transit joins the two sides."""
    q_now = np.asarray(q_now, dtype=np.float64)
    if q_now.shape != (solver.dof,) or not np.isfinite(q_now).all():
        raise MotionError(f"q_now has shape {q_now.shape}; expected finite ({solver.dof},)")
    hand_yaw = pose_yaw(solver.fk(q_now)[0])
    grasp, _ = request_grasp(request, hand_yaw, config)
    targets = waypoint_targets(request, hand_yaw, config)  # (6, 4, 4)
    # how far the hand backs off along its approach (tool z) at the pick and at the place
    back = (targets[0, :3, 3] - targets[1, :3, 3]) @ -targets[1, :3, 2]
    room = min(back, (targets[5, :3, 3] - targets[4, :3, 3]) @ -targets[4, :3, 2])
    if room < config.min_approach:  # a ceiling over the pick or the place is too low
        evidence = {
            "pick_ceiling": request.pick_ceiling,
            "place_ceiling": request.place_ceiling,
            "approach_m": round(float(room), 4),
        }
        return MotionResult(False, (), "no_clearance", evidence, grasp=grasp)
    start = time.perf_counter()
    if seeds is not None:
        seeds = tuple(np.asarray(x, dtype=np.float64) for x in seeds)
        if len(seeds) != 2 or any(x.shape != (solver.dof,) for x in seeds):
            raise MotionError(f"seeds must be two configurations of shape ({solver.dof},)")
    ok, q, pos_err, rot_err, resolved = _solve_waypoints(
        solver, targets, q_now, config.max_joint_jump, seeds
    )
    ik_time = time.perf_counter() - start
    if not ok.all():
        bad = [name for name, good in zip(WAYPOINTS, ok, strict=True) if not good]
        k = WAYPOINTS.index(bad[0])
        evidence = {
            "waypoint": bad[0],
            "target_xyz": tuple(float(v) for v in targets[k, :3, 3]),
            "pos_err": float(pos_err[k]),
            "rot_err": float(rot_err[k]),
            "unreachable": tuple(bad),
        }
        return MotionResult(False, (), "ik_infeasible", evidence, ik_time, grasp)

    w = {"now": q_now, **dict(zip(WAYPOINTS, q, strict=True))}  # name -> (J,)
    start = time.perf_counter()
    try:
        phases = _phases(solver, w, dict(zip(WAYPOINTS, targets, strict=True)), config)
    except _NotStraight as bent:
        k = WAYPOINTS.index(bent.waypoint)
        evidence = {
            "waypoint": bent.waypoint,
            "target_xyz": tuple(float(v) for v in targets[k, :3, 3]),
            "straight": False,
            "unreachable": (bent.waypoint,),
        }
        ik_time += time.perf_counter() - start
        return MotionResult(False, (), "ik_infeasible", evidence, ik_time, grasp)
    ik_time += time.perf_counter() - start
    final = np.stack([w[n] for n in WAYPOINTS])  # (6, J), after the vertical re-solves
    steps = np.abs(np.diff(np.vstack([q_now[None], final]), axis=0)).max(1)  # (6,) rad
    evidence = {
        "waypoints": {
            n: tuple(float(v) for v in targets[i, :3, 3]) for i, n in enumerate(WAYPOINTS)
        },
        "yaws": {"grasp": pose_yaw(targets[1]), "place": pose_yaw(targets[4])},
        "max_joint_step": {n: float(s) for n, s in zip(WAYPOINTS, steps, strict=True)},
        "resolved": tuple(resolved),
    }
    if grasp is not None:
        evidence["grasp"] = grasp.name
    return MotionResult(True, phases, None, evidence, ik_time, grasp)
