"""Pick-and-place planning: phase order, gripper commands, continuity, waypoints, failures."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest

from motion.errors import MotionError
from motion.ik import pose_yaw
from motion.pick_place import PHASES, PickPlaceConfig, PickPlaceRequest, plan_pick_place
from robots.panda import PANDA

CONFIG = PickPlaceConfig()
HALF = CONFIG.block_size / 2
REQUESTS = {
    # pick a table block, put it on a one-block stack; a two-block tower stands elsewhere
    "table_to_stack": PickPlaceRequest((0.45, -0.20, HALF), 0.3, (0.55, 0.15, 3 * HALF), 0.0, 0.10),
    # unstack the top of a three-block tower onto the table, rotated
    "tower_to_table": PickPlaceRequest(
        (0.60, 0.25, 5 * HALF), -1.2, (0.40, -0.25, HALF), 2.0, 0.15
    ),
}
GRIPPER = ("open", "open", "closed", "closed", "closed", "closed", "open", "open")


@pytest.fixture(scope="module", params=sorted(REQUESTS))
def planned(request, solver):
    req = REQUESTS[request.param]
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert result.ok, result.evidence
    return req, result


def _end_pose(solver, result, name: str) -> np.ndarray:
    phase = next(p for p in result.phases if p.name == name)
    return solver.fk(phase.trajectory.positions[-1])[0]


def test_phases_and_gripper_commands_in_order(planned):
    _, result = planned
    assert tuple(p.name for p in result.phases) == PHASES
    assert tuple(p.gripper for p in result.phases) == GRIPPER
    assert result.failure is None
    assert result.ik_time_s > 0.0


def test_phases_are_continuous_and_at_rest_where_the_gripper_acts(planned):
    _, result = planned
    np.testing.assert_array_equal(result.phases[0].trajectory.positions[0], PANDA.q_home)
    for before, after in zip(result.phases, result.phases[1:], strict=False):
        np.testing.assert_array_equal(
            after.trajectory.positions[0], before.trajectory.positions[-1]
        )
        # passing from one phase into the next without a jump in velocity
        np.testing.assert_allclose(
            after.trajectory.velocities[0], before.trajectory.velocities[-1], atol=1e-9
        )
    ends = [result.phases[0].trajectory.velocities[0], result.phases[-1].trajectory.velocities[-1]]
    for phase in result.phases:
        if phase.name in ("close", "open"):
            ends += [phase.trajectory.velocities[0], phase.trajectory.velocities[-1]]
        assert all(PANDA.clamp_error(q) is None for q in phase.trajectory.positions)
    assert np.abs(ends).max() < 1e-12


def test_blending_passes_the_corners_moving_and_saves_time(solver, planned):
    req, result = planned
    by_name = {p.name: p.trajectory for p in result.phases}
    for name in ("descend", "lower"):  # entered moving from the free-space phase before
        assert np.abs(by_name[name].velocities[0]).max() > 0.05
    assert np.abs(by_name["lift"].velocities[-1]).max() > 0.05
    stop = plan_pick_place(solver, PANDA.q_home, req, dataclasses.replace(CONFIG, blend=False))
    for phase in stop.phases:
        assert np.abs(phase.trajectory.velocities[[0, -1]]).max() < 1e-12
    total = sum(p.trajectory.duration for p in result.phases)
    assert total < sum(p.trajectory.duration for p in stop.phases)


@pytest.mark.parametrize("phase", [p for p in PHASES if p not in ("close", "open")])
def test_every_phase_keeps_within_its_fraction_of_the_datasheet_limits(planned, phase):
    _, result = planned
    found = next(p for p in result.phases if p.name == phase)
    free = phase in ("approach", "transit")
    limits = CONFIG.transit if free else CONFIG.approach
    assert found.limits == limits
    v_max, a_max, j_max = limits.scaled(PANDA)
    tr = found.trajectory
    assert (np.abs(tr.velocities) <= v_max * (1 + 1e-6)).all()
    assert (np.abs(tr.accelerations) <= a_max * (1 + 1e-6)).all()
    jerk = np.diff(tr.accelerations, axis=0) / np.diff(tr.times)[:, None]  # (S-1, J)
    if not free:  # a vertical phase turns by a fraction of a degree at its IK knots: skip those
        unit = tr.velocities / np.maximum(np.linalg.norm(tr.velocities, axis=1), 1e-12)[:, None]
        same = np.abs(np.diff(unit, axis=0)).max(1) < 1e-9  # (S-1,) both samples on one piece
        assert same.mean() > 0.8
        jerk = jerk[same]
    assert (np.abs(jerk) <= j_max * (1 + 1e-6)).all()
    # the sampled motion: positions differenced agree with the velocities it commands
    speed = np.abs(np.diff(tr.positions, axis=0) / np.diff(tr.times)[:, None])  # (S-1, J)
    assert (speed <= v_max * (1 + 1e-3) + 1e-6).all()


def test_the_default_limits_are_datasheet_fractions_slower_near_contact():
    for name in ("velocity", "acceleration", "jerk"):
        fast, slow = getattr(CONFIG.transit, name), getattr(CONFIG.approach, name)
        assert 0.0 < slow <= fast <= 1.0
    assert CONFIG.approach.velocity < CONFIG.transit.velocity


def test_descend_ends_at_the_block_and_lower_at_the_release_point(solver, planned):
    req, result = planned
    grasp = _end_pose(solver, result, "descend")
    np.testing.assert_allclose(grasp[:3, 3], req.pick, atol=1e-3)
    assert grasp[2, 2] < -0.999  # pointing down
    assert abs(math.remainder(pose_yaw(grasp) - req.pick_yaw, math.pi / 2)) < 1e-3
    place = _end_pose(solver, result, "lower")
    np.testing.assert_allclose(place[:3, 3], np.add(req.place, (0, 0, CONFIG.place_gap)), atol=1e-3)
    assert place[2, 2] < -0.999
    assert abs(math.remainder(pose_yaw(place) - req.place_yaw, math.pi / 2)) < 1e-3
    retreat = _end_pose(solver, result, "retreat")
    rise = max(place[2, 3] + CONFIG.approach_height, req.clear_z + CONFIG.lift_clearance)
    assert retreat[2, 3] >= rise - 1e-3


def test_the_empty_hand_hovers_above_every_stack_before_descending(solver, planned):
    req, result = planned
    pre_grasp = _end_pose(solver, result, "approach")
    np.testing.assert_allclose(pre_grasp[:2, 3], req.pick[:2], atol=1e-3)
    assert pre_grasp[2, 3] >= req.clear_z + CONFIG.lift_clearance - 1e-3


def test_transit_keeps_the_held_block_above_every_stack(solver, planned):
    req, result = planned
    transit = next(p for p in result.phases if p.name == "transit").trajectory
    block_bottom = solver.fk(transit.positions)[:, 2, 3] - HALF  # (S,)
    assert block_bottom.min() > req.clear_z + CONFIG.lift_clearance - 1e-3


def test_no_joint_jumps_between_nearby_waypoints(planned):
    _, result = planned
    steps = result.evidence["max_joint_step"]
    for name in ("grasp", "lift", "place", "retreat"):  # the short vertical moves
        assert steps[name] < 1.0, (name, steps)


def test_unreachable_place_is_ik_infeasible(solver):
    req = dataclasses.replace(REQUESTS["table_to_stack"], place=(1.5, 0.0, 3 * HALF))
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert not result.ok
    assert result.failure == "ik_infeasible"
    assert result.phases == ()
    assert result.evidence["waypoint"] == "pre_place"
    assert result.evidence["target_xyz"][0] == pytest.approx(1.5)
    assert "place" in result.evidence["unreachable"]
    assert result.evidence["pos_err"] > 0.1


def test_a_ceiling_keeps_the_hand_under_it_or_leaves_no_clearance(solver):
    base = REQUESTS["table_to_stack"]  # the block's top at 5 cm, the stack's top at 10 cm
    req = dataclasses.replace(base, pick_ceiling=0.12, place_ceiling=0.16)
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert result.ok, result.evidence
    tops = {
        n: solver.fk(p.trajectory.positions)[:, 2, 3].max()
        for n, p in ((p.name, p) for p in result.phases)  # (S,) TCP heights
        if n in ("descend", "lift", "lower")
    }
    assert tops["descend"] <= 0.12 + 1e-3 and tops["lift"] <= 0.12 + 1e-3
    assert tops["lower"] <= 0.16 + 1e-3
    low = dataclasses.replace(base, pick_ceiling=HALF + 0.01)  # no room to come down
    result = plan_pick_place(solver, PANDA.q_home, low, CONFIG)
    assert not result.ok and result.failure == "no_clearance" and result.phases == ()
    assert result.evidence["pick_ceiling"] == HALF + 0.01


def test_a_turned_grasp_takes_the_other_pair_of_faces(solver):
    base = REQUESTS["table_to_stack"]
    plain = plan_pick_place(solver, PANDA.q_home, base, CONFIG)
    turned = plan_pick_place(solver, PANDA.q_home, dataclasses.replace(base, turn=True), CONFIG)
    assert plain.ok and turned.ok
    quarter = (turned.evidence["yaws"]["grasp"] - plain.evidence["yaws"]["grasp"]) % math.pi
    assert quarter == pytest.approx(math.pi / 2, abs=1e-3)


def test_malformed_request_raises(solver):
    req = dataclasses.replace(REQUESTS["table_to_stack"], pick=(0.5, 0.0))
    with pytest.raises(MotionError):
        plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    with pytest.raises(MotionError):
        plan_pick_place(solver, PANDA.q_home[:6], REQUESTS["table_to_stack"], CONFIG)


@pytest.mark.parametrize("name", ["descend", "lift", "lower", "retreat"])
def test_vertical_moves_follow_the_cartesian_line(solver, planned, name):
    _, result = planned
    path = next(p for p in result.phases if p.name == name).trajectory
    xyz = solver.fk(path.positions[::10])[:, :3, 3]  # (S', 3)
    drift = np.linalg.norm(xyz[:, :2] - xyz[-1, :2], axis=1)  # sideways from the end point
    assert drift.max() < 0.003, (name, drift.max())


def _drift(solver, result, name: str) -> float:
    """How far (m) the TCP of phase ``name`` strays sideways from the phase's end point."""
    path = next(p for p in result.phases if p.name == name).trajectory
    xyz = solver.fk(path.positions[::5])[:, :3, 3]  # (S', 3)
    return float(np.linalg.norm(xyz[:, :2] - xyz[-1, :2], axis=1).max())


