"""`motion.grasps`: the candidate grasps of cubes, cuboids and cylinders, in the object frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from motion.errors import MotionError
from motion.grasps import (
    GRASP_DEPTH,
    PAD_OVERLAP,
    SIDE_CLEARANCE,
    STROKE,
    back_out,
    grasps,
    world_approach,
    world_tcp,
)
from motion.ik import top_down_pose

CUBE = (0.025, 0.025, 0.025)
BAR = (0.035, 0.015, 0.025)  # 7 cm x 3 cm x 5 cm
CAN = (0.02, 0.02, 0.06)  # a cylinder 4 cm across, 12 cm tall
SIDES = ("+x", "-x", "+y", "-y")
ROLLS = ("", ":flip")


def _names(found) -> set[str]:
    return {g.name for g in found}


@pytest.mark.parametrize(("kind", "half"), [("cube", CUBE), ("cuboid", BAR), ("cylinder", CAN)])
def test_every_grasp_is_a_rigid_pose_whose_fingers_span_its_width(kind, half):
    found = grasps(kind, half)
    assert found and len(_names(found)) == len(found)
    for g in found:
        m = g.matrix
        r = m[:3, :3]
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(r) == pytest.approx(1.0)
        np.testing.assert_allclose(m[3], (0, 0, 0, 1))
        np.testing.assert_allclose(r[:, 2], g.approach, atol=1e-12)  # approach = tool z
        # the fingers close along tool y: the width is the object's extent along it
        assert g.width == pytest.approx(2 * float(np.abs(r[:, 1]) @ half))
        assert g.width + 0.01 < STROKE  # more than 5 mm spare per finger


def test_a_cube_has_four_top_yaws_and_sides_and_tilts_from_four_sides():
    found = grasps("cube", CUBE)
    tops = {f"top{k}" for k in range(4)}
    sides = {f"{f}{s}{r}" for f in ("side", "tilt") for s in SIDES for r in ROLLS}
    assert _names(found) == tops | sides
    assert [g.name[:3] for g in found] == ["top"] * 4 + ["sid"] * 8 + ["til"] * 8
    assert _names(grasps("cube", CUBE, ("top",))) == tops
    assert _names(grasps("cube", CUBE, ("side", "tilt"))) == sides


def test_top0_of_a_cube_is_todays_top_down_grasp():
    xyz, yaw = (0.5, -0.1, 0.025), 0.3
    by_name = {g.name: g for g in grasps("cube", CUBE)}
    np.testing.assert_allclose(world_tcp(by_name["top0"], xyz, yaw), top_down_pose(xyz, yaw))
    for k in range(4):
        want = top_down_pose(xyz, yaw + k * math.pi / 2)
        np.testing.assert_allclose(world_tcp(by_name[f"top{k}"], xyz, yaw), want, atol=1e-12)
    np.testing.assert_allclose(world_approach(by_name["top0"], yaw), (0, 0, -1))


def test_a_7cm_by_3cm_cuboid_is_held_only_across_its_3cm_side():
    found = grasps("cuboid", BAR)
    assert [g.width for g in found] == pytest.approx([0.03] * len(found))
    assert _names(grasps("cuboid", BAR, ("top",))) == {"top0", "top2"}
    side = {g.name for g in found if g.name.startswith("side")}
    assert side == {f"side{s}{r}" for s in ("+x", "-x") for r in ROLLS}
    for g in found:  # the fingers close along the object's y
        assert abs(g.matrix[1, 1]) == pytest.approx(1.0)


def test_a_cylinder_needs_two_top_yaws_and_keeps_four_approach_directions():
    found = grasps("cylinder", CAN)
    assert _names(grasps("cylinder", CAN, ("top",))) == {"top0", "top1"}
    for family in ("side", "tilt"):
        approaches = {g.approach for g in found if g.name.startswith(family)}
        assert len(approaches) == 4
    assert [g.width for g in found] == pytest.approx([0.04] * len(found))


def test_top_grasps_hold_a_tall_object_by_its_upper_part():
    for half in (CUBE, CAN):
        top0 = grasps("cuboid", half, ("top",))[0]
        depth = half[2] - top0.matrix[2, 3]  # TCP below the top
        assert depth == pytest.approx(min(GRASP_DEPTH, half[2]))
        assert back_out(top0, half) == pytest.approx(depth)  # back up to the top face


def test_side_grasps_are_horizontal_from_the_named_side_and_keep_the_palm_off_the_support():
    for half in (CUBE, CAN):
        for g in grasps("cuboid", half, ("side",)):
            n = {"+x": (1, 0), "-x": (-1, 0), "+y": (0, 1), "-y": (0, -1)}[g.name[4:6]]
            np.testing.assert_allclose(g.approach, (-n[0], -n[1], 0.0), atol=1e-12)
            x_up = g.matrix[2, 0]  # tool x's height: +1 as is, -1 flipped
            assert x_up == pytest.approx(-1.0 if g.name.endswith(":flip") else 1.0)
            z = g.matrix[2, 3]
            assert z <= half[2] - PAD_OVERLAP + 1e-9  # the pads reach the object
            assert z - 0.03 >= -half[2] + SIDE_CLEARANCE - 1e-9  # the palm above the support
            inward = float(np.dot(g.matrix[:2, 3], n))  # the TCP inside the face n
            assert half[0] - inward == pytest.approx(min(GRASP_DEPTH, half[0]))


def test_tilted_grasps_come_in_at_45_degrees_to_the_top_edge():
    for g in grasps("cube", CUBE, ("tilt",)):
        a = np.asarray(g.approach)
        assert a[2] == pytest.approx(-math.sqrt(0.5))
        edge = g.matrix[:3, 3] - GRASP_DEPTH * a  # back out along the approach
        n = -a[:2] / np.linalg.norm(a[:2])
        np.testing.assert_allclose(edge, (*(0.025 * n), 0.025), atol=1e-12)


def test_too_wide_or_too_flat_objects_have_no_grasps():
    assert grasps("cuboid", (0.05, 0.05, 0.05)) == ()  # 10 cm across every way
    assert grasps("cuboid", (0.03, 0.03, 0.008)) == ()  # 1.6 cm flat: fingertips on the table
    assert _names(grasps("cuboid", (0.03, 0.03, 0.01))) == {f"top{k}" for k in range(4)}


def test_bad_input_raises_naming_the_options():
    with pytest.raises(MotionError, match="cube, cuboid, cylinder"):
        grasps("sphere", CUBE)
    with pytest.raises(MotionError, match="top, side, tilt"):
        grasps("cube", CUBE, ("top", "pinch"))
    with pytest.raises(MotionError, match="half"):
        grasps("cube", (0.025, 0.025))
    with pytest.raises(MotionError, match="half"):
        grasps("cube", (0.025, -0.025, 0.025))
