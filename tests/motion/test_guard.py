"""`motion.guard`: a planned pick-and-place checked against boxes before it runs, blocked
free-space phases rerouted by the OMPL motion planner, blocked vertical phases failed."""

from __future__ import annotations

import numpy as np
import pytest

from motion.guard import GuardConfig, PickPlaceWorld, guard_free_move, guard_pick_place
from motion.ik import IKSolver
from motion.pick_place import PickPlaceRequest, plan_pick_place
from motion.trajectory import thin
from robots.collision import Box, PandaCollision
from robots.panda import PANDA

HALF = (0.025, 0.025, 0.025)
PICK, PLACE = (0.45, -0.2, 0.025), (0.45, 0.2, 0.025)
WALL = Box("wall", (0.45, 0.0, 0.12), (0.12, 0.01, 0.12))  # between pick and place, 24 cm tall


@pytest.fixture(scope="module")
def model():
    with PandaCollision(margin=0.01) as m:
        yield m


@pytest.fixture(scope="module")
def planned():
    request = PickPlaceRequest(PICK, 0.0, PLACE, 0.0, clear_z=0.05)
    result = plan_pick_place(IKSolver(), np.asarray(PANDA.q_home), request)
    assert result.ok
    return result.phases


def _world(*extra: Box) -> PickPlaceWorld:
    a = Box("a", PICK, HALF)
    return PickPlaceWorld((a, *extra), "a", "table", "table", Box("a", PLACE, HALF), 0.05)


def test_thin_keeps_the_ends_and_bounds_the_step():
    path = np.linspace(0.0, 1.0, 2000)[:, None] * np.ones((1, 7))  # (S, J)
    kept = thin(path, 0.02)
    assert np.array_equal(kept[0], path[0]) and np.array_equal(kept[-1], path[-1])
    sample = np.abs(np.diff(path, axis=0)).max()  # a kept step may overshoot by one sample
    assert len(kept) < 200 and np.abs(np.diff(kept, axis=0)).max() <= 0.02 + sample


def test_a_free_scene_passes_unchanged(model, planned):
    out = guard_pick_place(planned, model, _world())
    assert out.ok and out.rerouted == () and out.phases == tuple(planned)


def test_a_transit_through_a_wall_is_predicted_as_a_collision(model, planned):
    out = guard_pick_place(planned, model, _world(WALL), GuardConfig(plan=False))
    assert not out.ok and out.failure == "collision"
    assert out.evidence["phase"] == "transit" and out.evidence["other"] == "wall"


def test_the_motion_planner_routes_the_transit_around_the_wall(model, planned):
    out = guard_pick_place(planned, model, _world(WALL), seed=4)
    assert out.ok and "transit" in out.rerouted and out.plan_time_s > 0
    transit = next(p for p in out.phases if p.name == "transit")
    old = next(p for p in planned if p.name == "transit")
    assert np.allclose(transit.trajectory.positions[[0, -1]], old.trajectory.positions[[0, -1]])
    model.set_boxes([b for b in _world(WALL).boxes if b.name != "a"])
    model.hold(0.05)
    assert model.check_path(transit.trajectory.positions, 0.025, max_step=0.01).ok
    again = guard_pick_place(planned, model, _world(WALL), seed=4)  # the same seed, same detour
    twin = next(p for p in again.phases if p.name == "transit")
    assert np.array_equal(twin.trajectory.positions, transit.trajectory.positions)


def test_a_blocked_vertical_phase_fails_without_a_detour(model, planned):
    """A neighbour beside the block to pick leaves the approach above it free but stands in the
    open fingers' way down; a board just above the place leaves the transit free but stops the
    held block coming down. Each vertical phase fails as planned, with the motion planner
    (which would reroute a free-space phase) never run."""
    side = Box("b", (PICK[0], PICK[1] + 0.05, 0.025), HALF)
    board = Box("board", (PLACE[0], PLACE[1], 0.11), (0.03, 0.03, 0.005))
    for box, phase, part in ((side, "descend", "finger"), (board, "lower", "held")):
        out = guard_pick_place(planned, model, _world(box))
        assert not out.ok and out.failure == "collision"
        assert (out.evidence["phase"], out.evidence["other"]) == (phase, box.name)
        assert part in out.evidence["part"]
        assert out.planner_runs == 0 and out.plan_time_s == 0 and "planner" not in out.evidence
        assert out.rerouted == ()


