"""Pick-and-place with a chosen grasp: the default path unchanged, the waypoints where the grasp
puts the hand, reached by the solved joint path inside the limits, and the guard holding the
object where the grasp holds it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from motion.errors import MotionError
from motion.grasps import back_out, grasps, world_tcp
from motion.ik import pose_yaw
from motion.pick_place import (
    WAYPOINTS,
    PickPlaceConfig,
    PickPlaceRequest,
    plan_pick_place,
    request_grasp,
    waypoint_targets,
)
from robots.panda import PANDA

CONFIG = PickPlaceConfig()
H = CONFIG.block_size / 2
CUBE = (H, H, H)
TALL = (0.02, 0.02, 0.06)  # 4 x 4 x 12 cm
# a cube from the table onto a one-block stack (as in test_motion_pick_place)
BASE = PickPlaceRequest((0.45, -0.20, H), 0.3, (0.55, 0.15, 3 * H), 0.0, 0.10)
ARM = ("approach", "descend", "lift", "transit", "lower", "retreat")  # phase -> its end waypoint


def _grasp(kind: str, half, name: str):
    return next(g for g in grasps(kind, half) if g.name == name)


def test_without_grasp_and_half_the_request_keeps_todays_grasp(solver):
    hand = pose_yaw(solver.fk(PANDA.q_home)[0])
    assert request_grasp(BASE, hand, CONFIG) == (None, CUBE)
    today = waypoint_targets(BASE, hand, CONFIG)
    # the cube's top grasp at the yaw today's rule picks gives the same six waypoints
    k = round((pose_yaw(today[1]) - BASE.pick_yaw) / (math.pi / 2)) % 4
    same = dataclasses.replace(BASE, grasp=_grasp("cube", CUBE, f"top{k}"))
    np.testing.assert_allclose(waypoint_targets(same, hand, CONFIG), today, atol=1e-12)
    # half alone: the default hand yaw, taken by the matching top grasp
    sized = dataclasses.replace(BASE, half=CUBE)
    assert request_grasp(sized, hand, CONFIG)[0].name == f"top{k}"
    np.testing.assert_allclose(waypoint_targets(sized, hand, CONFIG), today, atol=1e-12)


def _expected(req: PickPlaceRequest, half) -> dict[str, np.ndarray]:
    """The TCP pose (4, 4) each waypoint must reach, from the grasp and the object's pose."""
    g, up = req.grasp, np.array([0.0, 0.0, 1.0])
    take = world_tcp(g, req.pick, req.pick_yaw)
    put = world_tcp(g, req.place, req.place_yaw)
    put[:3, 3] += CONFIG.place_gap * up
    highest = max(req.clear_z, req.pick[2] + half[2], req.place[2] - half[2])
    z_transit = highest + CONFIG.lift_clearance + 2 * half[2] + g.matrix[2, 3]
    out = {"grasp": take, "place": put}
    for name, pose, off in (
        ("pre_grasp", take, back_out(g, half) + CONFIG.approach_height),
        ("retreat", put, CONFIG.approach_height),
    ):
        out[name] = pose.copy()
        out[name][:3, 3] -= off * pose[:3, 2]  # back along the approach (tool z)
        if pose[2, 2] < -0.999:  # a vertical approach also hovers over the stacks
            out[name][2, 3] = max(out[name][2, 3], highest + CONFIG.lift_clearance)
    for name, pose in (("lift", take), ("pre_place", put)):
        out[name] = pose.copy()
        out[name][2, 3] = z_transit
    return out


