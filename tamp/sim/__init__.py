"""Simulator backends behind one interface (`tamp.sim.base.Simulator`): PyBullet and MuJoCo.

``make_simulator(name, ...)`` picks one by name; each backend imports its simulator lazily, so
choosing PyBullet never imports MuJoCo and vice versa.

What a simulator offers the robot is what a real robot has: joint positions, the finger sensors
(``gripper()``: opening and the contact force on each finger from whatever it touches) and the
camera (``render()``, ``render_rgbd()``). Its ground truth (block poses, the true state) sits
behind ``sim.truth`` (`tamp.sim.truth.GroundTruth`): simulator ground truth only scores
episodes, and an episode locks it so that any other read raises `GroundTruthLeak`.
"""

from __future__ import annotations

from tamp.sim.base import SIMULATORS, Camera, GripperReading, Simulator
from tamp.sim.factory import make_simulator
from tamp.sim.truth import GroundTruth, GroundTruthLeak

__all__ = [
    "SIMULATORS",
    "Camera",
    "GripperReading",
    "GroundTruth",
    "GroundTruthLeak",
    "Simulator",
    "make_simulator",
]
