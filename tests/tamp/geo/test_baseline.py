"""The search-then-check baseline (`tamp.geo.baseline`): it solves the blocked scene too, by
forbidding the symbolic moves it cannot bind and replanning, at more checks than the search."""

from __future__ import annotations

import pytest

from tamp.geo.baseline import apply_symbolic, plan_search_then_check, symbolic_moves, symbolic_plan
from tamp.geo.search import SearchConfig, plan_search
from tamp.geo.types import TABLE, GeoStatus
from tamp.world.goal import parse_goal
from tests.tamp.geo.geo_scenes import alcove, blocked, cube, hemmed, scene, tools

SMALL = SearchConfig(choices=("top",), places=4, max_time_s=60.0)


def test_the_symbolic_search_ignores_geometry_and_honours_constraints():
    s = blocked()
    goal = parse_goal("(in t goal)", s)
    start = tuple((o.name, TABLE) for o in s.objects)
    plan, _ = symbolic_plan(start, goal, ("goal", TABLE), set(), 1000)
    assert plan == [("t", "goal")]  # the two-line plan
    plan, _ = symbolic_plan(start, goal, ("goal", TABLE), {(start, ("t", "goal"))}, 1000)
    assert len(plan) == 2 and plan[-1] == ("t", "goal")
    assert ("t", TABLE) not in symbolic_moves(start, ("goal", TABLE))  # no table-to-table
    assert apply_symbolic(start, ("n", "w"))[3] == ("n", "w")


@pytest.mark.sim
def test_the_baseline_solves_a_hemmed_target_with_more_checks_and_failures_than_the_search():
    s = hemmed()
    goal = parse_goal("(in t goal)", s)
    base = plan_search_then_check(s, goal, tools(), SMALL)
    ours = plan_search(s, goal, tools(), SMALL)
    assert base.status is GeoStatus.SOLVED and ours.status is GeoStatus.SOLVED
    assert len(base.moves) == len(ours.moves) == 2
    assert base.moves[-1].obj == "t"
    assert base.stats["plans"] > 1 and base.stats["constraints"] >= 1
    assert base.stats["checks"] > ours.stats["checks"]
    assert base.stats["failures"] > ours.stats["failures"]


@pytest.mark.sim
def test_the_baseline_says_unsolvable_when_every_symbolic_plan_is_forbidden():
    small = {"name": "small", "min": [0.45, -0.3], "max": [0.49, -0.26]}
    s = scene(cube("a", 0.5, 0.0), regions=[small])
    plan = plan_search_then_check(s, parse_goal("(in a small)", s), tools(), SMALL)
    assert plan.status is GeoStatus.UNSOLVABLE
    assert "no symbolic plan left" in plan.reason


@pytest.mark.sim
@pytest.mark.parametrize("inner_first", [False, True])
def test_the_baseline_places_into_nested_regions_whatever_their_order(inner_first):
    """An object moved from the desk into the alcove marked inside it, and another into the
    alcove once the first has gone to the desk's free part (no parking)."""
    s = alcove(cube("a", 0.5, -0.15), inner_first=inner_first)
    plan = plan_search_then_check(s, parse_goal("(in a alcove)", s), tools(), SMALL)
    assert plan.status is GeoStatus.SOLVED, plan.reason
    s = alcove(cube("a", 0.5, 0.15), cube("b", 0.5, -0.15), inner_first=inner_first)
    goal = parse_goal("(and (in b alcove) (in a desk))", s)
    plan = plan_search_then_check(s, goal, tools(), SMALL)
    assert plan.status is GeoStatus.SOLVED, plan.reason
    assert [(m.obj, m.place.target) for m in plan.moves] == [("a", "desk"), ("b", "alcove")]
