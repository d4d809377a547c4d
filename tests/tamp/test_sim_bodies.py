"""Objects of any size and shape in both simulators (`tamp.scene.Body`,
``SceneConfig.bodies``): each settles where it was put, stacks of a small object on a big one
stand, the ground truth reports them, and the friction grasp lifts and places a 3 cm and a
7 cm wide cuboid. Masses and yaw readings are checked without a simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from motion.ik import IKSolver, grasp_yaw, pose_yaw
from motion.pick_place import PickPlaceConfig, PickPlaceRequest, plan_pick_place
from motion.trajectory import JointTrajectory
from robots.panda import PANDA
from tamp.scene import Body, Pose, SceneConfig, SceneError
from tamp.sim import SIMULATORS, make_simulator
from tamp.sim.base import MAX_MASS, MIN_MASS, body_mass, body_yaw
from tamp.world.convert.from_poses import read_state
from task.problem import TABLE

BODIES = (
    ("cube", Body("cube", (0.015,) * 3)),  # 3 cm
    ("box", Body("cuboid", (0.02, 0.03, 0.04))),  # 4 x 6 x 8 cm
    ("disc", Body("cylinder", (0.03, 0.03, 0.015))),  # 6 cm across, 3 cm tall
    ("top", Body("cube", (0.015,) * 3)),  # 3 cm, on the box
    ("puck", Body("cylinder", (0.015, 0.015, 0.01))),  # 3 cm across, 2 cm tall, on the disc
)
POSES = {
    "cube": Pose((0.45, -0.25, 0.015), 0.2),
    "box": Pose((0.5, 0.0, 0.04), 0.3),
    "disc": Pose((0.45, 0.25, 0.015), 0.0),
    "top": Pose((0.5, 0.0, 0.08 + 0.015), -0.1),
    "puck": Pose((0.45, 0.25, 0.03 + 0.01), 0.0),
}
SUPPORTS = (TABLE, TABLE, TABLE, "box", "disc")  # entity order


def _rotz(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_a_body_is_a_cube_cuboid_or_upright_cylinder_and_the_default_is_the_scene_s_block():
    config = SceneConfig(bodies=BODIES)
    assert config.body("box") == Body("cuboid", (0.02, 0.03, 0.04))
    assert config.body("other") == Body("cube", (0.025,) * 3) == SceneConfig().default_body
    assert SceneConfig(shape="cylinder").body("x") == Body("cylinder", (0.025,) * 3)
    with pytest.raises(SceneError, match="valid: cube, cuboid, cylinder"):
        Body("sphere", (0.02,) * 3)
    with pytest.raises(SceneError, match="cylinder"):
        Body("cylinder", (0.02, 0.03, 0.01))


def test_masses_follow_the_default_block_s_density_within_bounds():
    big, tiny = Body("cube", (0.1,) * 3), Body("cube", (0.01,) * 3)
    config = SceneConfig(bodies=(*BODIES, ("big", big), ("tiny", tiny)))
    assert body_mass(config, "unlisted") == config.block_mass
    assert body_mass(config, "box") == pytest.approx(0.1 * (4 * 6 * 8) / 125)
    assert body_mass(config, "big") == MAX_MASS  # 8 litres would weigh 6.4 kg
    assert body_mass(config, "tiny") == MIN_MASS  # 8 cm^3 would weigh 6.4 g
    assert body_mass(config, "cube") == pytest.approx(0.1 * 27 / 125)


def test_yaw_readings_fold_each_body_s_symmetry():
    box, cube = Body("cuboid", (0.02, 0.03, 0.04)), Body("cube", (0.02,) * 3)
    assert body_yaw(_rotz(2.0), box) == pytest.approx(2.0 - math.pi)  # half a turn: the same box
    assert body_yaw(_rotz(0.3), box) == pytest.approx(0.3)
    assert body_yaw(_rotz(0.9), cube) == pytest.approx(0.9 - math.pi / 2)
    square = Body("cuboid", (0.02, 0.02, 0.04))  # a square footprint folds like a cube
    assert body_yaw(_rotz(0.9), square) == pytest.approx(0.9 - math.pi / 2)


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_bodies_of_every_size_and_kind_settle_where_they_were_put_and_stay_stacked(sim_name):
    entities = tuple(POSES)
    config = SceneConfig(bodies=BODIES)
    with make_simulator(sim_name, entities, POSES, config) as sim:
        sim.run(JointTrajectory.hold(PANDA.q_home, 1.0, sim.dt), "open")
        after = sim.truth.block_poses()
        state = read_state(entities, after, config).state
        snapshot = sim.truth.snapshot()
    for name, pose in POSES.items():
        assert np.abs(np.subtract(after[name].xyz, pose.xyz)).max() < 0.002, name
        assert abs(math.remainder(after[name].yaw - pose.yaw, math.pi / 2)) < 0.01, name
    assert after["box"].yaw == pytest.approx(0.3, abs=0.01)  # the cuboid's own yaw
    assert state == SUPPORTS
    np.testing.assert_allclose(snapshot.centres, [after[n].xyz for n in entities], atol=1e-9)


HEIGHT, YAW = 0.05, 0.3  # the carried cuboid's height (m) and yaw (rad)
PICK, PLACE = (0.5, 0.1, HEIGHT / 2), (0.45, -0.15, HEIGHT / 2)


@pytest.fixture(scope="module")
def carry():
    """The move of both widths (either cuboid's centre and yaw are the same): the cube move of
    `motion.pick_place` with the object's height as its block size and the hand turned so the
    fingers close along the object's y axis."""
    solver = IKSolver()
    hand = pose_yaw(solver.fk(np.asarray(PANDA.q_home))[0])
    turn = abs(math.remainder(grasp_yaw(YAW, hand) - YAW, math.pi)) > 0.1  # hand y on body y
    request = PickPlaceRequest(PICK, YAW, PLACE, YAW, clear_z=HEIGHT, turn=turn)
    return plan_pick_place(solver, PANDA.q_home, request, PickPlaceConfig(block_size=HEIGHT))


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
@pytest.mark.parametrize("width", [0.03, 0.07])
def test_the_friction_grasp_lifts_and_places_a_narrow_and_a_wide_cuboid(sim_name, width, carry):
    """A 5 cm tall cuboid, ``width`` across the fingers and 4 cm along them, picked top-down,
    carried 25 cm and put down."""
    plan, pick, place, yaw = carry, PICK, PLACE, YAW
    assert plan.ok, plan.evidence
    body = Body("cuboid", (0.02, width / 2, HEIGHT / 2))  # the fingers close along y
    config = SceneConfig(bodies=(("o", body),))
    held = {}
    with make_simulator(sim_name, ("o",), {"o": Pose(pick, yaw)}, config) as sim:
        for phase in plan.phases:
            sim.run(phase.trajectory, phase.gripper)
            if phase.name == "transit":
                held = {"reading": sim.gripper(), "z": sim.truth.block_poses()["o"].xyz[2]}
        end = sim.truth.block_poses()["o"]
    reading = held["reading"]
    assert abs(reading.width - width) < 0.003  # the fingers rest on the object's faces
    assert reading.left_force > 1.0 and reading.right_force > 1.0
    assert held["z"] > pick[2] + 0.1  # carried high above the table
    assert np.abs(np.subtract(end.xyz, place)).max() < 0.003
    assert end.yaw == pytest.approx(yaw, abs=0.03)
