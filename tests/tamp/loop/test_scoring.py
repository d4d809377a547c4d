"""Scoring sees what goes wrong: scripted disturbances, and each scoring column that must count
them. The arm pushing a tower over (collisions and a disturbed stack, the block it has just
moved included), the carried block hitting a wall (the held block's own contacts), a contact
shorter than the old sampling interval, and, in a whole given-plan episode, a tower shoved, a
block dropped onto another and a block left where it rests on nothing readable (unreadable
counts against the plan, and as its own count). Then the motion planner's count: a move is
rerouted only when it ran on a detour, not when the planner ran and found no way."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from motion.ik import IKSolver, top_down_pose
from motion.trajectory import JointTrajectory, straight_segment
from robots.collision import PandaCollision
from robots.panda import PANDA
from tamp.bench.motion import episode_rows
from tamp.loop import LoopConfig
from tamp.loop.execute import ExecConfig, ExecTools, execute_move
from tamp.loop.geo_fallback import geo_fallback
from tamp.loop.given import GivenPlanEpisode, parse_given
from tamp.loop.score import MoveScore, Scorer
from tamp.obstacles import Obstacle
from tamp.outcome import Failure
from tamp.scene import Pose, SceneConfig, layout
from tamp.sim import SIMULATORS, make_simulator
from tamp.sim.pybullet_sim import PyBulletSim
from task.problem import TABLE, Move, Problem

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_the_arm_pushing_over_the_tower_it_just_built_is_a_collision_and_a_disturbance(
    sim_name, solver
):
    """a goes onto c (on b); then the hand sweeps through the tower. Touching a, the block the
    last move handled, counts once that move is over."""
    entities, init = ("a", "b", "c", "d"), (TABLE, TABLE, "b", TABLE)
    problem = Problem("push", "blocksworld", entities, init, (("a", "c"),))
    poses = layout(entities, init, seed=0, slots=[2, 7, 9])  # the tower b-c at (0.56, 0.0)
    with make_simulator(sim_name, entities, poses) as sim:
        score = Scorer(sim.truth, problem, SceneConfig())
        assert execute_move(sim, Move("a", "c"), sim.truth.block_poses, ExecTools(solver)).ok
        assert sim.touched == {}  # the move itself touched nothing it was not meant to
        before = score.state()
        x, y = sim.truth.block_poses()["b"].xy
        sweep = np.stack([top_down_pose((x, y + dy, 0.09), 0.0) for dy in (-0.15, 0.12)])
        q = solver.solve(sweep, sim.arm_q()).q  # (2, J): beside the tower, past it
        over = solver.solve(top_down_pose((x, y - 0.15, 0.3), 0.0)[None], sim.arm_q()).q[0]
        for a, b in ((sim.arm_q(), over), (over, q[0]), (q[0], q[1])):
            sim.run(straight_segment(a, b, sim.dt), "open")
        sim.run(JointTrajectory.hold(q[1], 1.0, sim.dt), "open")
        assert "a" in sim.touched, sim.touched
        assert score.move(Move("d", TABLE), before) is not MoveScore.CLEAN


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_the_carried_block_hitting_a_wall_is_its_own_collision(sim_name, solver):
    """A 15 cm wall between the slots, run unchecked: the hand passes over it, the block it
    carries (its bottom 13.5 cm up in transit) does not."""
    wall = Obstacle("wall", (0.48, 0.0, 0.075), (0.15, 0.01, 0.075))
    scene = replace(SceneConfig(), obstacles=(wall,))
    poses = layout(("a", "b"), (TABLE, TABLE), scene, seed=0, slots=[0, 4])
    unchecked = replace(ExecConfig(), collision="off")
    with make_simulator(sim_name, ("a", "b"), poses, scene) as sim:
        tools = ExecTools(solver, scene)
        done = execute_move(sim, Move("a", "b"), sim.truth.block_poses, tools, unchecked)
        assert not done.ok
        assert sim.touched.get("held:wall", 0) > 0 and "wall" not in sim.touched, sim.touched


class _Blink(PyBulletSim):
    """A PyBullet world whose contact reading shows the arm touching "x" on the third physics
    step of a run only (shorter than a sample interval of five steps)."""

    steps = 0

    def _step(self) -> None:
        super()._step()
        self.steps += 1

    def _contacts(self) -> set[tuple[str, str]]:
        return {("robot", "x")} if self.steps == 3 else set()

    def _robot_touching(self) -> set[str]:  # the reading before contacts were pairs
        return {"x"} if self.steps == 3 else set()


def test_a_contact_of_one_physics_step_is_counted():
    with _Blink(("a",), {"a": Pose((0.5, 0.0, 0.025))}) as sim:
        sim.run(JointTrajectory.hold(PANDA.q_home, 0.02, sim.dt), "open")  # ten steps
        assert sim.touched == {"x": 1}


# --- a whole given-plan episode with the experimenter's scripted disturbance ---------------
FIVE = ("a", "b", "c", "d", "e", "f")
SIX = Problem("six", "blocksworld", FIVE, (TABLE, TABLE, TABLE, "c", TABLE, TABLE), (("a", "b"),))


def _shove(poses: dict[str, Pose]) -> dict[str, Pose]:
    """Push d 3.5 cm off c: it falls."""
    d = poses["d"]
    return {"d": Pose((d.xyz[0], d.xyz[1] + 0.035, d.xyz[2]), d.yaw)}


def _drop(poses: dict[str, Pose]) -> dict[str, Pose]:
    """Drop f from 3 cm above e: it lands on e."""
    e = poses["e"]
    return {"f": Pose((e.xyz[0], e.xyz[1], e.xyz[2] + 0.08), e.yaw)}


def _offset(poses: dict[str, Pose]) -> dict[str, Pose]:
    """Put f on e 2.2 cm off its centre: it stays there, its centre over e, so on e."""
    e = poses["e"]
    along = 0.022 * np.array([np.cos(e.yaw), np.sin(e.yaw)])
    return {"f": Pose((*(e.xy + along), e.xyz[2] + 0.05), e.yaw)}


def _bridge(poses: dict[str, Pose]) -> dict[str, Pose]:
    """Set e beside f, 1 mm apart, and d across the two: it stays there, on nothing the state
    can name (its centre over neither)."""
    f = poses["f"]
    x, y = f.xyz[0], f.xyz[1]
    return {
        "f": Pose((x, y, 0.025)),
        "e": Pose((x, y + 0.051, 0.025)),
        "d": Pose((x, y + 0.0255, 0.075)),
    }


@pytest.mark.parametrize(
    ("script", "unreadable"),
    [(_shove, None), (_drop, 0), (_offset, 0), (_bridge, 1)],
    ids=["shove", "drop", "offset", "bridge"],
)
def test_a_scripted_disturbance_during_a_move_counts_against_the_plan(script, unreadable, solver):
    """The given plan moves a onto b; during the move the experimenter disturbs other blocks.
    The move is not scored clean (``disturbed``), and an unreadable true state is counted as
    such (``None``: either way)."""
    fired = []

    def experimenter(sim) -> None:
        if fired or sim.time < 1.0:
            return
        with sim.truth.experimenter():
            poses = sim.truth.block_poses()
        for block, pose in script(poses).items():
            sim.set_block_pose(block, pose)
        fired.append(sim.time)

    steps = parse_given("move(a -> b)", "script", SIX)
    episode = GivenPlanEpisode(SIX, steps, LoopConfig(), seed=0, solver=solver)
    episode.on_frame = experimenter
    report = episode.run()
    assert fired and report.moves[0].ok
    assert report.disturbed == 1, report.steps
    row = episode_rows([report])[0]
    assert row["disturbed"] == 1
    if unreadable is not None:
        assert report.unreadable == row["unreadable"] == unreadable
    assert not report.collided, report.touched  # the arm touched nothing


# --- the motion planner's count ------------------------------------------------------------
def test_a_planner_run_that_finds_no_way_is_not_a_reroute(solver):
    """A 30 cm post 1.5 cm beside block a: the hand above a, where every top-down approach
    ends, is in it, so each grasp tried runs the motion planner, which finds no way; the move
    fails and was rerouted nowhere. The executor's geometric fallback (on by default) then
    makes the move with a grasp that is not top-down, its planner runs counted the same."""
    post = Obstacle("post", (0.4, -0.26, 0.15), (0.02, 0.02, 0.15))
    scene = replace(SceneConfig(), obstacles=(post,))
    poses = layout(("a", "b"), (TABLE, TABLE), scene, seed=0, slots=[0, 4])  # a at (0.4, -0.32)
    outcomes = []
    for fallback in (False, True):
        with make_simulator("pybullet", ("a", "b"), poses, scene) as sim, PandaCollision() as model:
            outcomes.append(
                execute_move(
                    sim,
                    Move("a", "b"),
                    sim.truth.block_poses,
                    ExecTools(
                        solver, scene, model, geo_fallback(solver, model, ExecConfig().guard)
                    ),
                    ExecConfig(geo_fallback=fallback),
                )
            )
    done, geo = outcomes
    assert done.failure is Failure.COLLISION and done.evidence["other"] == "post"
    assert done.path_time_s > 0  # the planner ran ...
    assert done.rerouted == () and done.planner_runs == done.planner_failures == 2  # ... in vain
    assert geo.ok and not geo.evidence["grasp"].startswith("top")
    assert geo.rerouted == () and geo.planner_runs == geo.planner_failures == 2
