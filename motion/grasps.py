"""Grasps as choices: how the hand may hold an upright object, each a TCP pose in its frame.

An object's frame has its origin at the object's centre, z up, x and y along its faces (turned
by the object's yaw about the world z). A `Grasp` is the TCP (``panda_grasptarget``) pose in
that frame, the direction the hand comes in along to reach it, and the object's width between
the fingers. `world_tcp` turns a grasp and an object pose into the TCP pose in the base frame.

(Skeleton: the candidate generator `grasps` is being written; see its docstring.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Grasp:
    """How the hand holds an object.

    ``name``: e.g. ``"top0"`` .. ``"top3"`` (top-down, hand yaw k pi/2 in the object frame),
    ``"side+x"`` (from the object's +x side, hand horizontal), ``"tilt+x"``.
    ``tcp``: (4, 4) TCP pose in the object frame, as nested tuples (row-major).
    ``approach``: unit vector in the object frame along which the TCP moves in to the grasp
    (top-down: (0, 0, -1)); the hand backs out along its opposite.
    ``width``: m, the object's extent between the fingers (at most the stroke, 0.08 m).
    """

    name: str
    tcp: tuple[tuple[float, ...], ...]
    approach: tuple[float, float, float]
    width: float

    @property
    def matrix(self) -> np.ndarray:
        """The (4, 4) TCP pose in the object frame."""
        return np.asarray(self.tcp, dtype=np.float64)


def object_frame(xyz, yaw: float) -> np.ndarray:
    """(4, 4) pose of an upright object's frame: its centre ``xyz`` (m), turned ``yaw`` (rad)."""
    c, s = math.cos(yaw), math.sin(yaw)
    h = np.eye(4)
    h[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    h[:3, 3] = np.asarray(xyz, dtype=np.float64)
    return h


def world_tcp(grasp: Grasp, xyz, yaw: float) -> np.ndarray:
    """(4, 4) TCP pose in the base frame holding the object at centre ``xyz``, yaw ``yaw``."""
    return object_frame(xyz, yaw) @ grasp.matrix


def world_approach(grasp: Grasp, yaw: float) -> np.ndarray:
    """(3,) the grasp's approach direction in the base frame for an object turned ``yaw``."""
    return object_frame((0.0, 0.0, 0.0), yaw)[:3, :3] @ np.asarray(grasp.approach)
