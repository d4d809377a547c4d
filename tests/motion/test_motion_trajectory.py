"""Straight rest-to-rest joint segments timed by 1-DoF ruckig: limits, rest, straightness."""

from __future__ import annotations

import numpy as np
import pytest

from motion.errors import MotionError
from motion.trajectory import JointTrajectory, SpeedLimits, straight_segment
from robots.panda import PANDA

Q_HOME = np.array(PANDA.q_home)
TRANSIT = SpeedLimits(velocity=0.5, acceleration=0.3, jerk=0.1)
APPROACH = SpeedLimits(velocity=0.2, acceleration=0.1, jerk=0.1)
STEPS = [
    np.array([0.8, -0.3, 0.2, 0.5, -0.4, 0.3, 1.2]),
    np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -2.0]),  # one joint only
    np.array([0.01, 0.0, -0.01, 0.0, 0.0, 0.0, 0.0]),  # short: jerk-limited
    np.array([-1.5, 0.4, 0.0, 0.9, 0.0, -0.6, 0.0]),
]


@pytest.mark.parametrize("limits", [TRANSIT, APPROACH], ids=["transit", "approach"])
@pytest.mark.parametrize("step", range(len(STEPS)))
def test_segment_respects_limits_and_is_straight(limits, step):
    q0, q1 = Q_HOME, Q_HOME + STEPS[step]
    traj = straight_segment(q0, q1, dt=0.002, limits=limits)
    v_max, a_max, j_max = limits.scaled(PANDA)
    assert (np.abs(traj.velocities) <= v_max * (1 + 1e-6)).all()
    assert (np.abs(traj.accelerations) <= a_max * (1 + 1e-6)).all()
    jerk = np.diff(traj.accelerations, axis=0) / np.diff(traj.times)[:, None]  # (S-1, J)
    assert (np.abs(jerk) <= j_max * (1 + 1e-6)).all()
    # rest to rest, exact end points, uniform sampling from 0
    np.testing.assert_array_equal(traj.positions[0], q0)
    np.testing.assert_array_equal(traj.positions[-1], q1)
    for end in (0, -1):
        assert np.abs(traj.velocities[end]).max() < 1e-12
        assert np.abs(traj.accelerations[end]).max() < 1e-12
    assert traj.times[0] == 0.0
    np.testing.assert_allclose(np.diff(traj.times), 0.002, rtol=1e-9)
    # every sample on the segment q0 -> q1, progressing monotonically
    d = q1 - q0
    s = (traj.positions - q0) @ d / (d @ d)  # (S,)
    deviation = np.abs(traj.positions - (q0 + s[:, None] * d)).max()
    assert deviation < 1e-9
    assert (np.diff(s) >= -1e-12).all() and s[0] == 0.0 and abs(s[-1] - 1.0) < 1e-12


def test_the_slowest_joint_reaches_its_limit_on_a_long_segment():
    traj = straight_segment(Q_HOME, Q_HOME + STEPS[0], limits=TRANSIT)
    v_max, _, _ = TRANSIT.scaled(PANDA)
    ratio = np.abs(traj.velocities).max(0) / v_max
    assert ratio.max() > 0.99  # time-optimal along the line: some joint saturates


def test_zero_length_segment_is_a_single_sample():
    traj = straight_segment(Q_HOME, Q_HOME.copy())
    assert traj.times.tolist() == [0.0]
    assert traj.duration == 0.0
    np.testing.assert_array_equal(traj.positions, Q_HOME[None])
    q, qd = traj.at(0.3)
    np.testing.assert_array_equal(q, Q_HOME)
    assert not qd.any()


def test_at_interpolates_and_clamps():
    traj = straight_segment(Q_HOME, Q_HOME + STEPS[3], limits=TRANSIT)
    np.testing.assert_array_equal(traj.at(-1.0)[0], traj.positions[0])
    np.testing.assert_array_equal(traj.at(traj.duration + 5.0)[0], traj.positions[-1])
    k = traj.times.size // 3
    np.testing.assert_allclose(traj.at(traj.times[k])[0], traj.positions[k], atol=1e-12)
    q, qd = traj.at(0.5 * (traj.times[k] + traj.times[k + 1]))
    np.testing.assert_allclose(q, 0.5 * (traj.positions[k] + traj.positions[k + 1]), atol=1e-12)
    np.testing.assert_allclose(qd, 0.5 * (traj.velocities[k] + traj.velocities[k + 1]), atol=1e-12)


def test_hold_is_a_standstill():
    traj = JointTrajectory.hold(Q_HOME, 0.5, dt=0.002)
    assert traj.duration == pytest.approx(0.5)
    assert traj.positions.shape == (251, 7)
    assert (traj.positions == Q_HOME).all() and not traj.velocities.any()


def test_trajectories_are_read_only():
    traj = straight_segment(Q_HOME, Q_HOME + STEPS[1])
    with pytest.raises(ValueError):
        traj.positions[0, 0] = 1.0


@pytest.mark.parametrize("factor", [0.0, -0.1, 1.5])
def test_speed_limits_must_be_fractions(factor):
    with pytest.raises(MotionError):
        SpeedLimits(velocity=factor)


@pytest.mark.parametrize(
    ("q0", "q1", "dt"),
    [(Q_HOME[:6], Q_HOME, 0.002), (Q_HOME, np.tile(Q_HOME, (2, 1)), 0.002), (Q_HOME, Q_HOME, 0.0)],
)
def test_bad_inputs_raise_motion_error(q0, q1, dt):
    with pytest.raises(MotionError):
        straight_segment(q0, q1, dt=dt)


def test_inconsistent_trajectory_arrays_raise():
    with pytest.raises(MotionError):
        JointTrajectory(np.array([0.0, 0.1]), np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7)))
    with pytest.raises(MotionError):
        JointTrajectory(np.array([0.1, 0.2]), np.zeros((2, 7)), np.zeros((2, 7)), np.zeros((2, 7)))
