"""Both simulators: one pick-and-place, a 3-block plan end to end, a dropped block that is
recovered by replanning, an unreachable block, and the video writer. Each takes seconds."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motion.ik import IKSolver
from tamp.cli import main
from tamp.loop.episode import EpisodeStatus, LoopConfig, run_episode
from tamp.loop.execute import Failure, execute_move
from tamp.loop.faults import Injection
from tamp.scene import Pose, layout, read_state
from tamp.sim import SIMULATORS, make_simulator
from task.problem import TABLE, Move, Problem

pytestmark = pytest.mark.sim

THREE = Problem(
    "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
)


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_one_pick_and_place_stacks_the_block(sim_name, solver):
    entities = ("a", "b")
    with make_simulator(sim_name, entities, layout(entities, (TABLE, TABLE), seed=2)) as sim:
        done = execute_move(sim, solver, Move("a", "b"), sim.block_poses)
        assert done.ok, done.evidence
        assert read_state(entities, sim.block_poses()).state == ("b", TABLE)
        assert done.sim_time_s > 1.0 and done.ik_time_s > 0.0


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_three_block_plan_runs_end_to_end(sim_name, solver):
    report = run_episode(THREE, LoopConfig(sim=sim_name), seed=0, solver=solver)
    assert report.status is EpisodeStatus.GOAL_REACHED, report.reason
    assert report.reached_goal
    assert all(m.ok for m in report.moves) and report.replans == 0


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_dropped_block_triggers_a_replan_and_the_goal_is_still_reached(sim_name, solver):
    config = LoopConfig(sim=sim_name, inject=Injection(drop_moves=(0,)))
    report = run_episode(THREE, config, seed=0, solver=solver)
    assert report.moves[0].failure is Failure.DROPPED
    assert report.faults == ("drop@0",)
    assert report.replans >= 1 and len(report.plans) >= 2
    assert report.reached_goal, report.reason


def test_a_nudged_block_is_seen_and_the_plan_is_repaired(solver):
    config = LoopConfig(inject=Injection(nudge_moves=(1,)))  # move 1 stacks a on c
    report = run_episode(THREE, config, seed=0, solver=solver)
    assert report.faults == ("nudge@1",)
    assert report.replans >= 1 and report.reached_goal, report.reason


def test_observation_noise_perturbs_the_observed_poses_only():
    from tamp.loop.episode import Episode

    episode = Episode(THREE, LoopConfig(inject=Injection(noise=1.0, noise_sigma=0.01)), seed=0)
    try:
        truth, seen = episode.sim.block_poses(), episode.observe()
        offsets = [np.linalg.norm(np.subtract(seen[x].xyz, truth[x].xyz)) for x in truth]
        assert 0.0 < max(offsets) < 0.1
        assert episode.sim.block_poses() == truth
    finally:
        episode.sim.close()


@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_weld_grasp_mode_also_stacks_the_block(sim_name, solver):
    entities = ("a", "b")
    poses = layout(entities, (TABLE, TABLE), seed=4)
    with make_simulator(sim_name, entities, poses, grasp="weld") as sim:
        done = execute_move(sim, solver, Move("a", "b"), sim.block_poses)
        assert done.ok, done.evidence
        assert read_state(entities, sim.block_poses()).state == ("b", TABLE)


def test_an_unreachable_block_is_an_ik_infeasible_failure(solver):
    entities = ("a",)
    with make_simulator("pybullet", entities, {"a": Pose((1.4, 0.0, 0.025))}) as sim:
        done = execute_move(sim, solver, Move("a", TABLE), sim.block_poses)
    assert not done.ok and done.failure is Failure.IK_INFEASIBLE
    assert done.evidence["waypoint"] == "pre_grasp"


def test_an_out_of_reach_episode_stops_with_a_clear_reason(solver, monkeypatch):
    import tamp.loop.episode as loop

    far = {"a": Pose((1.4, 0.0, 0.025)), "b": Pose((0.5, 0.0, 0.025))}
    monkeypatch.setattr(loop, "layout", lambda *a, **k: far)
    problem = Problem("far", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    report = run_episode(problem, LoopConfig(), seed=0, solver=solver)
    assert report.status is EpisodeStatus.OUT_OF_REACH and not report.reached_goal
    assert "ik_infeasible" in report.reason and "pre_grasp" in report.reason


def test_renders_look_alike_in_both_simulators():
    entities = ("a", "b")
    poses = layout(entities, (TABLE, "a"), seed=1)
    images = []
    for name in SIMULATORS:
        with make_simulator(name, entities, poses) as sim:
            images.append(sim.render())
    centres = []
    for img in images:
        assert img.shape == (240, 320, 3) and img.dtype == np.uint8
        red = (img[..., 0] > 120) & (img[..., 1] < 80) & (img[..., 2] < 80)  # block a
        assert red.sum() > 10
        centres.append(np.argwhere(red).mean(axis=0))
    # the same camera model in both: block a lands at about the same pixel
    assert np.linalg.norm(centres[0] - centres[1]) < 25


def test_tamp_run_writes_video_and_report(tmp_path):
    code = main(["run", "--sim", "pybullet", "--seed", "0", "--out", str(tmp_path), "--json"])
    report = json.loads((tmp_path / "report.json").read_text())
    assert code == (0 if report["reached_goal"] else 1)
    assert report["status"] == "goal_reached" and report["config"]["sim"] == "pybullet"
    assert (tmp_path / "episode.mp4").stat().st_size > 10_000


def test_a_loose_block_is_tidied_onto_the_table_and_the_episode_goes_on(solver, monkeypatch):
    import tamp.loop.episode as loop
    from tamp.scene import Reading

    real, calls = loop.read_state, []

    def once_loose(entities, poses, config):
        calls.append(1)
        if len(calls) == 3:  # true state before, after, then the observation: c "leans"
            return Reading(None, ("block c leans",), ("c",))
        return real(entities, poses, config)

    monkeypatch.setattr(loop, "read_state", once_loose)
    report = run_episode(THREE, LoopConfig(), seed=0, solver=solver)
    assert any(str(m.move) == "move(c -> table)" and m.ok for m in report.moves)
    assert report.reached_goal, report.reason
