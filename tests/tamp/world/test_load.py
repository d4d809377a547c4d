"""Scene files (`tamp.world.load`): the shipped scenes match `tamp.obstacles`, round trips, and
every kind of bad file gets one line naming the field and the problem."""

from __future__ import annotations

import copy
import json

import pytest

from tamp.obstacles import SCENES, with_scene
from tamp.scene import SceneConfig
from tamp.world import (
    SceneFileError,
    load_named,
    load_scene,
    named_scenes,
    save_scene,
    scene_config,
    scene_dict,
)
from tamp.world.load import MAX_REACH, MIN_REACH


def cube(name, x, y, z, size=0.05, yaw=0.0):
    return {
        "name": name,
        "kind": "cube",
        "size": size,
        "colour": "red",
        "pose": {"xyz": [x, y, z], "yaw": yaw},
    }


def scene(*objects, regions=(), obstacles=()):
    return {
        "schema": 1,
        "name": "test",
        "table": {"min": [-0.3, -0.7], "max": [1.0, 0.7]},
        "regions": list(regions),
        "obstacles": list(obstacles),
        "objects": list(objects),
    }


TRAY = {
    "name": "tray",
    "min": [0.45, 0.15],
    "max": [0.65, 0.35],
    "wall_height": 0.03,
    "wall_thickness": 0.01,
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_each_named_scene_ships_as_a_file_that_matches_tamp_obstacles(name):
    """The shipped file cannot drift from the obstacles and slot grid the loop uses today."""
    loaded = load_named(name)
    assert loaded.name == name
    assert loaded.obstacles == SCENES[name]
    assert scene_config(loaded) == with_scene(SceneConfig(), name)


def test_every_shipped_scene_loads_and_round_trips(tmp_path):
    assert set(SCENES) <= set(named_scenes())
    for name in named_scenes():
        s = load_named(name)
        assert load_scene(scene_dict(s)) == s
        assert load_scene(save_scene(s, tmp_path / f"{name}.json")) == s


def test_a_scene_with_every_field_round_trips(tmp_path):
    data = scene(
        cube("a", 0.45, -0.2, 0.025),
        {
            "name": "c",
            "kind": "cylinder",
            "size": [0.05, 0.06],
            "colour": [0.2, 0.3, 0.4],
            "pose": {"xyz": [0.55, 0.25, 0.03]},
        },
        {
            "name": "d",
            "kind": "cuboid",
            "size": [0.04, 0.08, 0.04],
            "colour": "green",
            "pose": {"xyz": [0.6, -0.05, 0.02], "yaw": 0.3},
        },
        regions=[TRAY, {"name": "plate", "min": [0.3, 0.3], "max": [0.4, 0.4], "floor": 0.01}],
        obstacles=[{"name": "post", "centre": [0.7, 0.0, 0.05], "half": [0.02, 0.02, 0.05]}],
    )
    data["camera"] = {"eye": [1.2, -0.4, 0.8], "target": [0.5, 0.0, 0.1], "fovy": 50.0}
    data["slots"] = {"xs": [0.4], "ys": [-0.3, 0.0]}
    data["parking"] = False
    s = load_scene(data)
    assert s.camera.fovy == 50.0 and s.camera.width == 320 and s.parking is False
    assert s.region("plate").surface == pytest.approx(0.01)
    assert load_scene(scene_dict(s)) == s
    assert load_scene(save_scene(s, tmp_path / "s.json")) == s


def _fault(data) -> str:
    with pytest.raises(SceneFileError) as err:
        load_scene(data)
    message = str(err.value)
    assert "\n" not in message
    return message


GOOD = scene(cube("a", 0.5, 0.0, 0.025), cube("b", 0.5, 0.0, 0.075), regions=[TRAY])


def _with(path, value):
    """GOOD with the field at ``path`` (keys and list indices) set to ``value`` (or deleted
    when ``value`` is `KeyError`)."""
    data = copy.deepcopy(GOOD)
    node = data
    for key in path[:-1]:
        node = node[key]
    if value is KeyError:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return data


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        (("table",), KeyError, r"^scene: table: missing \(required: name, schema, table\)"),
        (("colour",), "red", r"colour: unknown field \(valid: camera, name, objects, obstacles"),
        (("objects", 0, "pose"), KeyError, r"objects\[0\] \(a\)\.pose: missing"),
        (("objects", 0, "mass"), 1.0, r"objects\[0\] \(a\)\.mass: unknown field \(valid: colour"),
        (("schema",), 2, r"schema: unknown version 2 \(this code reads version 1\)"),
        (("schema",), "1", r"schema: unknown version '1'"),
        (("objects", 0, "size"), "big", r"objects\[0\] \(a\)\.size: expected a number, got"),
        (("objects", 0, "size"), -0.05, r"objects\[0\] \(a\)\.size: must be > 0.0"),
        (("objects", 0, "pose", "xyz"), [0.5, 0.0], r"objects\[0\] \(a\)\.pose\.xyz: expected a"),
        (("objects", 0, "kind"), "sphere", r"kind: unknown kind 'sphere' \(valid: cube, cuboid"),
        (("objects", 0, "colour"), "teal", r"colour: unknown colour 'teal' \(valid: red, blue"),
        (("objects", 0, "colour"), [0, 0, 2], r"colour: RGB values lie in \[0, 1\]"),
        (("objects", 0, "name"), "A b", r"objects\[0\] \(A b\)\.name: expected a PDDL name"),
        (("objects", 0, "name"), "table", r"name: 'table' is reserved"),
        (
            ("objects", 1, "name"),
            "a",
            r"objects\[1\]\.name: 'a' is already the name of objects\[0\]",
        ),
        (("objects", 1, "name"), "tray", r"'tray' is already the name of regions\[0\]"),
        (("regions",), {}, r"^scene: regions: expected a list, got an object"),
        (("regions", 0, "max"), [1.2, 0.35], r"regions\[0\] \(tray\)\.max: .* outside the table"),
        (("regions", 0, "on"), "shelf", r"regions\[0\] \(tray\)\.on: unknown obstacle 'shelf'"),
        (("regions", 0, "wall_thickness"), 0.2, r"wall_thickness: 0.2 m walls leave no room"),
        (("camera",), {"eye": [1, 0, 1]}, r"camera\.target: missing"),
        (("parking",), "no", r"^scene: parking: expected true or false, got 'no'"),
    ],
)
def test_bad_fields_get_one_line_naming_the_field(path, value, expected):
    assert load_scene(GOOD).objects[1].name == "b"  # the unchanged scene loads
    import re

    assert re.search(expected, _fault(_with(path, value)))


