"""Jerk-limited joint trajectories: exactly straight, rest-to-rest segments timed by ruckig.

A segment ``q0 -> q1`` is parameterised by its arclength s in joint space, ``q(t) = q0 + s(t) u``
with ``u = (q1 - q0) / L``, and s is timed by an offline 1-DoF ruckig problem ``0 -> L`` with the
limits ``min_i(lim_i / |u_i|)``. Every joint then respects its own velocity, acceleration and jerk
limit and the path stays exactly on the line (a 7-DoF ruckig with phase synchronisation falls back
to time synchronisation for the Panda's unequal limits and leaves the line by about 1e-2 rad).
Ruckig's intermediate waypoints are never used: the Community build computes them on a remote
server. Everything here runs locally.
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


def _ruckig_rest_to_rest(length: float, v: float, a: float, j: float):
    """Offline 1-DoF ruckig trajectory from rest at 0 to rest at ``length``."""
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [length]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    traj = Trajectory(1)
    result = Ruckig(1).calculate(inp, traj)
    if result not in (Result.Working, Result.Finished):
        raise MotionError(f"ruckig failed on a segment of length {length:.4g}: {result}")
    return traj


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
    path, dt: float = 0.002, spec: PandaSpec = PANDA, limits: SpeedLimits = SpeedLimits()
) -> JointTrajectory:
    """Rest-to-rest motion along the joint-space polyline ``path`` (K, J), K >= 2.

    One 1-DoF ruckig profile on the total arclength, with limits min over segments and joints of
    ``limit / |direction cosine|``, so every joint stays within its limits on every straight
    piece. Dense knots from IK along a Cartesian line make the tool move (nearly) straight in
    Cartesian space; with two knots this is `straight_segment`.
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
    length = float(knots[-1])
    direction = d / seg[:, None]  # (P, J) unit directions
    u = np.abs(direction).max(axis=0)  # (J,) largest direction cosine of each joint
    moving = u > 0.0
    v, a, j = (float(np.min(lim[moving] / u[moving])) for lim in limits.scaled(spec))
    traj = _ruckig_rest_to_rest(length, v, a, j)
    n = max(1, math.ceil(traj.duration / dt - 1e-9))
    times = dt * np.arange(n + 1)  # (S,)
    s = np.array([[x[0] for x in traj.at_time(min(t, traj.duration))] for t in times])  # (S, 3)
    s[:, 0] = np.clip(s[:, 0], 0.0, length)
    s[-1] = (length, 0.0, 0.0)
    piece = np.clip(np.searchsorted(knots, s[:, 0], side="right") - 1, 0, len(seg) - 1)  # (S,)
    start = path[:-1][keep][piece]  # (S, J)
    positions = start + (s[:, :1] - knots[piece][:, None]) * direction[piece]  # (S, J)
    positions[0], positions[-1] = path[0], path[-1]
    dirs = direction[piece]  # (S, J)
    return JointTrajectory(times, positions, s[:, 1:2] * dirs, s[:, 2:3] * dirs)
