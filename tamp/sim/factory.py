"""The simulator factory: a backend by name. Backends import `tamp.sim.base`; base imports none
of them, and each backend's simulator module loads only when that backend is chosen."""

from __future__ import annotations

from tamp.sim.base import SIMULATORS, Simulator
from task.errors import TampError, one_of


def make_simulator(name: str, *args, **kwargs) -> Simulator:
    """The backend called ``name`` ('pybullet' or 'mujoco'), built with the given scene."""
    if name == "pybullet":
        from tamp.sim.pybullet_sim import PyBulletSim

        return PyBulletSim(*args, **kwargs)
    if name == "mujoco":
        from tamp.sim.mujoco_sim import MuJoCoSim

        return MuJoCoSim(*args, **kwargs)
    raise TampError(f"unknown simulator {one_of(name, SIMULATORS)}")
