"""The symbolic state read from a scene's geometry (`tamp.world.relations`) and goals over a
scene (`tamp.world.goal`)."""

from __future__ import annotations

import pytest

from tamp.world import (
    SceneFileError,
    Tolerances,
    load_goal,
    load_named,
    load_scene,
    parse_goal,
    read_facts,
)
from tamp.world.schema import Scene
from tests.tamp.world.test_load import TRAY, cube, scene


def facts_of(*objects, regions=(), obstacles=()):
    return read_facts(load_scene(scene(*objects, regions=regions, obstacles=obstacles)))


def test_a_tower_of_three():
    f = facts_of(
        cube("a", 0.5, 0.0, 0.025),
        cube("b", 0.502, 0.003, 0.075, yaw=0.2),
        cube("c", 0.499, -0.002, 0.125, yaw=-0.1),
    )
    assert f.atoms == {("ontable", "a"), ("on", "b", "a"), ("on", "c", "b"), ("clear", "c")}
    assert f.supports == (("a", "table"), ("b", "a"), ("c", "b"))
    assert f.unexplained == () and f.issues == ()
    assert f.text().splitlines() == ["(clear c)", "(on b a)", "(on c b)", "(ontable a)"]


def test_an_object_in_a_tray_and_one_on_the_table_beside_it():
    f = facts_of(cube("a", 0.55, 0.25, 0.025), cube("b", 0.55, 0.0, 0.025), regions=[TRAY])
    assert f.atoms == {("in", "a", "tray"), ("ontable", "b"), ("clear", "a"), ("clear", "b")}
    assert f.supports == (("a", "tray"), ("b", "table"))


def test_a_block_on_a_block_in_a_tray_is_on_it_not_in_the_tray():
    f = facts_of(cube("a", 0.55, 0.25, 0.025), cube("b", 0.55, 0.25, 0.075), regions=[TRAY])
    assert f.atoms == {("in", "a", "tray"), ("on", "b", "a"), ("clear", "b")}


@pytest.mark.parametrize("inner_first", [False, True])
def test_nested_regions_read_the_same_whatever_their_order(inner_first):
    """An object in an alcove marked inside a larger area is in both, its support the alcove
    (the inner one); one in the area's free part is in the area alone."""
    desk = {"name": "desk", "min": [0.35, -0.3], "max": [0.65, 0.3]}
    nook = {"name": "nook", "min": [0.45, 0.1], "max": [0.55, 0.2]}
    regions = [nook, desk] if inner_first else [desk, nook]
    f = facts_of(cube("a", 0.5, 0.15, 0.025), cube("b", 0.5, -0.15, 0.025), regions=regions)
    assert f.atoms == {("in", "a", "nook"), ("in", "a", "desk"), ("in", "b", "desk")} | {
        ("clear", "a"),
        ("clear", "b"),
    }
    assert f.supports == (("a", "nook"), ("b", "desk"))


def test_an_object_on_a_trays_wall_is_not_in_it():
    """A wide cuboid lying across the tray's x0 wall top (its centre over the wall)."""
    lid = {
        "name": "lid",
        "kind": "cuboid",
        "size": [0.03, 0.1, 0.02],
        "colour": "blue",
        "pose": {"xyz": [0.455, 0.25, 0.04]},
    }
    f = facts_of(lid, regions=[TRAY])
    assert ("in", "lid", "tray") not in f.atoms
    assert f.unexplained == ("lid",)
    assert f.issues == (
        "object lid rests on tray:wall_x0: a region's wall is no support a plan can name",
    )
    assert f.atoms == {("clear", "lid")}


def test_a_marked_area_without_walls_needs_the_whole_footprint_inside():
    mat = {"name": "mat", "min": [0.45, 0.15], "max": [0.65, 0.35]}
    f = facts_of(cube("a", 0.5, 0.2, 0.025), cube("b", 0.46, 0.3, 0.025), regions=[mat])
    assert ("in", "a", "mat") in f.atoms
    assert ("ontable", "b") in f.atoms and ("in", "b", "mat") not in f.atoms


def test_observed_poses_may_cross_a_regions_edge_by_the_edge_tolerance():
    """A cube 0.5 mm inside a marked area's edge, then 1 mm and 3 mm over it: a file reads it
    in only when inside; observed poses (`Tolerances.edge`, 2 mm) also 1 mm over, not 3 mm."""
    mat = {"name": "mat", "min": [0.45, 0.15], "max": [0.65, 0.35]}
    sensed = Tolerances(z=0.012, overlap=0.004, edge=0.002)
    for over, in_file, in_sensed in (
        (0.0, True, True),
        (0.0015, False, True),
        (0.0035, False, False),
    ):
        s = load_scene(scene(cube("a", 0.4755 - over, 0.25, 0.025), regions=[mat]))
        assert (("in", "a", "mat") in read_facts(s).atoms) is in_file, over
        assert (("in", "a", "mat") in read_facts(s, sensed).atoms) is in_sensed, over


