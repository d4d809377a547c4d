"""Joint-space RRT paths (OMPL) against a synthetic wall in joint space; their ruckig timing."""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise

import numpy as np
import pytest

from motion.errors import MotionError
from motion.rrt import PLANNERS, PathPlannerConfig, path_trajectory, plan_path
from motion.trajectory import SpeedLimits
from robots.panda import PANDA

Q_HOME = np.array(PANDA.q_home)
START = Q_HOME + np.array([-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
GOAL = Q_HOME + np.array([1.0, 0.0, 0.3, 0.2, 0.0, 0.0, 0.0])
FAST = PathPlannerConfig(time_limit=5.0)
VERIFY = PathPlannerConfig(time_limit=5.0, verify=True)


# the planner checks segments every STEP rad: a margin of STEP / 2 makes the whole segment valid
STEP = FAST.resolution * np.linalg.norm(np.subtract(PANDA.q_max, PANDA.q_min))


def wall(q: np.ndarray, margin: float = 0.0) -> bool:
    """A wall across joint 1 that is open only for joint 2 >= 0.5: a detour is needed."""
    return not (abs(q[0]) < 0.3 + margin and q[1] < 0.5 + margin)


def padded(q: np.ndarray) -> bool:
    return wall(q, margin=0.55 * STEP)


def dense_ok(path: np.ndarray, valid, step: float = 0.005) -> bool:
    for a, b in pairwise(path):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        if not all(valid(a + (k / n) * (b - a)) for k in range(n + 1)):
            return False
    return True


@pytest.fixture(scope="module")
def around_wall():
    return plan_path(START, GOAL, padded, config=FAST)


def test_the_path_is_valid_at_the_checking_resolution():
    r = plan_path(START, GOAL, wall, config=FAST)
    assert r.ok and r.evidence["step_rad"] == pytest.approx(STEP, rel=1e-6)
    assert dense_ok(r.path, wall, step=r.evidence["step_rad"])


def test_finds_a_valid_path_around_the_wall(around_wall):
    r = around_wall
    assert r.ok and r.failure is None, r.evidence
    assert not wall(np.linspace(START, GOAL, 50)[25])  # the straight line is blocked
    np.testing.assert_array_equal(r.path[0], START)
    np.testing.assert_array_equal(r.path[-1], GOAL)
    assert r.path.ndim == 2 and r.path.shape[1] == 7 and r.path.shape[0] >= 3
    assert (r.path[:, 1] >= 0.5).any()  # goes over the wall
    assert (r.path >= np.array(PANDA.q_min) - 1e-6).all()
    assert (r.path <= np.array(PANDA.q_max) + 1e-6).all()
    assert dense_ok(r.path, wall)  # planned with the margin: valid everywhere
    assert r.checks == r.evidence["checks"] > 0 and r.time_s > 0.0
    assert r.evidence["length"] <= r.evidence["raw_length"] + 1e-9
    assert r.evidence["simplified"] and not r.evidence["simplify_capped"]
    assert not r.path.flags.writeable


@pytest.mark.parametrize("planner", [p for p in PLANNERS if p != "rrt_connect"])
@pytest.mark.parametrize("simplify", [True, False])
def test_every_planner_and_the_raw_path_are_valid(planner, simplify):
    config = replace(FAST, planner=planner, simplify=simplify)
    r = plan_path(START, GOAL, padded, config=config)
    assert r.ok, r.evidence
    assert dense_ok(r.path, wall)
    np.testing.assert_array_equal(r.path[[0, -1]], np.stack([START, GOAL]))


def test_same_seed_same_path_across_other_calls(around_wall):
    first = plan_path(START, GOAL, padded, config=replace(FAST, seed=3))
    other = plan_path(START, GOAL, padded, config=replace(FAST, seed=7))
    again = plan_path(START, GOAL, padded, config=replace(FAST, seed=3))
    assert first.ok and other.ok and again.ok
    np.testing.assert_array_equal(first.path, again.path)
    assert first.checks == again.checks
    for p in (other.path, around_wall.path):  # seeds 7 and 0 take other detours
        assert p.shape != first.path.shape or not np.array_equal(p, first.path)
    seed0 = plan_path(START, GOAL, padded, config=FAST)
    np.testing.assert_array_equal(seed0.path, around_wall.path)


@pytest.mark.parametrize("which", ["start", "goal"])
def test_invalid_start_or_goal_is_a_failure_value(which):
    blocked = np.array(Q_HOME)  # joint 1 at 0, joint 2 at -0.785: inside the wall
    start, goal = (blocked, GOAL) if which == "start" else (START, blocked)
    r = plan_path(start, goal, wall, config=FAST)
    assert not r.ok and r.path is None and r.failure == f"invalid_{which}"
    assert r.checks <= 2


def test_enclosed_goal_gives_no_path_within_the_time_limit():
    def shell(q):  # the goal sits in a closed hollow box
        return not 0.05 < np.abs(q - GOAL).max() < 0.4

    r = plan_path(START, GOAL, shell, config=replace(FAST, time_limit=0.2))
    assert not r.ok and r.path is None and r.failure == "no_path"
    assert r.checks > 0 and r.evidence["checks"] == r.checks
    assert 0.2 <= r.evidence["plan_s"] < 3.0  # stops at the limit (generous upper bound)


def test_errors_from_valid_propagate_and_planning_goes_on():
    def broken(q):
        raise ValueError("collision checker crashed")

    with pytest.raises(ValueError, match="crashed"):
        plan_path(START, GOAL, broken)
    assert plan_path(START, GOAL, wall, config=FAST).ok


@pytest.mark.parametrize(
    "start, goal, match",
    [
        (START[:6], GOAL, r"start has shape \(6,\)"),
        (START, np.stack([GOAL, GOAL]), r"goal has shape \(2, 7\)"),
        (np.full(7, np.nan), GOAL, "start contains NaN"),
        (START + np.array([0, 0, 0, 5.0, 0, 0, 0]), GOAL, "start: panda_joint4"),
        (START, GOAL + np.array([0, 3.0, 0, 0, 0, 0, 0]), "goal: panda_joint2"),
    ],
)
def test_misuse_raises_motion_error(start, goal, match):
    with pytest.raises(MotionError, match=match):
        plan_path(start, goal, wall)


def test_bad_config_and_valid_raise():
    with pytest.raises(MotionError, match="rrt_connect, rrt, rrt_star"):
        PathPlannerConfig(planner="prm")
    for field, value in [("time_limit", 0.0), ("seed", -1), ("resolution", 0.0), ("range", -1)]:
        with pytest.raises(MotionError, match=field):
            PathPlannerConfig(**{field: value})
    with pytest.raises(MotionError, match="valid must be a callable"):
        plan_path(START, GOAL, None)


def test_trajectory_follows_the_path_within_limits(around_wall):
    path, limits = around_wall.path, SpeedLimits(velocity=0.5)
    traj = path_trajectory(path, dt=0.004, limits=limits)
    np.testing.assert_array_equal(traj.positions[0], START)
    np.testing.assert_array_equal(traj.positions[-1], GOAL)
    assert traj.times[0] == 0.0 and (np.diff(traj.times) > 0).all()
    for q in path:  # passes every waypoint, at rest
        i = np.linalg.norm(traj.positions - q, axis=1).argmin()
        assert np.linalg.norm(traj.positions[i] - q) < 1e-12
        assert np.abs(traj.velocities[i]).max() < 1e-9
    v_max = limits.velocity * np.array(PANDA.v_max)
    assert (np.abs(traj.velocities) <= v_max * (1 + 1e-6)).all()
    assert dense_ok(traj.positions, wall)  # straight pieces: the timed motion stays valid


def test_trajectory_edge_cases():
    still = path_trajectory(np.stack([START, START]))
    assert still.times.size == 1 and np.array_equal(still.positions[0], START)
    with pytest.raises(MotionError, match="expected"):
        path_trajectory(START[None])
    with pytest.raises(MotionError, match="NaN"):
        path_trajectory(np.stack([START, np.full(7, np.inf)]))


# ---- with a batched check (motion.sphere_check's valid_batch, here the wall in joint space) --


def wall_batch(q: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """`wall` for (B, J) configurations at once."""
    return ~((np.abs(q[:, 0]) < 0.3 + margin) & (q[:, 1] < 0.5 + margin))


def padded_batch(q: np.ndarray) -> np.ndarray:
    return wall_batch(q, margin=0.55 * STEP)


def test_a_batched_check_finds_a_path_without_calling_valid():
    """``valid_batch`` is at least as strict as ``valid``: what it finds is returned unverified
    (``verify`` off, the default), and ``valid`` agrees with it at the checking resolution."""
    r = plan_path(START, GOAL, wall, config=FAST, valid_batch=padded_batch)
    assert r.ok and r.evidence["search"] in ("via", "connect"), r.evidence
    assert r.checks == 0 and not r.evidence["verified"]
    assert dense_ok(r.path, wall, step=r.evidence["step_rad"])


def test_a_batched_check_finds_a_path_that_valid_verifies():
    r = plan_path(START, GOAL, wall, config=VERIFY, valid_batch=padded_batch)
    assert r.ok and r.evidence["search"] in ("via", "connect"), r.evidence
    assert r.evidence["verified"] and "plan_s" not in r.evidence  # OMPL never ran
    assert r.evidence["batch_configs"] > 0 and r.evidence["batch_calls"] > 0
    assert dense_ok(r.path, wall, step=r.evidence["step_rad"])
    np.testing.assert_array_equal(r.path[[0, -1]], np.stack([START, GOAL]))
    again = plan_path(START, GOAL, wall, config=VERIFY, valid_batch=padded_batch)
    np.testing.assert_array_equal(again.path, r.path)  # seeded: the same path


def test_a_free_straight_line_is_one_segment():
    r = plan_path(START, GOAL, lambda q: True, valid_batch=lambda q: np.ones(len(q), bool))
    assert r.ok and r.path.shape == (2, 7) and r.evidence["search"] == "via"


def test_a_wall_one_via_point_cannot_pass_needs_the_batched_rrt_connect():
    # vias drawn only 0.01 rad about the midpoint: never over the wall
    config = replace(FAST, via_spreads=(0.01,))
    r = plan_path(START, GOAL, wall, config=config, valid_batch=padded_batch)
    assert r.ok and r.evidence["search"] == "connect", r.evidence
    assert dense_ok(r.path, wall, step=r.evidence["step_rad"])


def test_a_path_valid_refuses_falls_back_to_ompl_with_valid():
    """A batched check laxer than ``valid`` (it sees no wall): its straight line fails the
    verification, and OMPL plans with ``valid`` as without a batched check."""
    r = plan_path(START, GOAL, padded, config=VERIFY, valid_batch=lambda q: np.ones(len(q), bool))
    assert r.ok and r.evidence["search"] == "batched_refused" and "plan_s" in r.evidence
    assert dense_ok(r.path, wall)


def test_a_bad_batched_check_raises():
    with pytest.raises(MotionError, match="valid_batch must be None or a callable"):
        plan_path(START, GOAL, wall, valid_batch=3)
    with pytest.raises(MotionError, match=r"valid_batch returned shape \(1,\)"):
        plan_path(START, GOAL, wall, valid_batch=lambda q: np.ones(1, bool))
    with pytest.raises(MotionError, match="vias"):
        PathPlannerConfig(vias=0)


def test_a_batched_check_that_refuses_an_end_valid_accepts_asks_valid_about_its_refusals():
    def strict(q: np.ndarray) -> np.ndarray:  # stricter than padded: refuses the start
        return padded_batch(q) & (np.abs(q - START).max(axis=1) > 1e-9)

    r = plan_path(START, GOAL, padded, config=FAST, valid_batch=strict)
    assert r.ok and r.evidence["search"] in ("via", "connect"), r.evidence
    assert r.evidence["screened"] and "plan_s" not in r.evidence  # OMPL never ran
    assert 0 < r.checks < r.evidence["batch_configs"]  # valid only where strict refuses
    assert dense_ok(r.path, wall)


def test_a_batched_check_that_refuses_an_end_valid_refuses_too_hands_over_to_ompl_at_once():
    blocked_start = START.copy()
    blocked_start[:2] = (0.0, 0.0)  # inside the wall

    r = plan_path(blocked_start, GOAL, wall, config=FAST, valid_batch=wall_batch)
    assert not r.ok and r.failure == "invalid_start", r.evidence
    assert r.evidence["search"] == "batched_failed" and r.evidence["batch_calls"] == 1