def test_the_fingers_may_touch_the_block_they_pick_but_not_a_neighbour(model, planned):
    # a neighbour 4.5 cm beside the picked block: an open finger passes through it
    side = Box("b", (PICK[0], PICK[1] + 0.045, 0.025), HALF)
    fine = Box("c", (PICK[0] + 0.3, PICK[1], 0.025), HALF)
    assert guard_pick_place(planned, model, _world(fine)).ok
    out = guard_pick_place(planned, model, _world(side), GuardConfig(plan=False))
    assert not out.ok and out.evidence["other"] == "b"


def test_a_free_move_through_a_wall_is_rerouted_or_refused(model, planned):
    transit = next(p for p in planned if p.name == "transit").trajectory
    way = guard_free_move(transit, model, [WALL], seed=1)
    assert way is not None and not np.array_equal(way.positions, transit.positions)
    model.set_boxes([WALL])
    model.hold(None)
    assert not model.check_path(transit.positions, 0.04, max_step=0.01).ok
    assert model.check_path(way.positions, 0.04, max_step=0.01).ok
    assert np.allclose(way.positions[[0, -1]], transit.positions[[0, -1]])
    box = Box("box", PICK, (0.6, 0.6, 0.6))  # swallows the whole workspace: no way at all
    assert guard_free_move(transit, model, [box], seed=1) is None


def test_a_detour_stops_the_vertical_phases_beside_it(model, planned):
    """The planned lift ends and the lower starts moving (the transit passes through), a
    detour starts and ends at rest: the guard re-times both along the same path to stop."""
    by_name = {p.name: p for p in planned}
    assert np.abs(by_name["lift"].trajectory.velocities[-1]).max() > 0.05
    assert np.abs(by_name["lower"].trajectory.velocities[0]).max() > 0.05
    out = guard_pick_place(planned, model, _world(WALL), seed=4)
    assert out.ok and "transit" in out.rerouted
    for before, after in zip(out.phases, out.phases[1:], strict=False):
        np.testing.assert_array_equal(
            after.trajectory.positions[0], before.trajectory.positions[-1]
        )
        np.testing.assert_allclose(
            after.trajectory.velocities[0], before.trajectory.velocities[-1], atol=1e-9
        )
    lift, lower = (next(p for p in out.phases if p.name == n) for n in ("lift", "lower"))
    assert np.abs(lift.trajectory.velocities[-1]).max() < 1e-12
    assert np.abs(lower.trajectory.velocities[0]).max() < 1e-12
    for phase in (lift, lower):  # the same path: its ends and every sample on the old samples
        old = by_name[phase.name].trajectory.positions
        np.testing.assert_array_equal(phase.trajectory.positions[[0, -1]], old[[0, -1]])


class _Counted:
    """A collision model that counts its mesh path checks."""

    def __init__(self, inner):
        self.inner, self.paths = inner, 0

    @property
    def margin(self) -> float:
        return self.inner.margin

    @margin.setter
    def margin(self, value: float) -> None:
        self.inner.margin = value

    def check_path(self, *args, **kwargs):
        self.paths += 1
        return self.inner.check_path(*args, **kwargs)

    def __getattr__(self, name):
        return getattr(self.inner, name)


@pytest.mark.parametrize("extra", ["none", "wall", "side", "board"])
def test_sphere_screening_gives_the_meshes_verdicts_and_skips_them_where_clear(
    model, planned, extra
):
    from motion.sphere_check import Screened

    boxes = {
        "none": (),
        "wall": (WALL,),
        "side": (Box("b", (PICK[0], PICK[1] + 0.05, 0.025), HALF),),
        "board": (Box("board", (PLACE[0], PLACE[1], 0.11), (0.03, 0.03, 0.005)),),
    }[extra]
    config = GuardConfig(plan=False)
    alone = guard_pick_place(planned, model, _world(*boxes), config)
    counted = _Counted(model)
    screened = Screened(counted)
    both = guard_pick_place(planned, screened, _world(*boxes), config)
    assert (both.ok, both.failure) == (alone.ok, alone.failure)
    assert both.evidence == alone.evidence  # a flagged phase: the meshes' own contact
    if extra == "none":  # the spheres clear every phase: the meshes are never asked
        assert counted.paths == 0
    else:
        assert counted.paths >= 1