CASES = {
    # the cube's other pair of faces, from the table onto a stack
    "cube_top1": (BASE, "cube", CUBE, "top1"),
    # a tall object taken from the robot's side, the hand horizontal, to the table's other side
    "tall_side": (
        PickPlaceRequest((0.45, -0.20, 0.06), 0.0, (0.45, 0.20, 0.06), 0.0, 0.05),
        "cuboid",
        TALL,
        "side-x:flip",
    ),
    "cube_tilt": (
        PickPlaceRequest((0.5, -0.15, H), 0.3, (0.5, 0.2, H), -0.2, 0.05),
        "cube",
        CUBE,
        "tilt-x",
    ),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def planned(request, solver):
    base, kind, half, name = CASES[request.param]
    req = dataclasses.replace(base, grasp=_grasp(kind, half, name), half=half)
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert result.ok, result.evidence
    return req, half, result


def test_the_solved_path_reaches_every_grasp_waypoint_inside_the_limits(solver, planned):
    req, half, result = planned
    assert result.grasp == req.grasp and result.evidence["grasp"] == req.grasp.name
    want = _expected(req, half)
    ends = dict(zip(WAYPOINTS, ARM, strict=True))
    for name in WAYPOINTS:
        phase = next(p for p in result.phases if p.name == ends[name])
        got = solver.fk(phase.trajectory.positions[-1])[0]
        np.testing.assert_allclose(got[:3, 3], want[name][:3, 3], atol=1e-3, err_msg=name)
        np.testing.assert_allclose(got[:3, :3], want[name][:3, :3], atol=1e-3, err_msg=name)
    for phase in result.phases:
        assert all(PANDA.clamp_error(q) is None for q in phase.trajectory.positions)


def test_descend_and_retreat_follow_the_approach_axis(solver, planned):
    _, _, result = planned
    for name in ("descend", "retreat"):
        path = next(p for p in result.phases if p.name == name).trajectory
        tcp = solver.fk(path.positions[::10])  # (S', 4, 4)
        line = tcp[-1, :3, 3] - tcp[0, :3, 3]
        axis = tcp[-1, :3, 2]  # the approach: the move runs along it
        assert abs(abs(line @ axis) - np.linalg.norm(line)) < 1e-3, name
        off = tcp[:, :3, 3] - tcp[0, :3, 3]
        drift = np.linalg.norm(off - np.outer(off @ axis, axis), axis=1)  # (S',) off the line
        assert drift.max() < 0.003, (name, drift.max())


def test_transit_carries_the_object_above_every_stack(solver, planned):
    req, half, result = planned
    transit = next(p for p in result.phases if p.name == "transit").trajectory
    inverse = np.linalg.inv(req.grasp.matrix)  # the object's pose in the TCP frame
    centre = (solver.fk(transit.positions) @ inverse)[:, 2, 3]  # (S,)
    assert (centre - half[2]).min() > req.clear_z + CONFIG.lift_clearance - 1e-3


def test_an_unreachable_place_with_a_grasp_is_ik_infeasible(solver):
    g = _grasp("cuboid", TALL, "top1")
    req = dataclasses.replace(BASE, place=(1.5, 0.0, 0.06), grasp=g, half=TALL)
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert not result.ok and result.failure == "ik_infeasible" and result.phases == ()
    assert result.evidence["waypoint"] == "pre_place" and result.evidence["pos_err"] > 0.1
    assert result.grasp == g


def test_a_ceiling_leaves_a_tilted_hand_less_room_or_none(solver):
    base, kind, half, name = CASES["cube_tilt"]
    req = dataclasses.replace(base, grasp=_grasp(kind, half, name), half=half)
    hand = pose_yaw(solver.fk(PANDA.q_home)[0])
    high = waypoint_targets(req, hand, CONFIG)
    low = waypoint_targets(dataclasses.replace(req, pick_ceiling=0.08), hand, CONFIG)
    assert high[0, 2, 3] > 0.08 and low[0, 2, 3] == pytest.approx(0.08)
    back = low[0, :3, 3] - low[1, :3, 3]  # still along the approach, only shorter
    assert np.linalg.norm(np.cross(back, low[1, :3, 2])) < 1e-9
    shut = dataclasses.replace(req, pick_ceiling=req.pick[2] + 0.02)
    result = plan_pick_place(solver, PANDA.q_home, shut, CONFIG)
    assert not result.ok and result.failure == "no_clearance"


def test_malformed_grasp_requests_raise(solver):
    g = _grasp("cube", CUBE, "top1")
    with pytest.raises(MotionError, match="turn"):
        plan_pick_place(solver, PANDA.q_home, dataclasses.replace(BASE, grasp=g, turn=True))
    with pytest.raises(MotionError, match="half"):
        plan_pick_place(solver, PANDA.q_home, dataclasses.replace(BASE, half=(0.02, 0.02)))
    with pytest.raises(MotionError, match="half"):
        plan_pick_place(solver, PANDA.q_home, dataclasses.replace(BASE, half=(0.02, 0.0, 0.02)))
    with pytest.raises(MotionError, match="no top-down grasp"):
        plan_pick_place(solver, PANDA.q_home, dataclasses.replace(BASE, half=(0.05, 0.05, H)))


@pytest.mark.sim
def test_the_guard_holds_a_tall_object_where_its_grasp_holds_it(solver):
    """A bar across the way, 26 cm tall: the hand carrying the 12 cm object by its top passes
    over it, the object hanging below the fingers does not; a world that does not say what
    is held (today's cube at the TCP) misses that collision. With nothing in the way, the
    fingers around the object and the object on the table are allowed contacts."""
    from motion.guard import GuardConfig, PickPlaceWorld, guard_pick_place
    from robots.collision import Box, PandaCollision

    pick, place = (0.45, -0.2, 0.06), (0.45, 0.2, 0.06)
    g = _grasp("cuboid", TALL, "top0")
    req = PickPlaceRequest(pick, 0.0, place, 0.0, clear_z=0.05, grasp=g, half=TALL)
    result = plan_pick_place(solver, PANDA.q_home, req, CONFIG)
    assert result.ok, result.evidence
    obj, bar = Box("a", pick, TALL), Box("bar", (0.45, 0.0, 0.13), (0.12, 0.01, 0.13))
    placed = Box("a", place, TALL)
    held = PickPlaceWorld((obj, bar), "a", "table", "table", placed, 0.05, TALL, result.grasp)
    with PandaCollision(margin=0.01) as model:
        out = guard_pick_place(result.phases, model, held, GuardConfig(plan=False))
        assert not out.ok and out.failure == "collision"
        assert (out.evidence["phase"], out.evidence["part"]) == ("transit", "held")
        assert out.evidence["other"] == "bar"
        cube = dataclasses.replace(held, half=None, grasp=None)
        assert guard_pick_place(result.phases, model, cube, GuardConfig(plan=False)).ok
        free = dataclasses.replace(held, boxes=(obj,))
        assert guard_pick_place(result.phases, model, free, GuardConfig(plan=False)).ok