def test_vertical_moves_near_the_arms_base_stay_on_their_lines(solver):
    """Near the base, from a high hover, the descend's IK branch from the pre-grasp solution
    runs into the elbow's limit before the grasp; the path is followed up from the grasp
    instead (the pre-grasp solution changes). A plain joint segment bowed 2 cm and more."""
    req = PickPlaceRequest((0.234, -0.188, HALF), 0.0, (0.5, 0.2, HALF), 0.0, 0.30)
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert result.ok, result.evidence
    for name in ("descend", "lift", "lower", "retreat"):
        assert _drift(solver, result, name) < 0.003, name


def test_a_vertical_line_no_ik_branch_follows_is_a_returned_failure(solver):
    """Closer to the base no branch reaches both ends of the descend: the move fails as
    unreachable at the grasp, saying the line was not straight, instead of bowing."""
    req = PickPlaceRequest((0.192, -0.203, HALF), 0.0, (0.5, 0.2, HALF), 0.0, 0.15)
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert not result.ok and result.failure == "ik_infeasible"
    assert result.evidence["waypoint"] == "grasp" and result.evidence["straight"] is False
    assert result.phases == ()


def test_polyline_segment_respects_limits_and_passes_every_knot():
    from motion.trajectory import SpeedLimits, polyline_segment
    from robots.panda import PANDA

    q0 = np.asarray(PANDA.q_home)
    step = np.array([0.2, 0.1, 0.2, 0.1, 0.2, 0.1, 0.2])
    knots = np.stack([q0, q0 + 0.1, q0 + step])  # (3, J)
    limits = SpeedLimits(velocity=0.5, acceleration=0.3, jerk=0.1)
    traj = polyline_segment(knots, 0.002, PANDA, limits)
    v_max, a_max, _ = limits.scaled(PANDA)
    assert (np.abs(traj.velocities) <= v_max * (1 + 1e-6)).all()
    assert (np.abs(traj.accelerations) <= a_max * (1 + 1e-6)).all()
    np.testing.assert_allclose(traj.positions[[0, -1]], knots[[0, -1]])
    assert np.abs(traj.velocities[[0, -1]]).max() == 0.0
    middle = np.linalg.norm(traj.positions - knots[1], axis=1).min()
    assert middle < 1e-3  # the path goes through the middle knot


