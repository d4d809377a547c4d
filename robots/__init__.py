"""robots: robot descriptions and their per-simulator loaders.

- ``robots.panda``: the Franka Emika Panda (joint names, datasheet limits, home pose, TCP frame,
  gripper stroke; the URDF and meshes shipped with ``pybullet_data``), `PANDA`;
- ``robots.pybullet_loader`` / ``robots.mujoco_loader``: the same description loaded into
  PyBullet (finger gear constraint) or built as a MuJoCo ``MjSpec`` (tendon gripper, gravity
  compensation);
- ``robots.errors.RobotError``: a missing URDF, an unknown joint or link.

No torch and no motion library here; each simulator is imported only by its own loader.
"""
