"""A planned move corrected while it runs: the place side moved to where the held object sits in
the hand (`corrected_place`), and the lower cut where the hand stops to look once more
(`split_lower`). Both keep the vertical phases on their lines (`motion.pick_place.lines`).
"""

from __future__ import annotations

import numpy as np

from motion.errors import MotionError
from motion.ik import IKSolver
from motion.pick_place.lines import LineEnd, vertical_path
from motion.pick_place.plan import Phase, PickPlaceConfig
from motion.trajectory import JointTrajectory, polyline_segment, thin


def corrected_place(
    solver: IKSolver,
    q_now,
    phases: tuple[Phase, ...],
    shift,
    config: PickPlaceConfig = PickPlaceConfig(),
) -> tuple[Phase, ...] | None:
    """The place side of a pick-and-place corrected for where the held object sits in the
    hand: the arm is at ``q_now`` (J,), held still near the end of ``phases``' transit, and
    the object sits ``-shift`` (3,) (m, base frame, z ignored) away in the hand from where the
    plan has it, so the plan's lower, place and retreat TCP poses move by ``shift``. Returns
    the phases that replace the plan's ``lower``, ``open`` and ``retreat``: ``shift`` (a
    straight Cartesian move of the TCP from where it stands to the moved start of the lower,
    at the near-contact speed), ``lower`` and ``retreat`` along the planned lines moved by
    ``shift``, and ``open``; None when an IK point on them fails (run the plan as it is then)."""
    by_name = {p.name: p for p in phases}
    if not {"lower", "retreat"} <= set(by_name):
        raise MotionError("corrected_place needs the plan's lower and retreat phases")
    q_now = np.asarray(q_now, dtype=np.float64)
    move = np.zeros(3)
    move[:2] = np.asarray(shift, dtype=np.float64)[:2]
    lower = by_name["lower"].trajectory.positions
    up_q = by_name["retreat"].trajectory.positions[-1]
    poses = solver.fk(np.stack([lower[0], lower[-1], up_q]))  # (3, 4, 4)
    poses[:, :3, 3] += move
    ends = solver.follow(poses, q_now, solver.config.max_iterations)  # seeded at the hand now
    if not ends.ok.all():
        return None
    here = solver.fk(q_now)[0]
    pre, place, up = poses
    q_pre, q_place, q_up = ends.q
    step, tolerance = config.vertical_step, config.straight_tolerance
    paths = [vertical_path(solver, LineEnd(here, q_now), LineEnd(pre, q_pre), step, tolerance)]
    for a, b, q_b in ((pre, place, q_place), (place, up, q_up)):
        if paths[-1] is None:
            return None
        start, end = LineEnd(a, paths[-1][-1]), LineEnd(b, q_b)
        paths.append(vertical_path(solver, start, end, step, tolerance))
    if paths[-1] is None:
        return None
    spec, dt, limits = solver.spec, config.dt, config.approach
    shift_path, lower_path, retreat_path = paths  # each (K >= 2, J): `vertical_path`
    return (
        Phase("shift", polyline_segment(shift_path, dt, spec, limits), "closed", limits),
        Phase("lower", polyline_segment(lower_path, dt, spec, limits), "closed", limits),
        Phase("open", JointTrajectory.hold(lower_path[-1], config.open_time, dt), "open"),
        Phase("retreat", polyline_segment(retreat_path, dt, spec, limits), "open", limits),
    )


def split_lower(
    solver: IKSolver, lower: Phase, above: float, config: PickPlaceConfig = PickPlaceConfig()
) -> tuple[Phase, Phase] | None:
    """``lower`` (a vertical phase ending at the place) cut where the TCP stands ``above`` m
    over its end: two ``lower`` phases along the same joint path, each rest to rest (the hand
    stops there, e.g. to look at what it holds once more); None when the phase does not come
    down from higher than that."""
    knots = thin(lower.trajectory.positions, 0.002)  # (K, J)
    z = solver.fk(knots)[:, 2, 3]  # (K,)
    cut = int(np.argmax(z <= z[-1] + above))  # the first knot that low
    if z[0] <= z[-1] + above or not 0 < cut < len(knots) - 1:
        return None
    dt = float(lower.trajectory.times[1] - lower.trajectory.times[0])
    limits = lower.limits or config.approach
    upper, rest = knots[: cut + 1], knots[cut:]
    return (
        Phase(lower.name, polyline_segment(upper, dt, solver.spec, limits), lower.gripper, limits),
        Phase(lower.name, polyline_segment(rest, dt, solver.spec, limits), lower.gripper, limits),
    )
