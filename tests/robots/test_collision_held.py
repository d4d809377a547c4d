"""The held object of the Panda collision model: any box, at any pose relative to the TCP."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robots.collision import Box, PandaCollision
from robots.errors import RobotError
from robots.panda import PANDA

pytestmark = pytest.mark.sim

HOME = np.asarray(PANDA.q_home)
HALF = (0.035, 0.015, 0.06)  # a 7 x 3 x 12 cm box
GAP, FAR = 0.003, 0.02  # m, probes beside each face: within the margin, and well outside it


@pytest.fixture(scope="module")
def pc():
    with PandaCollision(margin=0.005) as model:
        yield model


@pytest.fixture(scope="module")
def tcp_pose() -> np.ndarray:
    """(4, 4) TCP pose at HOME, from a separate PyBullet client."""
    import pybullet as p

    from robots.pybullet_loader import load_panda

    c = p.connect(p.DIRECT)
    robot = load_panda(c)
    for j, v in zip(robot.arm, HOME, strict=True):
        p.resetJointState(robot.body, j, v, physicsClientId=c)
    state = p.getLinkState(robot.body, robot.tcp, computeForwardKinematics=1, physicsClientId=c)
    h = np.eye(4)
    h[:3, :3] = np.reshape(p.getMatrixFromQuaternion(state[5]), (3, 3))
    h[:3, 3] = state[4]
    p.disconnect(c)
    return h


def _upright(xyz, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    h = np.eye(4)
    h[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    h[:3, 3] = xyz
    return h


def _probes(world: np.ndarray, yaw: float, gap: float) -> list[Box]:
    """Thin plates ``gap`` m outside each of the six faces of an upright HALF box at ``world``."""
    out = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            local = np.zeros(3)
            local[axis] = sign * (HALF[axis] + gap + 0.001)
            half = [0.8 * h for h in HALF]
            half[axis] = 0.001
            centre = world[:3, :3] @ local + world[:3, 3]
            out.append(Box(f"p{axis}{'+' if sign > 0 else '-'}", tuple(centre), tuple(half), yaw))
    return out


def test_a_held_box_rides_at_its_pose_relative_to_the_tcp(pc, tcp_pose):
    """An upright 7 x 3 x 12 cm box centred 12 cm below the TCP, turned 0.4 rad (so its pose in
    the TCP frame is a general rotation): every face touches a plate 3 mm outside it, none a
    plate 2 cm out; today's cube at the TCP touches none of them."""
    yaw = 0.4
    world = _upright(tcp_pose[:3, 3] - (0.0, 0.0, 0.12), yaw)
    in_tcp = np.linalg.inv(tcp_pose) @ world
    arm = [("robot", b.name) for b in _probes(world, yaw, GAP)]
    for gap, touched in ((GAP, 6), (FAR, 0)):
        probes = _probes(world, yaw, gap)
        pc.set_boxes(probes)
        pc.hold(half=HALF, pose=in_tcp)
        hits = pc.contacts(HOME, ignore=arm)
        assert {c.part for c in hits} <= {"held"}
        assert len({c.other for c in hits}) == touched, [(c.other, c.distance) for c in hits]
    pc.set_boxes(_probes(world, yaw, GAP))
    pc.hold(0.05)
    assert pc.valid(HOME, ignore=arm)
    pc.hold(None)


def test_half_extents_without_a_pose_are_centred_at_the_tcp_like_a_cube_edge(pc, tcp_pose):
    x, y, z = tcp_pose[:3, 3]
    pc.set_boxes([Box("below", (x, y, z - 0.033 - 0.02), (0.05, 0.05, 0.02))])  # 3 mm under
    pc.hold(0.06)
    edge = pc.contacts(HOME)
    pc.hold(half=(0.03, 0.03, 0.03))
    assert pc.contacts(HOME) == edge and [(c.part, c.other) for c in edge] == [("held", "below")]
    pc.hold(half=(0.03, 0.03, 0.01))  # a flat box of the same footprint stays above the board
    assert pc.valid(HOME)
    pc.hold(None)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"size": 0.05, "half": (0.02, 0.02, 0.02)},
        {"half": (0.02, 0.02)},
        {"half": (0.02, 0.0, 0.02)},
        {"half": (0.02, 0.02, 0.02), "pose": np.eye(3)},
        {"half": (0.02, 0.02, 0.02), "pose": np.diag([1.0, 1.0, -1.0, 1.0])},  # a mirror
        {"half": (0.02, 0.02, 0.02), "pose": np.full((4, 4), np.nan)},
    ],
)
def test_a_malformed_held_box_raises(pc, kwargs):
    with pytest.raises(RobotError):
        pc.hold(**kwargs)