@pytest.mark.parametrize(
    ("objects", "expected"),
    [
        (
            [cube("a", 0.5, 0.0, 0.025), cube("b", 0.52, 0.0, 0.025)],
            r"objects\[0\] \(a\)\.pose\.xyz: a overlaps b by 30 mm",
        ),
        (
            [cube("a", 0.5, 0.0, 0.025), cube("b", 0.5, 0.0, 0.065)],
            r"objects\[1\] \(b\)\.pose\.xyz: b sunk into a by 10 mm",
        ),
        ([cube("a", 0.5, 0.0, 0.045)], r"objects\[0\] \(a\)\.pose\.xyz: floats, its bottom 20 mm"),
        (
            [cube("a", 0.5, 0.0, 0.025), cube("b", 0.5, 0.0, 0.1)],
            r"\(b\)\.pose\.xyz: floats, its bottom 25 mm above a",
        ),
        ([cube("a", 0.5, 0.0, 0.015)], r"\(a\)\.pose\.xyz: sunk 10 mm into the table"),
        (
            [cube("a", 0.5, 0.0, 0.025), cube("b", 0.535, 0.0, 0.075)],
            r"\(b\)\.pose\.xyz: tips off a: its centre is not over it",
        ),
        ([cube("a", 1.2, 0.0, 0.025)], r"\(a\)\.pose\.xyz: \(1\.200, 0\.000\) lies off the table"),
        ([cube("a", 0.85, 0.0, 0.025)], r"\(a\)\.pose\.xyz: out of the arm's reach, 0\.850 m"),
        ([cube("a", 0.1, 0.1, 0.025)], r"\(a\)\.pose\.xyz: out of the arm's reach, 0\.141 m"),
        ([cube("a", 0.455, 0.25, 0.025)], r"\(a\)\.pose\.xyz: a overlaps tray:wall_x0"),
    ],
)
def test_bad_geometry_gets_one_line_naming_the_object(objects, expected):
    import re

    assert re.search(expected, _fault(scene(*objects, regions=[TRAY])))


@pytest.mark.parametrize(
    ("lo", "hi", "expected"),
    [
        (
            [0.85, -0.1],
            [0.95, 0.1],
            r"regions\[0\] \(far\): out of the arm's reach, its nearest "
            r"point 0\.850 m from the robot base's axis \(the Panda reaches 0\.25 to 0\.78 m\)",
        ),
        ([0.6, 0.55], [0.9, 0.65], r"\(far\): out of the arm's reach, its nearest point 0\.814 m"),
        ([0.0, -0.1], [0.15, 0.1], r"\(far\): out of the arm's reach, its farthest 0\.180 m"),
    ],
)
def test_a_region_wholly_out_of_reach_is_refused(lo, hi, expected):
    import re

    region = {"name": "far", "min": lo, "max": hi}
    assert re.search(expected, _fault(scene(cube("a", 0.5, 0.0, 0.025), regions=[region])))


