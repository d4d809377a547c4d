"""Jerk-limited joint trajectories: exactly straight segments timed by ruckig, and free-space
transitions between moving states.

A segment ``q0 -> q1`` is parameterised by its arclength s in joint space, ``q(t) = q0 + s(t) u``
with ``u = (q1 - q0) / L``, and s is timed by an offline 1-DoF ruckig problem ``0 -> L`` with the
limits ``min_i(lim_i / |u_i|)``. Every joint then respects its own velocity, acceleration and jerk
limit and the path stays exactly on the line (a 7-DoF ruckig with phase synchronisation falls back
to time synchronisation for the Panda's unequal limits and leaves the line by about 1e-2 rad).
Ruckig's intermediate waypoints are never used: the Community build computes them on a remote
server. Everything here runs locally.

A straight segment may start or end moving along its line (``v_start``, ``v_end``: arclength
speeds), so that a free-space `transition` (a 7-DoF ruckig problem between two moving states, which
leaves the straight line: free space only) can pass into it without stopping at the corner.

Speed limits (`SpeedLimits`) are fractions of the Franka Panda datasheet limits in
`robots.panda.PandaSpec` (velocity 2.175 rad/s for joints 1-4 and 2.61 for 5-7, the URDF's
``<limit velocity>``; acceleration 15, 7.5, 10, 12.5, 15, 20, 20 rad/s^2; jerk 7500, 3750, 5000,
6250, 7500, 10000, 10000 rad/s^3). `TRANSIT` (the free-space phases) uses 80% of the velocity and
acceleration limits: a 20% reserve for tracking the trajectory with the simulators' position
controllers; `APPROACH` (the phases near contact: the open hand around a block, a block lifted
off or lowered onto a stack) uses 50%; both use 5% of the jerk limit, which still reaches the
acceleration limit within 32 ms (joint 2) and keeps every ramp smooth at the 2 ms control period.
MoveIt's ``panda_moveit_config`` uses about 25% of the accelerations on a real arm, whose
tracking is worse than a simulator's; the friction grasp holds at these values in both
simulators (`tests/tamp/loop`).

`thin` takes a densely sampled joint path back to knots about a step apart, so that a timed
phase can be checked (`motion.guard`) or re-timed along the same path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, Result, Ruckig, Trajectory

from motion.errors import MotionError
from robots.panda import PANDA, PandaSpec


@dataclass(frozen=True)
class SpeedLimits:
    """Scale factors in (0, 1] on the datasheet velocity, acceleration and jerk limits."""

    velocity: float = 0.5
    acceleration: float = 0.3
    jerk: float = 0.1

    def __post_init__(self):
        for name in ("velocity", "acceleration", "jerk"):
            value = getattr(self, name)
            if not 0.0 < value <= 1.0:
                raise MotionError(f"SpeedLimits.{name} = {value}; expected a factor in (0, 1]")

    def scaled(self, spec: PandaSpec = PANDA) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per-joint (J,) velocity, acceleration and jerk limits of ``spec`` times the factors."""
        return (
            self.velocity * np.array(spec.v_max),
            self.acceleration * np.array(spec.a_max),
            self.jerk * np.array(spec.j_max),
        )


TRANSIT = SpeedLimits(velocity=0.8, acceleration=0.8, jerk=0.05)  # free space: approach, transit
APPROACH = SpeedLimits(velocity=0.5, acceleration=0.5, jerk=0.05)  # descend, lift, lower, retreat


def _frozen(a) -> np.ndarray:
    out = np.array(a, dtype=np.float64)  # a private copy
    out.flags.writeable = False
    return out


