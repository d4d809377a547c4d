"""The arm's default speeds (fractions of the Panda datasheet, `motion.trajectory`) keep the
friction grasp: a block lifted off the table, carried at transit speed and put on a two-block
tower stays in the fingers (the finger checks after lift and transit pass) and lands where it
was to go, in each simulator, with the whole pick-and-place under 4 s of simulated time."""

from __future__ import annotations

import numpy as np
import pytest

from motion.ik import IKSolver
from tamp.loop.execute import ExecTools, execute_move
from tamp.scene import SceneConfig, layout
from tamp.sim import SIMULATORS, make_simulator
from task.problem import TABLE, Move

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def solver():
    return IKSolver()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_block_carried_at_the_default_speeds_stays_in_the_friction_grasp(sim_name, solver):
    scene = SceneConfig()
    entities, supports = ("a", "b", "c"), (TABLE, TABLE, "b")
    poses = layout(entities, supports, scene, seed=0)
    with make_simulator(sim_name, entities, poses, scene, "friction") as sim:
        done = execute_move(sim, Move("a", "c"), sim.truth.block_poses, ExecTools(solver))
        assert done.ok, (done.failure, done.evidence)
        assert done.sim_time_s < 4.0
        assert done.evidence["tracking_rad"] < 0.1
        after = sim.truth.block_poses()
        np.testing.assert_allclose(after["a"].xy, after["c"].xy, atol=0.01)
        assert abs(after["a"].xyz[2] - after["c"].xyz[2] - scene.block_size) < 0.005
