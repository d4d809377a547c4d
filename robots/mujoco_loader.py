"""Build the Panda as a MuJoCo ``MjSpec`` from the same URDF the other loaders use.

MuJoCo does not resolve ``package://`` mesh paths, so the URDF is parsed with ``MjSpec`` and
fixed up (recipe verified in shared/notes/motion-research.md, section 5.1): mesh paths made
absolute, static bodies kept (``panda_hand`` and ``panda_grasptarget`` stay frames), inertia
from geometry (the URDF inertias are placeholders), position actuators on the 7 arm joints,
a fixed-tendon gripper with a joint equality, gravity compensation, and elliptic friction cones
with a high impratio (needed for friction grasps). Callers add the scene, then ``compile()``.
"""

from __future__ import annotations

import os

# MuJoCo picks its GL backend at import: default to headless EGL unless the user chose one
os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco

from robots.panda import PANDA, PandaSpec, urdf_path

ARM_KP = (4500.0, 4500.0, 3500.0, 3500.0, 2000.0, 2000.0, 2000.0)  # as in MuJoCo Menagerie
GRIP_KP = 1000.0  # grip force on the tendon = kp * (target - width/2): about 12 N per finger
TCP_SITE = "tcp"
GRIP_ACTUATOR = "a_grip"


def actuator_name(joint: str) -> str:
    return f"a_{joint}"


def panda_spec(spec: PandaSpec = PANDA, timestep: float = 0.002) -> mujoco.MjSpec:
    """An uncompiled MjSpec with the Panda, its actuators and the physics options set."""
    s = mujoco.MjSpec.from_file(str(urdf_path(spec)))
    root = str(urdf_path(spec).parent)
    for mesh in s.meshes:
        mesh.file = mesh.file.replace("package://", root + "/")
    s.compiler.fusestatic = False
    s.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    s.option.timestep = timestep
    s.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    s.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    s.option.impratio = 10
    for body in s.bodies:
        if body.name.startswith("panda_"):
            body.gravcomp = 1.0
    for name, kp, effort in zip(spec.arm_joints, ARM_KP, spec.effort, strict=True):
        joint = s.joint(name)
        joint.armature = 0.1
        joint.damping = [1.0, 0.0, 0.0]  # MuJoCo 4: polynomial damping, a 3-vector
        act = s.add_actuator(
            name=actuator_name(name), target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT
        )
        act.set_to_position(kp=kp, dampratio=1.0)
        act.forcerange = [-effort, effort]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # gripper as in the Menagerie: a fixed tendon on both fingers instead of the URDF mimic
    for eq in list(s.equalities):
        s.delete(eq)
    f1, f2 = spec.finger_joints
    tendon = s.add_tendon(name="split")
    tendon.wrap_joint(f1, 0.5)
    tendon.wrap_joint(f2, 0.5)
    eq = s.add_equality(
        type=mujoco.mjtEq.mjEQ_JOINT, name1=f1, name2=f2, objtype=mujoco.mjtObj.mjOBJ_JOINT
    )
    eq.data[:5] = [0, 1, 0, 0, 0]
    grip = s.add_actuator(name=GRIP_ACTUATOR, target="split", trntype=mujoco.mjtTrn.mjTRN_TENDON)
    grip.set_to_position(kp=GRIP_KP, dampratio=1.0)
    grip.ctrlrange = [0.0, spec.finger_open]
    grip.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    s.body(spec.tcp_link).add_site(name=TCP_SITE, size=[0.005] * 3)
    return s
