"""A sphere model of the Panda's moving links, for differentiable collision proxies (`motion`).

Each row is (link frame name, sphere centre in that link's URDF frame in m, radius in m). The
numbers are cuRobo's sphere fit to the Franka collision meshes, NVlabs/curobo
``src/curobo/content/configs/robot/spheres/franka_mesh.yml`` (commit 07e6ccf), without its two
``panda_link0`` spheres (the base does not move, so they cost a constant). cuRobo's URDF uses
the same link frames as pybullet_data's ``franka_panda/panda.urdf`` (joint origins from
franka_description; ``panda_hand`` turned -pi/4 about z from ``panda_link8``), so the centres
apply unchanged; tests/motion/test_spheres.py checks them against PyBullet's collision meshes.

The finger spheres are in the finger frames, which sit at ``FINGER_ORIGIN`` above
``panda_hand`` and slide by the finger opening along +y (left) and -y (right).
"""

from __future__ import annotations

FINGER_ORIGIN = 0.0584  # m, z of panda_finger_joint1/2 in panda_hand (panda.urdf)
FINGERS = ("panda_leftfinger", "panda_rightfinger")  # slide along +y and -y of panda_hand

SPHERES: tuple[tuple[str, tuple[float, float, float], float], ...] = (
    ("panda_link1", (0.0, -0.08, 0.0), 0.055),
    ("panda_link1", (0.0, -0.03, 0.0), 0.06),
    ("panda_link1", (0.0, 0.0, -0.12), 0.06),
    ("panda_link1", (0.0, 0.0, -0.17), 0.06),
    ("panda_link2", (0.0, 0.0, 0.03), 0.055),
    ("panda_link2", (0.0, 0.0, 0.08), 0.055),
    ("panda_link2", (0.0, -0.12, 0.0), 0.055),
    ("panda_link2", (0.0, -0.17, 0.0), 0.055),
    ("panda_link3", (0.0, 0.0, -0.06), 0.05),
    ("panda_link3", (0.0, 0.0, -0.1), 0.06),
    ("panda_link3", (0.08, 0.06, 0.0), 0.052),
    ("panda_link3", (0.08, 0.02, 0.0), 0.052),
    ("panda_link4", (0.0, 0.0, 0.02), 0.052),
    ("panda_link4", (0.0, 0.0, 0.06), 0.052),
    ("panda_link4", (-0.08, 0.095, 0.0), 0.055),
    ("panda_link4", (-0.08, 0.06, 0.0), 0.052),
    ("panda_link5", (0.0, 0.03, 0.0), 0.05),
    ("panda_link5", (0.0, 0.082, 0.0), 0.05),
    ("panda_link5", (0.0, 0.0, -0.22), 0.05),
    ("panda_link5", (0.0, 0.052, -0.18), 0.04),
    ("panda_link5", (0.01, 0.08, -0.14), 0.022),
    ("panda_link5", (0.01, 0.085, -0.11), 0.022),
    ("panda_link5", (0.01, 0.09, -0.08), 0.022),
    ("panda_link5", (0.01, 0.095, -0.05), 0.022),
    ("panda_link5", (-0.01, 0.08, -0.14), 0.022),
    ("panda_link5", (-0.01, 0.085, -0.11), 0.022),
    ("panda_link5", (-0.01, 0.09, -0.08), 0.022),
    ("panda_link5", (-0.01, 0.095, -0.05), 0.022),
    ("panda_link5", (0.0, -0.009, 0.0), 0.05),
    ("panda_link6", (0.085, 0.035, 0.0), 0.045),
    ("panda_link6", (0.085, 0.0, 0.0), 0.045),
    ("panda_link6", (0.085, -0.015, 0.0), 0.045),
    ("panda_link7", (0.0, 0.0, 0.07), 0.045),
    ("panda_link7", (0.02, 0.04, 0.08), 0.024),
    ("panda_link7", (0.04, 0.02, 0.08), 0.024),
    ("panda_link7", (0.04, 0.06, 0.085), 0.02),
    ("panda_link7", (0.06, 0.04, 0.085), 0.02),
    *(("panda_hand", (0.0, y, 0.01), 0.023) for y in (-0.075, -0.045, -0.015, 0.015, 0.045, 0.075)),
    *(("panda_hand", (0.0, y, 0.03), 0.022) for y in (-0.08, -0.045, -0.015, 0.015, 0.045, 0.08)),
    *(("panda_hand", (0.0, y, 0.045), 0.022) for y in (-0.08, -0.045, -0.015, 0.015, 0.045, 0.08)),
    ("panda_leftfinger", (0.0, 0.01, 0.043), 0.011),
    ("panda_leftfinger", (0.0, 0.02, 0.015), 0.011),
    ("panda_rightfinger", (0.0, -0.01, 0.043), 0.011),
    ("panda_rightfinger", (0.0, -0.02, 0.015), 0.011),
)