@pytest.mark.parametrize("shift", [(0.006, -0.004, 0.0), (-0.01, 0.0, 0.02)])
def test_a_corrected_place_moves_the_place_side_by_the_shift_in_the_plane(planned, solver, shift):
    from motion.pick_place import corrected_place

    _, result = planned
    transit = next(p for p in result.phases if p.name == "transit")
    q_above = transit.trajectory.positions[-1]
    tail = corrected_place(solver, q_above, result.phases, shift, CONFIG)
    assert tail is not None
    assert tuple(p.name for p in tail) == ("shift", "lower", "open", "retreat")
    assert tuple(p.gripper for p in tail) == ("closed", "closed", "open", "open")
    np.testing.assert_array_equal(tail[0].trajectory.positions[0], q_above)
    for before, after in itertools.pairwise(tail):
        np.testing.assert_array_equal(
            after.trajectory.positions[0], before.trajectory.positions[-1]
        )
    move = np.array([shift[0], shift[1], 0.0])  # z is ignored: the lower keeps its depth
    above = solver.fk(q_above)[0]
    for name, old in (("shift", above), ("lower", _end_pose(solver, result, "lower"))):
        new = solver.fk(next(p for p in tail if p.name == name).trajectory.positions[-1])[0]
        np.testing.assert_allclose(new[:3, 3], old[:3, 3] + move, atol=1e-3)
        np.testing.assert_allclose(new[:3, :3], old[:3, :3], atol=1e-3)
    retreat = solver.fk(tail[-1].trajectory.positions[-1])[0]
    np.testing.assert_allclose(
        retreat[:3, 3], _end_pose(solver, result, "retreat")[:3, 3] + move, atol=1e-3
    )


