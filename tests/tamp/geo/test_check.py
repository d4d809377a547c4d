"""A move's feasibility (`tamp.geo.check.check_move`): a hemmed-in cube has no grasp, a free
one has, and the verdicts name what failed."""

from __future__ import annotations

import pytest

from tamp.geo.check import candidate_grasps, check_move, transit_heights
from tamp.geo.places import candidate_places
from tamp.geo.types import TABLE, GeoMove, Place
from tamp.outcome import Failure
from tests.tamp.geo.geo_scenes import blocked, cube, scene, tools

pytestmark = pytest.mark.sim


def test_a_grasp_blocked_by_neighbours_is_rejected_on_the_pick_side():
    s = blocked()
    place = candidate_places(s, "t", "goal")[0]
    tops = candidate_grasps(s.object("t"), ("top",))
    verdict = check_move(s, GeoMove("t", place), tools(), grasps=tops)
    assert not verdict.ok and verdict.failure is Failure.COLLISION
    assert len(verdict.tried) == len(tops) == 4
    assert {t.side for t in verdict.tried} == {"pick"}  # whatever the place
    assert {t.other for t in verdict.tried} <= {"w", "e", "n"}
    assert not check_move(s, GeoMove("t", place), tools()).ok  # nor side or tilted grasps


def test_a_free_cube_is_accepted_with_a_grasp_and_phases_to_run():
    s = blocked()
    place = candidate_places(s, "n", TABLE)[0]
    verdict = check_move(s, GeoMove("n", place), tools())
    assert verdict.ok and verdict.failure is None
    assert verdict.grasp is not None
    assert [p.name for p in verdict.motion][:2] == ["approach", "descend"]
    # the grasp that works closes the fingers along x: t sits on n's -y side
    assert verdict.tried[-1].failure is None


def test_a_covered_object_and_an_occupied_place_are_refused_before_any_motion():
    s = scene(cube("a", 0.5, 0.1), cube("b", 0.5, 0.1, 0.075), cube("c", 0.45, -0.25))
    onto_c = candidate_places(s, "b", "c")[0]
    assert check_move(s, GeoMove("a", onto_c), tools()).failure is Failure.NOT_CLEAR
    taken = Place("fake", TABLE, (0.5, 0.1, 0.025))
    assert check_move(s, GeoMove("c", taken), tools()).failure is Failure.UNSUPPORTED


def test_transit_goes_over_what_is_near_its_way_not_the_highest_stack_anywhere():
    tower = [cube(k, 0.45, 0.3, 0.025 + 0.05 * i) for i, k in enumerate("abcd")]
    s = scene(*tower, cube("x", 0.5, -0.05), cube("y", 0.62, -0.05))
    near, every = transit_heights(s, "x", s.object("x").pose.xyz, (0.5, -0.25, 0.025))
    assert near == pytest.approx(0.05) and every == pytest.approx(0.2)