@dataclass(frozen=True, eq=False)
class JointTrajectory:
    """Joint states sampled at ``times`` (S,), starting at 0; arrays are read-only."""

    times: np.ndarray  # (S,) s, increasing, times[0] == 0
    positions: np.ndarray  # (S, J) rad
    velocities: np.ndarray  # (S, J) rad/s
    accelerations: np.ndarray  # (S, J) rad/s^2

    def __post_init__(self):
        for name in ("times", "positions", "velocities", "accelerations"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        t, q = self.times, self.positions
        if t.ndim != 1 or t.size == 0 or t[0] != 0.0 or (np.diff(t) <= 0).any():
            raise MotionError("times must be a non-empty increasing (S,) array starting at 0")
        if q.ndim != 2 or q.shape[0] != t.size:
            raise MotionError(f"positions has shape {q.shape}; expected ({t.size}, J)")
        for name in ("velocities", "accelerations"):
            if getattr(self, name).shape != q.shape:
                shape = getattr(self, name).shape
                raise MotionError(f"{name} has shape {shape}; expected {q.shape}")

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Linearly interpolated (q, qd), each (J,), at time ``t`` clamped to [0, duration]."""
        t = min(max(float(t), 0.0), self.duration)
        i = int(np.searchsorted(self.times, t, side="right")) - 1
        if i >= self.times.size - 1:
            return self.positions[-1].copy(), self.velocities[-1].copy()
        w = (t - self.times[i]) / (self.times[i + 1] - self.times[i])
        q = (1.0 - w) * self.positions[i] + w * self.positions[i + 1]
        qd = (1.0 - w) * self.velocities[i] + w * self.velocities[i + 1]
        return q, qd

    @classmethod
    def hold(cls, q, duration: float, dt: float = 0.002) -> JointTrajectory:
        """Standstill at ``q`` (J,) for ``duration`` s, sampled every ``dt`` (2 samples or more)."""
        q = np.asarray(q, dtype=np.float64)
        if q.ndim != 1:
            raise MotionError(f"q has shape {q.shape}; expected (J,)")
        if dt <= 0.0 or duration < 0.0:
            raise MotionError(f"hold needs dt > 0 and duration >= 0 (got {dt}, {duration})")
        n = max(1, math.ceil(duration / dt - 1e-9))
        zeros = np.zeros((n + 1, q.size))
        return cls(dt * np.arange(n + 1), np.tile(q, (n + 1, 1)), zeros, zeros)


def _ruckig_1dof(length: float, v: float, a: float, j: float, v0: float = 0.0, v1: float = 0.0):
    """Offline 1-DoF ruckig trajectory from 0 at speed ``v0`` to ``length`` at speed ``v1``
    (both at zero acceleration); MotionError when it would leave [0, length] (a boundary
    speed too high to stop or start within the segment)."""
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [length]
    inp.current_velocity, inp.target_velocity = [v0], [v1]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    traj = Trajectory(1)
    result = Ruckig(1).calculate(inp, traj)
    if result not in (Result.Working, Result.Finished):
        raise MotionError(f"ruckig failed on a segment of length {length:.4g}: {result}")
    extrema = traj.position_extrema[0]
    if extrema.min < -1e-9 or extrema.max > length + 1e-9:
        raise MotionError(
            f"boundary speeds {v0:.3g}, {v1:.3g} rad/s overshoot a segment of {length:.4g} rad"
        )
    return traj


def arc_limits(path, spec: PandaSpec = PANDA, limits: SpeedLimits = SpeedLimits()):
    """(length, v, a, j) of the joint-space polyline ``path`` (K >= 2, J): its arclength (rad)
    and the arclength limits min over pieces and joints of ``limit / |direction cosine|``."""
    d = np.diff(as_path(path, spec), axis=0)  # (K-1, J)
    seg = np.linalg.norm(d, axis=1)  # (K-1,)
    keep = seg > 1e-12
    if not keep.any():
        return 0.0, 0.0, 0.0, 0.0
    u = np.abs(d[keep] / seg[keep, None]).max(axis=0)  # (J,) largest direction cosine per joint
    moving = u > 0.0
    v, a, j = (float(np.min(lim[moving] / u[moving])) for lim in limits.scaled(spec))
    return float(seg.sum()), v, a, j


def pass_speed(path, share: float, spec: PandaSpec = PANDA, limits: SpeedLimits = SpeedLimits()):
    """An arclength speed (rad/s) at which a move along ``path`` (K, J) can start or end and
    still stop (or start) within it: ``share`` of the least of the arclength velocity limit and
    the speed that braking at half the acceleration limit stops in half the length, less what
    the jerk ramp adds. 0 for a zero-length path."""
    length, v, a, j = arc_limits(path, spec, limits)
    if length == 0.0:
        return 0.0
    # braking distance from speed w: about w^2 / (2 a) + w a / (2 j); keep it under L / 2
    w = min(v, math.sqrt(0.5 * a * length))
    while w > 1e-6 and w * w / a + w * a / j > 0.5 * length:
        w *= 0.8
    return share * w


def direction_at(path, end: int) -> np.ndarray:
    """The unit direction (J,) of ``path`` (K, J) as it leaves its first point (``end`` 0) or
    arrives at its last (``end`` -1); zeros for a path of zero length."""
    path = np.asarray(path, dtype=np.float64)
    d = np.diff(path, axis=0)  # (K-1, J)
    seg = np.linalg.norm(d, axis=1)
    moving = np.flatnonzero(seg > 1e-12)
    if not len(moving):
        return np.zeros(path.shape[1])
    k = moving[0] if end == 0 else moving[-1]
    return d[k] / seg[k]


def thin(positions: np.ndarray, step: float) -> np.ndarray:
    """The samples (K, J) of a densely sampled joint path (S, J) about ``step`` rad apart (the
    first and last kept): a trajectory sampled every 2 ms repeats nearly the same
    configuration many times, and the checker interpolates between what is kept."""
    moved = np.abs(np.diff(positions, axis=0)).max(axis=1)  # (S-1,)
    ticks = np.floor(np.concatenate([[0.0], np.cumsum(moved)]) / step)  # (S,)
    keep = np.flatnonzero(np.diff(ticks, prepend=-1.0) > 0)
    return positions[np.unique(np.concatenate([keep, [len(positions) - 1]]))]


def straight_segment(
    q0, q1, dt: float = 0.002, spec: PandaSpec = PANDA, limits: SpeedLimits = SpeedLimits()
) -> JointTrajectory:
    """Rest-to-rest, exactly straight joint segment ``q0 -> q1`` (J,), sampled every ``dt``.

    The first sample is q0 and the last exactly q1, both at zero velocity; the last sample time is
    the ruckig duration rounded up to a multiple of dt. A zero-length segment is a single sample.
    """
    q0, q1 = np.asarray(q0, dtype=np.float64), np.asarray(q1, dtype=np.float64)
    n_joints = len(spec.arm_joints)
    if q0.shape != (n_joints,) or q1.shape != (n_joints,):
        raise MotionError(f"q0, q1 have shapes {q0.shape}, {q1.shape}; expected ({n_joints},)")
    return polyline_segment(np.stack([q0, q1]), dt, spec, limits)


def as_path(path, spec: PandaSpec = PANDA) -> np.ndarray:
    """``path`` as a float64 joint-space polyline (K >= 2, J); MotionError when it is not one."""
    path = np.asarray(path, dtype=np.float64)
    n_joints = len(spec.arm_joints)
    if path.ndim != 2 or path.shape[0] < 2 or path.shape[1] != n_joints:
        raise MotionError(f"path has shape {path.shape}; expected (K >= 2, {n_joints})")
    if not np.isfinite(path).all():
        raise MotionError("the path contains NaN or inf")
    return path


def polyline_segment(
    path,
    dt: float = 0.002,
    spec: PandaSpec = PANDA,
    limits: SpeedLimits = SpeedLimits(),
    v_start: float = 0.0,
    v_end: float = 0.0,
) -> JointTrajectory:
    """Motion along the joint-space polyline ``path`` (K, J), K >= 2, rest to rest by default.

    One 1-DoF ruckig profile on the total arclength, with limits min over segments and joints of
    ``limit / |direction cosine|``, so every joint stays within its limits on every straight
    piece. Dense knots from IK along a Cartesian line make the tool move (nearly) straight in
    Cartesian space; with two knots this is `straight_segment`. ``v_start`` and ``v_end``
    (rad/s, at most the arclength velocity limit; see `pass_speed`) start or end it moving along
    the path: the joint velocity there is that speed times `direction_at` the end.
    """
    path, n_joints = as_path(path, spec), len(spec.arm_joints)
    if dt <= 0.0:
        raise MotionError(f"dt = {dt}; expected dt > 0")
    d = np.diff(path, axis=0)  # (K-1, J)
    seg = np.linalg.norm(d, axis=1)  # (K-1,)
    keep = seg > 1e-12
    d, seg = d[keep], seg[keep]
    if not len(seg):
        zeros = np.zeros((1, n_joints))
        return JointTrajectory(np.zeros(1), path[-1][None], zeros, zeros)
    knots = np.concatenate([[0.0], np.cumsum(seg)])  # (P+1,)
    direction = d / seg[:, None]  # (P, J) unit directions
    length, v, a, j = arc_limits(path, spec, limits)
    if not (0.0 <= v_start <= v * (1 + 1e-9) and 0.0 <= v_end <= v * (1 + 1e-9)):
        raise MotionError(f"v_start, v_end = {v_start}, {v_end}; expected speeds in [0, {v:.4g}]")
    traj = _ruckig_1dof(length, v, a, j, min(v_start, v), min(v_end, v))
    n = max(1, math.ceil(traj.duration / dt - 1e-9))
    times = dt * np.arange(n + 1)  # (S,)
    s = np.array([[x[0] for x in traj.at_time(min(t, traj.duration))] for t in times])  # (S, 3)
    s[:, 0] = np.clip(s[:, 0], 0.0, length)
    s[-1] = (length, min(v_end, v), 0.0)
    piece = np.clip(np.searchsorted(knots, s[:, 0], side="right") - 1, 0, len(seg) - 1)  # (S,)
    start = path[:-1][keep][piece]  # (S, J)
    positions = start + (s[:, :1] - knots[piece][:, None]) * direction[piece]  # (S, J)
    positions[0], positions[-1] = path[0], path[-1]
    dirs = direction[piece]  # (S, J)
    dirs[0] = direction[0]
    return JointTrajectory(times, positions, s[:, 1:2] * dirs, s[:, 2:3] * dirs)


def transition(
    q0,
    qd0,
    q1,
    qd1,
    dt: float = 0.002,
    spec: PandaSpec = PANDA,
    limits: SpeedLimits = SpeedLimits(),
) -> JointTrajectory:
    """A jerk-limited free-space move from ``q0`` moving at ``qd0`` to ``q1`` moving at ``qd1``
    (each (J,), zero acceleration at both ends), all joints time-synchronised, inside the
    datasheet joint limits. It leaves the straight line q0 -> q1 (free space only: check it
    for collisions as sampled). The last sample is exactly (q1, qd1). MotionError when ruckig
    finds no such trajectory."""
    q0, q1 = np.asarray(q0, dtype=np.float64), np.asarray(q1, dtype=np.float64)
    qd0, qd1 = np.asarray(qd0, dtype=np.float64), np.asarray(qd1, dtype=np.float64)
    n_joints = len(spec.arm_joints)
    for name, x in (("q0", q0), ("qd0", qd0), ("q1", q1), ("qd1", qd1)):
        if x.shape != (n_joints,) or not np.isfinite(x).all():
            raise MotionError(f"{name} has shape {x.shape}; expected finite ({n_joints},)")
    if dt <= 0.0:
        raise MotionError(f"dt = {dt}; expected dt > 0")
    v, a, j = limits.scaled(spec)
    inp = InputParameter(n_joints)
    inp.current_position, inp.current_velocity = list(q0), list(qd0)
    inp.target_position, inp.target_velocity = list(q1), list(qd1)
    inp.current_acceleration = inp.target_acceleration = [0.0] * n_joints
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(v), list(a), list(j)
    inp.min_position, inp.max_position = list(spec.q_min), list(spec.q_max)
    traj = Trajectory(n_joints)
    result = Ruckig(n_joints).calculate(inp, traj)
    if result not in (Result.Working, Result.Finished):
        raise MotionError(f"ruckig found no transition between the two states: {result}")
    n = max(1, math.ceil(traj.duration / dt - 1e-9))
    times = dt * np.arange(n + 1)  # (S,)
    states = [traj.at_time(min(t, traj.duration)) for t in times]
    positions = np.array([x[0] for x in states])  # (S, J)
    velocities = np.array([x[1] for x in states])  # (S, J)
    accelerations = np.array([x[2] for x in states])  # (S, J)
    positions[0], velocities[0] = q0, qd0
    positions[-1], velocities[-1], accelerations[-1] = q1, qd1, 0.0
    return JointTrajectory(times, positions, velocities, accelerations)