def test_a_lower_split_short_of_the_place_stops_there_and_ends_where_it_did(planned, solver):
    from motion.pick_place import split_lower

    _, result = planned
    lower = next(p for p in result.phases if p.name == "lower")
    upper, rest = split_lower(solver, lower, 0.02, CONFIG)
    assert (upper.name, rest.name, upper.gripper, rest.gripper) == ("lower",) * 2 + ("closed",) * 2
    np.testing.assert_array_equal(upper.trajectory.positions[-1], rest.trajectory.positions[0])
    np.testing.assert_array_equal(rest.trajectory.positions[-1], lower.trajectory.positions[-1])
    np.testing.assert_array_equal(upper.trajectory.positions[0], lower.trajectory.positions[0])
    for part in (upper, rest):  # each stops at its ends
        assert not np.abs(part.trajectory.velocities[[0, -1]]).any()
    cut, end = solver.fk(np.stack([upper.trajectory.positions[-1], lower.trajectory.positions[-1]]))
    assert 0.015 < cut[2, 3] - end[2, 3] <= 0.02
    np.testing.assert_allclose(cut[:2, 3], end[:2, 3], atol=1e-3)  # straight above the place
    assert split_lower(solver, rest, 0.05, CONFIG) is None  # it starts lower than that


def test_seeds_plan_the_same_move_in_another_posture(solver):
    """``seeds`` solve the pick's and the place's waypoints from other configurations: the
    hand makes the same move (the same grasp and place poses) in another posture of the arm,
    the approach still starting where the arm stands."""
    req = REQUESTS["table_to_stack"]
    nearest = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    grasp = next(p for p in nearest.phases if p.name == "descend").trajectory.positions[-1]
    place = next(p for p in nearest.phases if p.name == "lower").trajectory.positions[-1]
    swing = np.array([-0.8, 0.0, 1.2, 0.0, 1.0, 0.0, 0.0])
    other = plan_pick_place(solver, PANDA.q_home, req, CONFIG, seeds=(grasp + swing, place - swing))
    assert other.ok, other.evidence
    np.testing.assert_allclose(other.phases[0].trajectory.positions[0], PANDA.q_home)
    for name, before in (("descend", grasp), ("lower", place)):
        after = next(p for p in other.phases if p.name == name).trajectory.positions[-1]
        np.testing.assert_allclose(solver.fk(after), solver.fk(before), atol=1e-3)
        assert np.abs(after - before).max() > 0.3  # the same hand pose, another posture
    with pytest.raises(MotionError, match="two configurations"):
        plan_pick_place(solver, PANDA.q_home, req, CONFIG, seeds=(grasp,))
