"""The static goal check of a scene file (`tamp.world.goal_check`): goals no plan can reach are
named before any planning, by the rule a PDDL Blocksworld goal is checked with, and goals that
can be reached pass."""

from __future__ import annotations

import pytest

from tamp.world import load_scene, parse_goal
from tamp.world.goal_check import UnsolvableGoal, check_goal, unsolvable_reason
from tests.tamp.world.test_load import TRAY, cube, scene

NARROW = {"name": "slot", "min": [0.45, -0.35], "max": [0.49, -0.15]}  # 4 cm wide: no cube fits
BIN = {"name": "bin", "min": [0.3, -0.6], "max": [0.4, -0.5]}  # apart from the tray
SMALL = {"name": "small", "min": [0.3, 0.4], "max": [0.41, 0.46]}  # 11 x 6 cm: one cube, not 3


def _scene():
    return load_scene(
        scene(
            cube("a", 0.35, 0.0, 0.025),
            cube("b", 0.45, 0.0, 0.025),
            cube("c", 0.55, 0.0, 0.025),
            regions=[TRAY, NARROW, BIN, SMALL],
        )
    )


@pytest.mark.parametrize(
    ("goal", "expected"),
    [
        ("(and (on a c) (on b c))", "a and b are both on c"),
        ("(and (on a b) (on b a))", "cycle a on b on a"),
        ("(and (on a b) (on b c) (on c a))", "cycle"),
        ("(and (on a b) (on a c))", "a has two supports: b, c"),
        ("(and (on a b) (ontable a))", "a has two supports"),
        ("(and (on a b) (in a tray))", "a has two supports: b, region tray"),
        ("(and (ontable a) (in a tray))", "a has two supports: the table, region tray"),
        ("(and (on a b) (clear b))", "(clear b) with (on a b)"),
        ("(in a slot)", "a's footprint 0.05 x 0.05 m does not fit slot's inner rectangle 0.04"),
        ("(and (in a tray) (in a bin))", "the regions do not nest"),
        ("(and (in a small) (in b small) (in c small))", "a, b, c in small: their footprints"),
    ],
)
def test_a_goal_no_plan_can_reach_is_named_with_the_reason(goal, expected):
    s = _scene()
    reason = unsolvable_reason(s, parse_goal(goal, s))
    assert reason is not None and expected in reason, reason
    with pytest.raises(UnsolvableGoal, match="unsolvable goal: "):
        check_goal(s, parse_goal(goal, s))


@pytest.mark.parametrize(
    "goal",
    [
        "(and (on a b) (on b c))",
        "(and (on a c) (ontable b) (clear a))",
        "(and (in a tray) (in b tray) (on c a))",
        "(in a small)",
        "(and (in a tray) (in b bin))",
    ],
)
def test_a_goal_that_can_be_reached_passes(goal):
    s = _scene()
    goal = parse_goal(goal, s)
    assert unsolvable_reason(s, goal) is None
    assert check_goal(s, goal) == goal


def test_regions_that_nest_may_both_hold_an_object():
    inner = {"name": "alcove", "min": [0.5, 0.2], "max": [0.6, 0.3]}  # inside the tray
    s = load_scene(scene(cube("a", 0.35, 0.0, 0.025), regions=[TRAY, inner]))
    assert unsolvable_reason(s, parse_goal("(and (in a tray) (in a alcove))", s)) is None
