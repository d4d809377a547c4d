"""Simulator backends behind one interface (`tamp.sim.base.Simulator`): PyBullet and MuJoCo.

``make_simulator(name, ...)`` picks one by name; each backend imports its simulator lazily, so
choosing PyBullet never imports MuJoCo and vice versa.
"""

from __future__ import annotations

from tamp.sim.base import SIMULATORS, Camera, GripperReading, Simulator
from tamp.sim.factory import make_simulator

__all__ = ["SIMULATORS", "Camera", "GripperReading", "Simulator", "make_simulator"]
