"""Best-first search over world states (`tamp.geo.search.plan_search`): the blocked target is
reached by first moving a neighbour; goals no place serves are UNSOLVABLE at once."""

from __future__ import annotations

from dataclasses import replace

import pytest

from tamp.geo.check import check_move
from tamp.geo.places import candidate_places
from tamp.geo.search import SearchConfig, heuristic, plan_search
from tamp.geo.types import TABLE, GeoMove, GeoStatus
from tamp.world.goal import parse_goal
from tamp.world.relations import read_facts
from tests.tamp.geo.geo_scenes import alcove, blocked, cube, scene, tools

pytestmark = pytest.mark.sim
TOP = SearchConfig(choices=("top",), max_time_s=60.0)  # top-down grasps: a small test


def test_the_two_line_symbolic_plan_fails_the_check():
    """What makes the blocked test meaningful: moving the target straight to the region, as a
    purely symbolic plan does, fails at every place and grasp."""
    s = blocked()
    for place in candidate_places(s, "t", "goal", n=TOP.places):
        assert not check_move(s, GeoMove("t", place), tools()).ok


def test_blocked_is_solved_by_moving_a_neighbour_first():
    s = blocked()
    goal = parse_goal("(in t goal)", s)
    plan = plan_search(s, goal, tools(), TOP)
    assert plan.status is GeoStatus.SOLVED, plan.reason
    assert len(plan.moves) == 2
    first, last = plan.moves
    assert first.obj in {"w", "e", "n"} and last.obj == "t"
    assert all(m.grasp is not None for m in plan.moves)
    assert plan.stats["failures"] >= 1 and plan.stats["checks"] > plan.stats["failures"]


@pytest.mark.parametrize("inner_first", [False, True])
def test_nested_regions_are_solved_whatever_order_the_file_lists_them(inner_first):
    """Into the alcove from the desk around it; then a second object into the alcove, the
    first moved out of it into the desk's free part (no parking): the file's order of the two
    regions used to decide which of them an object in the alcove stood in."""
    s = alcove(cube("a", 0.5, -0.15), inner_first=inner_first)
    plan = plan_search(s, parse_goal("(in a alcove)", s), tools(), TOP)
    assert plan.status is GeoStatus.SOLVED, plan.reason
    assert [(m.obj, m.place.target) for m in plan.moves] == [("a", "alcove")]
    s = alcove(cube("a", 0.5, 0.15), cube("b", 0.5, -0.15), inner_first=inner_first)
    goal = parse_goal("(and (in b alcove) (in a desk))", s)
    plan = plan_search(s, goal, tools(), TOP)
    assert plan.status is GeoStatus.SOLVED, plan.reason
    assert [(m.obj, m.place.target) for m in plan.moves] == [("a", "desk"), ("b", "alcove")]


def test_a_region_too_small_for_the_object_is_unsolvable_at_once():
    small = {"name": "small", "min": [0.45, -0.3], "max": [0.49, -0.26]}
    s = scene(cube("a", 0.5, 0.0), regions=[small])
    plan = plan_search(s, parse_goal("(in a small)", s), tools(), TOP)
    assert plan.status is GeoStatus.UNSOLVABLE
    assert "no place of object a fits in region small" in plan.reason
    assert plan.stats["checks"] == 0


def test_a_region_out_of_reach_is_unsolvable():
    """Only the region's near edge lies within the loader's reach (0.78 m from the base's
    axis, so the file loads); no place in it is reachable."""
    far = {"name": "far", "min": [0.78, -0.1], "max": [0.95, 0.1]}
    s = scene(cube("a", 0.5, 0.0), regions=[far])
    plan = plan_search(s, parse_goal("(in a far)", s), tools(), TOP)
    assert plan.status is GeoStatus.UNSOLVABLE
    assert "reachable" in plan.reason


def test_a_tiny_budget_is_budget_not_unsolvable():
    s = blocked()
    plan = plan_search(s, parse_goal("(in t goal)", s), tools(), replace(TOP, max_nodes=1))
    assert plan.status is GeoStatus.BUDGET


def test_the_heuristic_counts_the_objects_that_must_move():
    s = scene(cube("a", 0.5, 0.1), cube("b", 0.5, 0.1, 0.075), cube("c", 0.45, -0.25))
    supports = dict(read_facts(s).supports)
    assert heuristic(supports, parse_goal("(in a goal)", s)) == 2  # a, and b above it
    assert heuristic(supports, parse_goal("(on c a)", s)) == 2  # c, and b above a
    assert heuristic(supports, parse_goal("(on b a)", s)) == 0
    assert heuristic(supports, parse_goal("(clear a)", s)) == 1
    assert heuristic(supports, parse_goal(f"(and (ontable b) (on{' '}c b))", s)) == 2
    assert TABLE == "table"
