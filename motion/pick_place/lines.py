"""Straight Cartesian lines of the hand as joint paths: the vertical phases of a move.

`vertical_path` gives the joint knots along the straight line between two TCP poses of the same
rotation, one IK point every few centimetres on one IK branch, so the tool moves straight (onto
the object it picks, down to its place) instead of drifting sideways as a straight joint
segment would; None where no branch keeps the hand on the line (near the arm's base the elbow's
limit can part the branches of the two ends). `bow` measures how far a joint path strays.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from motion.ik import IKSolver

KNOT_JUMP = 0.3  # rad, the most a joint may change between IK knots of a vertical phase


def _line_knots(pose_a: np.ndarray, pose_b: np.ndarray, step: float) -> np.ndarray:
    """(n, 4, 4): poses every ``step`` m along the straight line pose_a -> pose_b with pose_a's
    rotation, pose_b's position last (pose_a not included); empty when the line is shorter
    than two steps."""
    n = math.ceil(float(np.linalg.norm(pose_b[:3, 3] - pose_a[:3, 3])) / step)
    if n < 2:
        return np.zeros((0, 4, 4))
    knots = np.repeat(pose_a[None], n, axis=0)  # (n, 4, 4)
    frac = np.arange(1, n + 1)[:, None] / n  # (n, 1)
    knots[:, :3, 3] = pose_a[:3, 3] + frac * (pose_b[:3, 3] - pose_a[:3, 3])
    return knots


def _walk(solver: IKSolver, knots: np.ndarray, q0: np.ndarray) -> np.ndarray | None:
    """Joint knots (n+1, J) from ``q0`` through ``knots`` (n, 4, 4) on one IK branch, each
    knot continued from the one before: the knots left are solved at once from the last one
    found, and the run of them that converges without a joint jumping more than
    ``KNOT_JUMP`` rad is kept (the first alone with more iterations where none does); None
    where a knot cannot be continued."""
    path = [np.asarray(q0, dtype=np.float64)]
    while len(path) <= len(knots):
        rest = knots[len(path) - 1 :]
        found = solver.follow(rest, path[-1])
        chain = np.vstack([path[-1], found.q])  # (m+1, J)
        fine = found.ok & (np.abs(np.diff(chain, axis=0)).max(1) <= KNOT_JUMP)  # (m,)
        run = len(fine) if fine.all() else int(np.argmin(fine))
        if run == 0:
            found = solver.follow(rest[:1], path[-1], iterations=30)
            if not found.ok[0] or np.abs(found.q[0] - path[-1]).max() > KNOT_JUMP:
                return None
            run, chain = 1, np.vstack([path[-1], found.q])
        path.extend(chain[1 : run + 1])
    return np.stack(path)


def line_path(
    solver: IKSolver, pose_a: np.ndarray, pose_b: np.ndarray, q_a, step: float
) -> np.ndarray | None:
    """Joint knots (K, J) from ``q_a`` (a solution of ``pose_a``) along the straight line to
    ``pose_b`` (same rotation), one IK point every ``step`` m on ``q_a``'s branch; None where
    that branch cannot follow the line. Unlike `vertical_path`, no other branch and no plain
    joint segment: the path of that one posture of the arm (`tamp.geo.postures`)."""
    q_a = np.asarray(q_a, dtype=np.float64)
    knots = _line_knots(pose_a, pose_b, step)  # (n, 4, 4)
    return _walk(solver, knots, q_a) if len(knots) else q_a[None]


def bow(solver: IKSolver, path: np.ndarray, samples: int = 30) -> float:
    """How far (m) the TCP strays from the straight line between its two ends along the
    piecewise linear joint ``path`` (K, J), sampled ``samples`` times per segment."""
    frac = np.linspace(0.0, 1.0, samples)[:, None, None]  # (S, 1, 1)
    dense = (path[:-1][None] + frac * np.diff(path, axis=0)[None]).reshape(-1, path.shape[1])
    p = solver.tcp_positions(dense)  # (S * (K - 1), 3)
    a, line = p[0], p[-1] - p[0]
    t = np.clip((p - a) @ line / max(float(line @ line), 1e-12), 0.0, 1.0)  # (S',)
    return float(np.linalg.norm(p - (a + t[:, None] * line), axis=1).max())


class LineEnd(NamedTuple):
    """One end of a straight tool line: the tool's ``pose`` (4, 4) and the joints ``q`` (J,)
    planned there."""

    pose: np.ndarray
    q: np.ndarray


def vertical_path(
    solver: IKSolver,
    start: LineEnd,
    end: LineEnd,
    step: float,
    tolerance: float,
    free_start: bool = False,
) -> np.ndarray | None:
    """Joint knots (K, J) along the straight Cartesian line from ``start`` (pose_a, q_a) to
    ``end`` (pose_b, q_b), both of the same rotation,
    one IK point every ``step`` m, so the tool moves straight instead of drifting sideways. The
    knots follow one IK branch from ``q_a`` (`_walk`); the last solves pose_b on that branch
    (it may differ from ``q_b``). With ``free_start`` (nothing before pose_a is planned yet)
    the branch may also be followed up from ``q_b``, and the path then starts at another
    solution of pose_a. Failing those, the plain joint segment q_a -> q_b if its TCP strays at
    most ``tolerance`` m from the line, else None: near the arm's base one branch may not reach
    both ends (the elbow at its limit), and a joint segment there bows centimetres off the
    vertical, into whatever stands beside the pick or the place."""
    (pose_a, q_a), (pose_b, q_b) = start, end
    ends = np.stack([q_a, q_b])  # (2, J)
    knots = _line_knots(pose_a, pose_b, step)  # (n, 4, 4)
    if not len(knots):
        return ends
    path = _walk(solver, knots, q_a)
    if path is None and free_start:
        up = _walk(solver, _line_knots(pose_b, pose_a, step), q_b)
        path = None if up is None else up[::-1]
    if path is not None:
        return path
    return ends if bow(solver, ends) <= tolerance else None