def _plate_below(model, q, gap: float, tcp_z: float) -> Box:
    """A plate under the open hand at ``q`` (fingers down, the tool at height ``tcp_z``) with
    its top ``gap`` m below the lowest point of the hand (found by bisection on the model's
    verdict at margin 0)."""
    lo, hi = 0.0, tcp_z + 0.03  # plate top heights (m): free at lo, in the fingers at hi
    before = model.margin
    model.margin = 0.0
    model.hold(None)
    try:
        for _ in range(30):
            mid = (lo + hi) / 2
            model.set_boxes([Box("plate", (0.45, -0.2, mid - 0.005), (0.1, 0.1, 0.005))])
            lo, hi = (mid, hi) if model.valid(q, 0.04) else (lo, mid)
    finally:
        model.margin = before
    top = lo - gap
    return Box("plate", (0.45, -0.2, top - 0.005), (0.1, 0.1, 0.005))


def test_a_free_move_may_leave_where_the_arm_stands_within_the_margin(model):
    """The arm left 6 mm above a plate (within the 10 mm margin, clear at the vertical 2 mm):
    a free move up and away is allowed (`GuardConfig.escape`), the same move down toward it
    is refused, and so is moving off from 1 mm (within even the vertical margin) or with the
    escape off."""
    from motion.ik import top_down_pose
    from motion.trajectory import polyline_segment

    solver = IKSolver()
    tool = ((0.45, -0.2, 0.12), (0.45, -0.2, 0.30), (0.45, 0.2, 0.30))  # low, high, across
    found = solver.solve(np.stack([top_down_pose(xyz, 0.0) for xyz in tool]), PANDA.q_home)
    assert np.asarray(found.ok).all()
    low, high, far = np.asarray(found.q)
    up = polyline_segment(np.linspace(low, high, 20))
    down = polyline_segment(np.linspace(high, low, 20))
    near = _plate_below(model, low, 0.006, 0.12)
    model.set_boxes([near])
    model.hold(None)
    assert not model.valid(low, 0.04)  # within the 10 mm margin where it stands
    assert guard_free_move(up, model, [near], GuardConfig(plan=False)) is up
    assert guard_free_move(down, model, [near], GuardConfig(plan=False)) is None
    assert guard_free_move(up, model, [near], GuardConfig(plan=False, escape=0.0)) is None
    touching = _plate_below(model, low, 0.001, 0.12)
    assert guard_free_move(up, model, [touching], GuardConfig(plan=False)) is None
    # the motion planner may start there too: the way across the wall is gone around
    across = polyline_segment(np.linspace(low, far, 20))
    routed = guard_free_move(across, model, [near, WALL], seed=1)
    assert routed is not None and routed is not across
    assert np.allclose(routed.positions[[0, -1]], across.positions[[0, -1]])
    assert guard_free_move(across, model, [near, WALL], GuardConfig(escape=0.0), seed=1) is None


def test_a_path_is_clear_or_not_as_the_guard_checks_its_phase(model, planned):
    """`path_clear` screens a joint path before it is a phase, as the guard would check it:
    the transit's path through the wall is blocked, the same path in a free scene clear, and
    the descent clear beside a far block but not with a neighbour an open finger passes
    through."""
    from motion.guard import path_clear

    path = {p.name: thin(p.trajectory.positions, 0.02) for p in planned}
    assert not path_clear(path["transit"], model, _world(WALL), "transit")
    assert path_clear(path["transit"], model, _world(), "transit")
    side = Box("b", (PICK[0], PICK[1] + 0.045, 0.025), HALF)
    fine = Box("c", (PICK[0] + 0.3, PICK[1], 0.025), HALF)
    assert path_clear(path["descend"], model, _world(fine), "descend")
    assert not path_clear(path["descend"], model, _world(side), "descend")
