"""The experimenter's faults on a simulated world, injected to exercise recovery: `nudge`, a
push of one object, used by both episodes (`tamp.loop.Episode`, `tamp.geo.episode`).

A nudge is the experimenter's act, not the robot's: it reads the pose it perturbs from the
simulator's ground truth inside ``GroundTruth.experimenter()`` and teleports the object.
"""

from __future__ import annotations

import numpy as np

from tamp.scene import Pose
from tamp.sim.base import Simulator


def nudge(sim: Simulator, block: str, distance: float, rng: np.random.Generator) -> None:
    """Injected fault: push ``block`` ``distance`` m in a random direction (one draw from
    ``rng``), off whatever it rests on: it falls to the table next to its support. The
    experimenter reads the block's true pose to do so (``GroundTruth.experimenter()``)."""
    with sim.truth.experimenter():
        pose = sim.truth.block_poses()[block]
    angle = rng.uniform(0, 2 * np.pi)
    x, y, z = pose.xyz
    sim.set_block_pose(
        block, Pose((x + distance * np.cos(angle), y + distance * np.sin(angle), z), pose.yaw)
    )
