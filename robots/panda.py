"""The Franka Emika Panda: joint names, datasheet limits, home pose, TCP frame, gripper stroke.

One description serves IK (`motion`), trajectory limits (`motion.trajectory`) and both simulator
loaders (`robots.pybullet_loader`, `robots.mujoco_loader`). The URDF and its meshes are the ones
shipped in the installed ``pybullet_data`` package; nothing is copied into this repository.

Limits are the Franka datasheet / libfranka values (tighter than the URDF's hard limits, which
appear there only as ``safety_controller`` soft limits).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from robots.errors import RobotError

J = 7  # arm joints


@dataclass(frozen=True)
class PandaSpec:
    """The Panda arm and its parallel gripper. Per-joint tuples have length J = 7."""

    arm_joints: tuple[str, ...] = tuple(f"panda_joint{i}" for i in range(1, 8))
    finger_joints: tuple[str, str] = ("panda_finger_joint1", "panda_finger_joint2")
    base_link: str = "panda_link0"
    tcp_link: str = "panda_grasptarget"  # 0.105 m past panda_hand, between the fingertips
    q_min: tuple[float, ...] = (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973)
    q_max: tuple[float, ...] = (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973)
    v_max: tuple[float, ...] = (2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61)  # rad/s
    a_max: tuple[float, ...] = (15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0)  # rad/s^2
    j_max: tuple[float, ...] = (7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0)
    effort: tuple[float, ...] = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)  # Nm
    q_home: tuple[float, ...] = (0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785)
    finger_open: float = 0.04  # m per finger; stroke 0.08 m
    finger_effort: float = 20.0  # N per finger (URDF effort)
    urdf_relpath: str = "franka_panda/panda.urdf"

    def clamp_error(self, q) -> str | None:
        """A one-line description of the first joint outside the datasheet limits, or None."""
        for i, (v, lo, hi) in enumerate(zip(q, self.q_min, self.q_max, strict=True)):
            if not lo - 1e-6 <= v <= hi + 1e-6:
                return f"{self.arm_joints[i]} = {v:.4f} rad outside [{lo}, {hi}]"
        return None


PANDA = PandaSpec()


def data_dir() -> Path:
    """The installed ``pybullet_data`` folder that holds the Panda URDF and meshes."""
    try:
        import pybullet_data
    except ImportError:
        raise RobotError(
            "the Panda URDF comes from the pybullet package: pip install pybullet"
        ) from None
    return Path(pybullet_data.getDataPath())


def urdf_path(spec: PandaSpec = PANDA) -> Path:
    """Path of the Panda URDF inside ``pybullet_data``; raises RobotError when it is missing."""
    path = data_dir() / spec.urdf_relpath
    if not path.is_file():
        raise RobotError(f"Panda URDF not found at {path} (is pybullet installed intact?)")
    return path