@pytest.mark.parametrize(
    ("lo", "hi"),
    [([0.7, -0.1], [0.95, 0.1]), ([0.1, -0.3], [0.3, -0.2]), ([0.0, -0.25], [0.15, 0.25])],
)
def test_a_region_partly_within_reach_loads(lo, hi):
    region = {"name": "part", "min": lo, "max": hi}
    assert load_scene(scene(cube("a", 0.5, 0.0, 0.025), regions=[region])).regions[0].lo == tuple(
        lo
    )


BIN = {"name": "bin", "min": [0.45, 0.15], "max": [0.65, 0.35], "wall_height": 0.01}  # low


@pytest.mark.parametrize("x", [0.45 - 0.025, 0.45 - 0.024, 0.46 + 0.025, 0.46 + 0.024])
def test_an_object_touching_a_bins_wall_from_the_side_loads(x):
    """A cube taller than the bin's wall, beside it outside or inside, touching its x0 wall
    exactly or 1 mm into it (within the overlap tolerance)."""
    loaded = load_scene(scene(cube("a", x, 0.25, 0.025), regions=[BIN]))
    assert loaded.objects[0].pose.xyz[0] == x


@pytest.mark.parametrize(
    ("x", "z", "expected"),
    [
        (0.45 - 0.021, 0.025, r"\(a\)\.pose\.xyz: a overlaps bin:wall_x0 by 4 mm"),
        (0.46 + 0.021, 0.025, r"\(a\)\.pose\.xyz: a overlaps bin:wall_x0 by 4 mm"),
        (0.455, 0.031, r"\(a\)\.pose\.xyz: a sunk into bin:wall_x0 by 4 mm"),
    ],
)
def test_a_bins_wall_overlapped_from_the_side_or_sunk_into_from_above(x, z, expected):
    """Beside the low wall, 4 mm into it: an overlap (not "sunk into", though the cube's centre
    is above the wall's top); standing on the wall with its bottom 4 mm inside it: sunk."""
    import re

    assert re.search(expected, _fault(scene(cube("a", x, 0.25, z), regions=[BIN])))


def test_the_reach_bounds_come_from_the_arm():
    """Out to the far row of ``cramped`` (0.72 m) is reachable; the Panda's top-down IK fails
    beyond 0.8 m at table height (see `tamp.world.load`)."""
    assert MIN_REACH < 0.40 and 0.74 < MAX_REACH <= 0.80
    load_scene(scene(cube("a", 0.72, 0.12, 0.025)))


def test_an_object_out_of_an_obstacle_is_an_overlap():
    post = {"name": "post", "centre": [0.5, 0.0, 0.075], "half": [0.015, 0.015, 0.075]}
    message = _fault(scene(cube("a", 0.5, 0.03, 0.025), obstacles=[post]))
    assert "objects[0] (a).pose.xyz: a overlaps post by" in message


def test_a_file_that_is_not_json_or_missing(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"schema": 1,')
    with pytest.raises(SceneFileError, match=r"bad\.json: not JSON: .* at line 1"):
        load_scene(bad)
    with pytest.raises(SceneFileError, match=r"nope\.json: cannot read the scene file"):
        load_scene(tmp_path / "nope.json")
    good = tmp_path / "good.json"
    good.write_text(json.dumps(GOOD))
    assert [o.name for o in load_scene(good).objects] == ["a", "b"]
    with pytest.raises(SceneFileError, match=r"unknown scene 'attic' \(valid: clutter, cramped"):
        load_named("attic")


def test_a_region_on_an_obstacle_takes_its_top():
    board = {"name": "board", "centre": [0.5, 0.3, 0.2], "half": [0.1, 0.1, 0.01]}
    shelf = {"name": "shelf", "min": [0.45, 0.25], "max": [0.55, 0.35], "on": "board"}
    s = load_scene(scene(cube("a", 0.5, 0.3, 0.235), regions=[shelf], obstacles=[board]))
    assert s.region("shelf").surface == pytest.approx(0.21)
    wide = dict(shelf, max=[0.65, 0.35])
    message = _fault(scene(regions=[wide], obstacles=[board]))
    assert "regions[0] (shelf): the rectangle reaches beyond the top of obstacle 'board'" in message
