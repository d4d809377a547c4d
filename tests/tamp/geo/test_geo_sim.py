"""A scene file's world in either simulator (`tamp.geo.sim.open_sim`): the scene's objects are
the entities, each with its own solid and colour at its pose; its regions' walls and base slabs
are solid (`tamp.world.load.scene_config`); an unknown backend is one line listing both."""

from __future__ import annotations

import math

import numpy as np
import pytest

from motion.trajectory import JointTrajectory
from robots.panda import PANDA
from tamp.geo.sim import open_sim
from tamp.scene import Body, SceneConfig
from tamp.sim import SIMULATORS
from tamp.sim.base import Camera
from tamp.world.convert.from_poses import read_state
from tamp.world.load import load_scene, scene_config
from task.errors import TampError
from task.problem import TABLE

TRAY = {
    "name": "tray",
    "min": [0.45, 0.15],
    "max": [0.65, 0.35],
    "floor": 0.01,
    "wall_height": 0.03,
    "wall_thickness": 0.01,
}


def _object(name, kind, size, xyz, yaw=0.0, colour="red"):
    return {"name": name, "kind": kind, "size": size, "colour": colour,
            "pose": {"xyz": list(xyz), "yaw": yaw}}  # fmt: skip


SCENE = {
    "schema": 1,
    "name": "bodies",
    "table": {"min": [-0.3, -0.7], "max": [1.0, 0.7]},
    "regions": [TRAY],
    "objects": [
        _object("cube", "cube", 0.03, (0.55, 0.25, 0.01 + 0.015), 0.2, "green"),  # in the tray
        _object("box", "cuboid", [0.04, 0.06, 0.08], (0.5, -0.1, 0.04), 0.3, "blue"),
        _object("disc", "cylinder", [0.06, 0.03], (0.4, -0.3, 0.015), 0.0, [0.2, 0.3, 0.4]),
        _object("top", "cube", 0.03, (0.5, -0.1, 0.08 + 0.015), 0.3),  # on the box
    ],
}


def test_scene_config_has_the_walls_floors_bodies_and_colours_of_the_scene():
    scene = load_scene(SCENE)
    config = scene_config(scene)
    walls = [f"tray:wall_{side}" for side in ("x0", "x1", "y0", "y1")]
    assert [o.name for o in config.obstacles] == [*walls, "tray:floor"]
    assert config.body("box") == Body("cuboid", (0.02, 0.03, 0.04))
    assert config.body("disc") == Body("cylinder", (0.03, 0.03, 0.015))
    assert config.body("cube") == Body("cube", (0.015,) * 3)
    assert [name for name, _ in config.palette] == ["cube", "box", "disc", "top"]
    assert config.palette[2][1] == (0.2, 0.3, 0.4)
    empty = load_scene({**SCENE, "regions": [], "objects": []})
    assert scene_config(empty) == SceneConfig(name="bodies")  # a workcell: base's blocks


def test_an_unknown_backend_is_one_line_listing_both():
    with pytest.raises(TampError, match=r"'gazebo' \(valid: pybullet, mujoco\)"):
        open_sim(load_scene(SCENE), "gazebo")


@pytest.mark.sim
@pytest.mark.parametrize("backend", SIMULATORS)
def test_open_sim_builds_the_scene_s_objects_where_they_are_and_the_tray_holds_its_cube(backend):
    scene = load_scene(SCENE)
    camera = Camera(eye=(1.0, 0.0, 0.8), width=64, height=48)
    with open_sim(scene, backend, camera=camera) as sim:
        assert sim.entities == ("cube", "box", "disc", "top") and sim.camera == camera
        sim.run(JointTrajectory.hold(PANDA.q_home, 1.0, sim.dt), "open")
        after = sim.truth.block_poses()
    for o in scene.objects:
        assert np.abs(np.subtract(after[o.name].xyz, o.pose.xyz)).max() < 0.002, o.name
        assert abs(math.remainder(after[o.name].yaw - o.pose.yaw, math.pi / 2)) < 0.01, o.name
    # the cube rests on the tray's 1 cm floor (without the slab it would sink to z = 0.015)
    assert after["cube"].xyz[2] == pytest.approx(0.025, abs=0.002)
    # the truth reads each body's height: the top cube on the 8 cm box
    others = load_scene({**SCENE, "regions": [], "objects": SCENE["objects"][1:]})
    with open_sim(others, backend) as sim:
        state = read_state(sim.entities, sim.truth.block_poses(), sim.scene).state
    assert state == (TABLE, TABLE, "box")


MAT = {"name": "mat", "min": [0.4, -0.5], "max": [0.6, -0.3], "colour": [0.9, 0.2, 0.2]}


def test_a_region_without_walls_is_a_visual_mark_in_its_colour():
    config = scene_config(load_scene({**SCENE, "regions": [TRAY, MAT]}))
    assert "mat:mark" not in [o.name for o in config.obstacles]  # nothing collides with it
    (mark,) = config.marks  # the tray has walls: no mark
    assert mark.name == "mat:mark" and mark.rgb == (0.9, 0.2, 0.2)
    assert mark.centre[:2] == pytest.approx((0.5, -0.4)) and mark.half[:2] == pytest.approx(
        (0.1, 0.1)
    )
    bottom, top = mark.centre[2] - mark.half[2], mark.centre[2] + mark.half[2]
    assert bottom > 0.0 and top < 0.005  # on the table, under any object's tolerance


@pytest.mark.sim
@pytest.mark.parametrize("backend", SIMULATORS)
def test_a_region_without_walls_shows_in_camera_images_and_collides_with_nothing(backend):
    """Looking straight down at the mat: its colour where it lies, the table's grey without
    it; a cube standing on the table inside the mat's patch (its bottom 2 mm under the patch's
    top) stays at z = its half size: nothing pushes it up onto the patch."""
    camera = Camera(eye=(0.5, -0.4, 0.6), target=(0.5, -0.4, 0.0), up=(1.0, 0.0, 0.0),
                    fovy=20.0, width=32, height=32)  # fmt: skip
    cube = _object("cube", "cube", 0.04, (0.5, -0.4, 0.02))
    seen = {}
    for regions in ([MAT], []):
        scene = load_scene({**SCENE, "regions": regions, "objects": [cube]})
        with open_sim(scene, backend, camera=camera) as sim:
            image = np.asarray(sim.render(), dtype=float)[..., :3] / 255.0
            seen[bool(regions)] = image[4, 16]  # between the image's edge and the cube
            sim.run(JointTrajectory.hold(PANDA.q_home, 0.5, sim.dt), "open")
            assert sim.truth.block_poses()["cube"].xyz[2] == pytest.approx(0.02, abs=0.001)
    table, mat = seen[False], seen[True]
    assert np.ptp(table) < 0.05  # grey
    assert mat[0] - mat[1] > 0.3 and mat[0] - mat[2] > 0.3  # the mat's red
