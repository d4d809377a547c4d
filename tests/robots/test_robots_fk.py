"""The one Panda description, three kinematics: pytorch-kinematics, PyBullet and MuJoCo agree."""

from __future__ import annotations

import numpy as np
import pytest

from robots.errors import RobotError
from robots.panda import PANDA, PandaSpec, urdf_path

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def configs() -> np.ndarray:
    rng = np.random.default_rng(0)
    lo, hi = np.asarray(PANDA.q_min), np.asarray(PANDA.q_max)
    return rng.uniform(lo, hi, size=(8, 7))  # (B, J)


def _pybullet_fk(qs: np.ndarray) -> np.ndarray:
    import pybullet as p

    from robots.pybullet_loader import load_panda

    c = p.connect(p.DIRECT)
    try:
        robot = load_panda(c)
        out = []
        for q in qs:
            for j, v in zip(robot.arm, q, strict=True):
                p.resetJointState(robot.body, j, v, physicsClientId=c)
            state = p.getLinkState(
                robot.body, robot.tcp, computeForwardKinematics=True, physicsClientId=c
            )
            rot = np.asarray(p.getMatrixFromQuaternion(state[5])).reshape(3, 3)
            out.append((np.asarray(state[4]), rot))
        return out
    finally:
        p.disconnect(c)


def _mujoco_fk(qs: np.ndarray) -> list:
    import mujoco

    from robots.mujoco_loader import TCP_SITE, panda_spec

    m = panda_spec().compile()
    d = mujoco.MjData(m)
    adr = [m.joint(j).qposadr[0] for j in PANDA.arm_joints]
    out = []
    for q in qs:
        d.qpos[adr] = q
        mujoco.mj_kinematics(m, d)
        site = m.site(TCP_SITE).id
        out.append((d.site_xpos[site].copy(), d.site_xmat[site].reshape(3, 3).copy()))
    return out


def test_pytorch_kinematics_pybullet_and_mujoco_fk_agree(configs):
    from motion.ik import IKSolver

    ours = IKSolver().fk(configs)  # (B, 4, 4)
    for name, theirs in (("pybullet", _pybullet_fk(configs)), ("mujoco", _mujoco_fk(configs))):
        for k, (pos, rot) in enumerate(theirs):
            np.testing.assert_allclose(pos, ours[k, :3, 3], atol=1e-5, err_msg=name)
            np.testing.assert_allclose(rot, ours[k, :3, :3], atol=1e-5, err_msg=name)


def test_home_pose_puts_the_tcp_in_front_pointing_down():
    from motion.ik import IKSolver

    home = IKSolver().fk(np.asarray(PANDA.q_home))[0]
    np.testing.assert_allclose(home[:3, 3], (0.307, 0.0, 0.485), atol=2e-3)
    assert home[2, 2] < -0.999


def test_datasheet_limits_are_inside_the_urdf_hard_limits():
    assert all(lo < hi for lo, hi in zip(PANDA.q_min, PANDA.q_max, strict=True))
    assert PANDA.clamp_error(PANDA.q_home) is None
    assert "panda_joint4" in PANDA.clamp_error((0, 0, 0, 0.5, 0, 1.5, 0))


def test_mujoco_model_has_the_actuators_and_options_the_grasp_needs():
    import mujoco

    from robots.mujoco_loader import GRIP_ACTUATOR, actuator_name, panda_spec

    m = panda_spec().compile()
    names = {m.actuator(i).name for i in range(m.nu)}
    assert names == {actuator_name(j) for j in PANDA.arm_joints} | {GRIP_ACTUATOR}
    assert m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC and m.opt.impratio >= 10
    assert m.body("panda_grasptarget").id > 0  # static bodies were not fused away


def test_missing_urdf_is_a_clear_error():
    with pytest.raises(RobotError, match="not found"):
        urdf_path(PandaSpec(urdf_relpath="franka_panda/nope.urdf"))
