"""Collision-free execution in the loop: a move whose straight transit would carry the block
through a wall is rerouted by the motion planner and runs without touching anything, in both
simulators; with the planner off the same move fails as a predicted collision and nothing
moves; a whole episode in the clutter scene reaches the goal untouched."""

from __future__ import annotations

from dataclasses import replace

import pytest

from motion.ik import IKSolver
from robots.collision import PandaCollision
from tamp.loop import LoopConfig, run_episode
from tamp.loop.execute import ExecConfig, ExecTools, execute_move
from tamp.obstacles import Obstacle, with_scene
from tamp.outcome import Failure
from tamp.scene import SceneConfig, layout
from tamp.sim import SIMULATORS, make_simulator
from tamp.world.convert.from_poses import read_state
from task.problem import TABLE, Move, Problem

# a 20 cm wall across the table between the y = -0.32 and y = 0.32 slots
WALL = replace(SceneConfig(), obstacles=(Obstacle("wall", (0.48, 0.0, 0.1), (0.15, 0.01, 0.1)),))
ENTITIES, STATE = ("a", "b"), (TABLE, TABLE)


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


def _move(sim_name: str, solver: IKSolver, mode: str):
    poses = layout(ENTITIES, STATE, WALL, seed=0, slots=[0, 4])  # a at y = -0.32, b at 0.32
    with make_simulator(sim_name, ENTITIES, poses, WALL) as sim, PandaCollision() as model:
        observe = sim.truth._read_poses  # the test is the pose sensor
        config = replace(ExecConfig(), collision=mode)
        tools = ExecTools(solver, WALL, model)
        result = execute_move(sim, Move("a", "b"), observe, tools, config)
        after = read_state(ENTITIES, observe(), WALL).state
        return result, after, dict(sim.touched)


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_transit_through_a_wall_is_rerouted_and_runs_untouched(sim_name, solver):
    result, after, touched = _move(sim_name, solver, "plan")
    assert result.ok, result.evidence
    assert result.path_time_s > 0 and result.check_time_s > 0
    assert result.rerouted == ("transit",) and result.planner_failures == 0
    assert after == ("b", TABLE) and touched == {}


def test_without_the_planner_the_blocked_move_fails_before_it_moves(solver):
    result, after, touched = _move("pybullet", solver, "check")
    assert result.failure is Failure.COLLISION
    assert result.evidence["phase"] == "transit" and result.evidence["other"] == "wall"
    assert after == STATE and touched == {} and result.sim_time_s == 0


def test_an_episode_in_the_clutter_scene_reaches_the_goal_untouched(solver):
    three = Problem(
        "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
    )
    config = LoopConfig(scene=with_scene(SceneConfig(), "clutter"))
    report = run_episode(three, config, seed=1, solver=solver)
    assert report.reached_goal and not report.collided, (report.reason, report.touched)


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_the_planner_finds_a_way_under_the_shelf_and_runs_it_untouched(sim_name, solver):
    """Block a sits under the shelf board, the tower b-c-d-e elsewhere: the straight approach
    from home sweeps the arm through the board; the detour does not."""
    shelf = with_scene(SceneConfig(), "shelf")
    entities, state = ("a", "b", "c", "d", "e"), (TABLE, TABLE, "b", "c", "d")
    poses = layout(entities, state, shelf, seed=0, slots=[8, 0])  # a at (0.56, 0.16)
    with make_simulator(sim_name, entities, poses, shelf) as sim, PandaCollision() as model:
        observe = sim.truth._read_poses
        check = replace(ExecConfig(), collision="check")
        tools = ExecTools(solver, shelf, model)
        refused = execute_move(sim, Move("a", "e"), observe, tools, check)
        assert refused.failure is Failure.COLLISION
        assert (refused.evidence["phase"], refused.evidence["other"]) == ("approach", "shelf_board")
        result = execute_move(sim, Move("a", "e"), observe, tools, ExecConfig())
        assert result.ok and result.path_time_s > 0, result.evidence
        assert read_state(entities, observe(), shelf).state == ("e", *state[1:])
        assert sim.touched == {}
