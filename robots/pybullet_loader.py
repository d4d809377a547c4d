"""Load the Panda into a PyBullet client: fixed base, finger gear constraint, joint lookup.

The URDF is pybullet_data's ``franka_panda/panda.urdf`` (see `robots.panda`). Joints and links
are found by name, never by hard-coded index.
"""

from __future__ import annotations

from dataclasses import dataclass

import pybullet as p

from robots.errors import RobotError
from robots.panda import PANDA, PandaSpec, data_dir, urdf_path


@dataclass(frozen=True)
class PyBulletPanda:
    """Handles of a loaded Panda: body id, arm joint indices (J,), finger joints, TCP link."""

    client: int
    body: int
    arm: tuple[int, ...]
    fingers: tuple[int, int]
    tcp: int
    gear: int  # the finger gear constraint


def _joint_index(client: int, body: int) -> dict[str, int]:
    """Joint name -> index, and child-link name -> index (a link shares its parent joint's)."""
    names = {}
    for i in range(p.getNumJoints(body, physicsClientId=client)):
        info = p.getJointInfo(body, i, physicsClientId=client)
        names[info[1].decode()] = i
        names[info[12].decode()] = i
    return names


def load_panda(
    client: int, spec: PandaSpec = PANDA, base: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> PyBulletPanda:
    """Load the Panda with a fixed base at ``base`` and put it in ``spec.q_home``, fingers open."""
    p.setAdditionalSearchPath(str(data_dir()), physicsClientId=client)
    body = p.loadURDF(
        str(urdf_path(spec)),
        base,
        useFixedBase=True,
        flags=p.URDF_ENABLE_CACHED_GRAPHICS_SHAPES,
        physicsClientId=client,
    )
    index = _joint_index(client, body)
    wanted = (*spec.arm_joints, *spec.finger_joints, spec.tcp_link)
    missing = [n for n in wanted if n not in index]
    if missing:
        raise RobotError(f"the Panda URDF lacks {missing} (has: {', '.join(sorted(index))})")
    arm = tuple(index[n] for n in spec.arm_joints)
    fingers = (index[spec.finger_joints[0]], index[spec.finger_joints[1]])
    for link in range(-1, p.getNumJoints(body, physicsClientId=client)):
        p.changeDynamics(body, link, linearDamping=0, angularDamping=0, physicsClientId=client)
    # both fingers push on the object with equal force; the gear keeps them centred (bullet3#2101)
    gear = p.createConstraint(
        body,
        fingers[0],
        body,
        fingers[1],
        p.JOINT_GEAR,
        [1, 0, 0],
        [0, 0, 0],
        [0, 0, 0],
        physicsClientId=client,
    )
    p.changeConstraint(gear, gearRatio=-1, erp=0.1, maxForce=50, physicsClientId=client)
    for j, q in zip(arm, spec.q_home, strict=True):
        p.resetJointState(body, j, q, physicsClientId=client)
    for j in fingers:
        p.resetJointState(body, j, spec.finger_open, physicsClientId=client)
    return PyBulletPanda(client, body, arm, fingers, index[spec.tcp_link], gear)
