"""The physics step and sleeping: `Simulator.run` takes one physics step of ``physics_dt`` per
``stride`` trajectory samples and commands the last sample each step covers; blocks at rest
sleep in both backends, and a sleeping block is still touched, counted and moved by the arm,
and falls when what it rests on is teleported away."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pybullet as p
import pytest

from motion.ik import IKSolver, top_down_pose
from motion.trajectory import JointTrajectory, straight_segment
from robots.panda import PANDA
from tamp.scene import Pose
from tamp.sim import SIMULATORS, Simulator, make_simulator

A = Pose((0.5, 0.0, 0.025), 0.1)  # a block on the table in front of the robot


@pytest.mark.parametrize("stride", [1, 2, 3])
@pytest.mark.parametrize("samples", [1, 2, 3, 10, 11])
def test_each_physics_step_commands_the_last_sample_it_covers(stride, samples):
    ks = Simulator.commanded(SimpleNamespace(stride=stride), samples)
    assert len(ks) == -(-samples // stride)  # one step per stride samples, rounded up
    assert ks[-1] == samples - 1  # the trajectory's end is commanded
    assert ks[0] == min(stride, samples) - 1
    steps = np.diff(ks)  # samples each step advances
    assert np.all(steps[:-1] == stride) and np.all((steps > 0) & (steps <= stride))


def _asleep(sim: Simulator, name: str) -> bool:
    """Whether block ``name`` sleeps: MuJoCo's body sleep state; Bullet zeroes a sleeping
    body's velocity (an awake resting block jitters at 1e-9 m/s or more)."""
    if sim.name == "mujoco":
        return sim.data.body_awake[sim._block_ids[name]] == 0
    v, w = p.getBaseVelocity(sim.blocks[name], physicsClientId=sim.client)
    return v == w == (0.0, 0.0, 0.0)


def _rest(sim: Simulator, seconds: float) -> None:
    sim.run(JointTrajectory.hold(sim.arm_q(), seconds, sim.dt), "open")


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_run_steps_the_physics_once_per_stride_samples(sim_name):
    with make_simulator(sim_name, ("a",), {"a": A}) as sim:
        assert sim.stride == 2 and sim.physics_dt == pytest.approx(2 * sim.dt)
        hold = JointTrajectory.hold(PANDA.q_home, 0.1, sim.dt)  # 51 samples: 26 steps
        sim.run(hold, "open")
        assert sim.time == pytest.approx(26 * sim.physics_dt)


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_the_arm_pushing_a_sleeping_block_is_counted_and_moves_it(sim_name):
    solver = IKSolver()
    with make_simulator(sim_name, ("a",), {"a": A}) as sim:
        _rest(sim, 2.5)  # Bullet sleeps a body after 2 s at rest, MuJoCo after 10 steps
        assert _asleep(sim, "a")
        x, y = A.xy
        sweep = np.stack([top_down_pose((x, y + dy, 0.04), 0.0) for dy in (-0.12, 0.1)])
        q = solver.solve(sweep, sim.arm_q()).q  # (2, J): beside the block, past it
        over = solver.solve(top_down_pose((x, y - 0.12, 0.3), 0.0)[None], sim.arm_q()).q[0]
        for a, b in ((sim.arm_q(), over), (over, q[0]), (q[0], q[1])):
            sim.run(straight_segment(a, b, sim.dt), "closed")  # closed fingers: a paddle
        with sim.truth.experimenter():
            moved = np.linalg.norm(sim.truth.block_poses()["a"].xy - A.xy)
        assert sim.touched.get("a", 0) > 0, sim.touched
        assert moved > 0.01


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_sleeping_block_falls_when_its_support_is_teleported_away(sim_name):
    on_top = Pose((A.xyz[0], A.xyz[1], 0.075), A.yaw)
    with make_simulator(sim_name, ("a", "b"), {"a": A, "b": on_top}) as sim:
        _rest(sim, 2.5)
        assert _asleep(sim, "b")
        sim.set_block_pose("a", Pose((0.4, 0.3, 0.025)))
        _rest(sim, 0.5)
        with sim.truth.experimenter():
            b = sim.truth.block_poses()["b"]
        assert b.xyz[2] == pytest.approx(0.025, abs=0.003)


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_the_arm_tracks_a_fast_move_to_within_a_few_milliradians(sim_name):
    """Both simulators track the trajectory's velocity, not only its positions: MuJoCo's
    position actuators alone (kp (ctrl - q) - kv qd) lagged a fast shoulder move by 9 mrad,
    3 mm at the hand, enough for a held block to brush a neighbour 2 mm away as it rose."""
    with make_simulator(sim_name, (), {}) as sim:
        start = np.asarray(PANDA.q_home, dtype=float)
        end = start + np.array([0.3, 0.4, 0.0, 0.3, 0.0, -0.3, 0.0])
        worst = sim.run(straight_segment(start, end, sim.dt), "open")
        assert worst < 0.004, worst