def test_a_plate_is_a_raised_region_and_a_cube_on_a_post_is_unexplained():
    plate = {"name": "plate", "min": [0.45, 0.15], "max": [0.55, 0.25], "floor": 0.01}
    post = {"name": "post", "centre": [0.4, -0.2, 0.05], "half": [0.03, 0.03, 0.05]}
    f = facts_of(
        cube("a", 0.5, 0.2, 0.035), cube("b", 0.4, -0.2, 0.125), regions=[plate], obstacles=[post]
    )
    assert ("in", "a", "plate") in f.atoms
    assert f.unexplained == ("b",)
    assert "an obstacle's top" in f.issues[0]


def test_observed_poses_read_with_looser_tolerances():
    """A block resting 8 mm high (a noisy observation) is refused by the file's 5 mm but read
    with `tamp.scene`'s 12 mm."""
    data = scene(cube("a", 0.5, 0.0, 0.025), cube("b", 0.5, 0.0, 0.083))
    with pytest.raises(SceneFileError, match="floats"):
        load_scene(data)
    loose = Tolerances(z=0.012)
    assert ("on", "b", "a") in read_facts(load_scene(data, loose), loose).atoms


def test_the_shipped_tray_scene():
    s = load_named("tray")
    assert read_facts(s).atoms >= {("in", "c", "tray"), ("on", "b", "a"), ("ontable", "d")}


TRAY_SCENE = load_scene(
    scene(cube("a", 0.55, 0.25, 0.025), cube("b", 0.5, 0.0, 0.025), regions=[TRAY])
)


def test_goals_inline_and_from_files(tmp_path):
    goal = parse_goal("(and (on a b) (in b tray))", TRAY_SCENE)
    assert goal.atoms == (("on", "a", "b"), ("in", "b", "tray"))
    facts = read_facts(TRAY_SCENE)
    assert goal.unmet(facts) == goal.atoms and not goal.holds(facts)
    assert parse_goal("(IN A TRAY) ; already true", TRAY_SCENE).holds(facts)
    bare = tmp_path / "goal.pddl"
    bare.write_text("(and (ontable a)\n (clear b))\n")
    assert load_goal(str(bare), TRAY_SCENE).atoms == (("ontable", "a"), ("clear", "b"))
    problem = tmp_path / "problem.pddl"
    problem.write_text(
        "(define (problem p) (:domain d) (:objects a b)\n (:init (ontable a))\n"
        " (:goal (and (on b a))))\n"
    )
    assert load_goal(problem, TRAY_SCENE).atoms == (("on", "b", "a"),)
    assert load_goal(" (on a b)", TRAY_SCENE).text() == "(and (on a b))"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("(on a c)", r"^goal: \(on a c\): unknown object 'c' \(valid: a, b\)$"),
        ("(in a box)", r"^goal: \(in a box\): unknown region 'box' \(valid: tray\)$"),
        ("(on a tray)", r"'tray' is a region, on takes \(object object\); objects: a, b$"),
        ("(in a b)", r"'b' is an object, in takes \(object region\); regions: tray$"),
        ("(onn a b)", r"unknown predicate 'onn' \(valid: clear, in, on, ontable\)$"),
        ("(on a)", r"on takes 2 argument\(s\) \(object object\), got 1$"),
        ("(on a a)", r"an object cannot be on itself$"),
        ("(and (on a b) (not (clear b)))", r"\(not \(clear b\)\): a goal is an atom or \(and"),
        ("(and (on a b)", r"unbalanced parentheses \(a '\)' is missing\)"),
        ("(on a b))", r"text after the goal: '\)'"),
        ("(and)", r"the goal is empty"),
        ("on", r"expected an atom such as \(on a b\), got 'on'"),
    ],
)
def test_bad_goals_get_one_line_listing_the_valid_names(text, expected):
    import re

    with pytest.raises(SceneFileError) as err:
        parse_goal(text, TRAY_SCENE)
    assert "\n" not in str(err.value)
    assert re.search(expected, str(err.value)), str(err.value)


def test_a_missing_goal_file(tmp_path):
    with pytest.raises(SceneFileError, match=r"goal file .*none\.pddl: cannot read it"):
        load_goal(tmp_path / "none.pddl", TRAY_SCENE)


def test_a_goal_without_parentheses_says_what_a_goal_is(tmp_path, monkeypatch):
    """``--goal 'on a b'`` was read as a missing goal file's name."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneFileError) as err:
        load_goal("on a b", TRAY_SCENE)
    message = str(err.value)
    assert "goal 'on a b': a goal is a parenthesised PDDL formula, e.g. '(on a b)'" in message
    assert "or the path of a goal file" in message and "\n" not in message
    assert load_goal(" (on a b)", TRAY_SCENE).atoms == (("on", "a", "b"),)


def test_scene_lookups_list_the_valid_names():
    s: Scene = TRAY_SCENE
    with pytest.raises(SceneFileError, match=r"unknown object 'z' \(valid: a, b\)"):
        s.object("z")
    with pytest.raises(SceneFileError, match=r"unknown region 'z' \(valid: tray\)"):
        s.region("z")
