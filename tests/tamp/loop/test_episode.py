"""The closed loop (`tamp.loop`): its small steps without a simulator, then whole episodes in
both simulators: a 3-block plan end to end, a dropped block and a nudged block recovered by
replanning, observation noise, an unreachable block, and a loose block tidied away."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from motion.ik import IKSolver
from tamp.loop import Episode, EpisodeReport, EpisodeStatus, LoopConfig, describe, run_episode
from tamp.loop.execute import ExecutionResult
from tamp.loop.faults import Injection
from tamp.loop.recover import out_of_reach
from tamp.loop.report import Progress
from tamp.outcome import Failure
from tamp.scene import Pose
from tamp.sim import SIMULATORS
from task.errors import TampError
from task.problem import TABLE, Move, Problem

THREE = Problem(
    "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
)
A_TABLE, A_B = Move("a", TABLE), Move("a", "b")
NO_IK = {"waypoint": "pre_grasp", "target_xyz": (1.4, 0.0, 0.16)}


def _failed(move: Move, failure: Failure = Failure.IK_INFEASIBLE) -> ExecutionResult:
    return ExecutionResult(move, False, failure, dict(NO_IK))


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


# --- the small steps, no simulator ---------------------------------------------------------
@pytest.mark.parametrize(
    ("moves", "expected"),
    [
        ([], False),
        ([_failed(A_TABLE)], False),
        ([_failed(A_TABLE), _failed(A_TABLE)], True),
        ([_failed(A_TABLE), _failed(A_B)], False),  # two different moves
        ([_failed(A_TABLE), _failed(A_TABLE, Failure.DROPPED)], False),
        ([_failed(A_TABLE), _failed(A_TABLE), ExecutionResult(A_TABLE, True)], False),
    ],
)
def test_out_of_reach_needs_the_same_move_without_ik_twice_in_a_row(moves, expected):
    assert out_of_reach(moves) is expected


def test_describe_says_why_a_move_failed():
    assert describe(ExecutionResult(A_B, True)) == "move(a -> b): ok"
    assert describe(_failed(A_TABLE)) == (
        "move(a -> table): ik_infeasible "
        "(no IK solution for the pre_grasp waypoint at (1.400, 0.000, 0.160) m)"
    )
    dropped = ExecutionResult(A_B, False, Failure.DROPPED, {"after": "transit", "x": {"y": 1}})
    assert describe(dropped) == "move(a -> b): dropped (after transit)"  # nested dicts left out


def test_an_episode_report_turns_into_plain_json():
    moves = (ExecutionResult(A_B, True, sim_time_s=1.23456), _failed(A_TABLE))
    report = EpisodeReport(
        "p",
        "pybullet",
        EpisodeStatus.OUT_OF_REACH,
        False,
        moves,
        (("move(a -> b)",),),
        1,
        ("drop@0",),
        0,
        2.0,
        3.0,
        0.5,
        True,
        "why",
    )
    out = json.loads(json.dumps(report.to_json()))  # plain JSON
    assert out["status"] == "out_of_reach" and out["reason"] == "why"
    assert out["moves"][0] == {
        "move": "move(a -> b)",
        "ok": True,
        "failure": None,
        "evidence": {},
        "sim_time_s": 1.235,
        "wall_time_s": 0.0,
        "ik_time_s": 0.0,
        "rerouted": [],
        "planner_runs": 0,
        "planner_failures": 0,
    }
    assert out["unreadable"] == 0 and out["truth_reads"] == {}
    assert out["moves"][1]["failure"] == "ik_infeasible"
    assert out["plans"] == [["move(a -> b)"]] and out["faults"] == ["drop@0"]


def test_progress_stops_with_a_status_and_becomes_the_report():
    p = Progress(THREE.init, first_solved=True)
    assert not p.stopped and p.status is EpisodeStatus.GOAL_REACHED
    p.moves.append(ExecutionResult(A_B, True))
    p.stop(EpisodeStatus.NO_PLAN, "the planner found no plan")
    report = p.report("three", "mujoco", False, 4.0, wall0=0.0)
    assert p.stopped and report.status is EpisodeStatus.NO_PLAN
    assert report.reason == "the planner found no plan" and report.moves == tuple(p.moves)
    assert report.initial_plan_solved and report.sim_time_s == 4.0


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"observe": "lidar"}, "unknown observation 'lidar' (valid: state, camera)"),
        ({"observe": "camera", "perception": "state"}, "perception mode 'frozen' or 'optimised'"),
    ],
)
def test_loop_config_rejects_what_it_cannot_observe(fields, message):
    from tamp.camera.from_images import PerceptionMode

    if "perception" in fields:
        fields = {**fields, "perception": PerceptionMode(fields["perception"])}
    with pytest.raises(TampError, match=message.replace("(", r"\(").replace(")", r"\)")):
        LoopConfig(**fields)


def test_configs_hold_their_modes_as_enums_given_by_name():
    from tamp.camera.from_images import PerceptionMode
    from tamp.loop.execute import CollisionMode, ExecConfig
    from tamp.modes import Adapt, Crisp, Observation, Perception

    config = LoopConfig(observe="camera", crisp="true", execution=ExecConfig(collision="off"))
    assert config.observe is Observation.CAMERA and config.crisp is Crisp.TRUE
    assert config.execution.collision is CollisionMode.OFF
    assert LoopConfig().observe is Observation.STATE and LoopConfig().crisp is Crisp.PERCEIVED
    mode = PerceptionMode("optimised", adapt="all", crisp="perceived")
    assert (mode.mode, mode.adapt, mode.crisp) == (Perception.OPTIMISED, Adapt.ALL, Crisp.PERCEIVED)
    assert all(type(v) is not str for v in (mode.mode, mode.adapt, mode.crisp))
    with pytest.raises(
        TampError, match=r"^unknown collision mode 'of' \(valid: plan, check, off\)$"
    ):
        ExecConfig(collision="of")


# --- whole episodes in a simulator ----------------------------------------------------------
@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_three_block_plan_runs_end_to_end(sim_name, solver):
    report = run_episode(THREE, LoopConfig(sim=sim_name), seed=0, solver=solver)
    assert report.status is EpisodeStatus.GOAL_REACHED, report.reason
    assert report.reached_goal
    assert all(m.ok for m in report.moves) and report.replans == 0


@pytest.mark.sim
@pytest.mark.parametrize("sim_name", SIMULATORS)
def test_a_dropped_block_triggers_a_replan_and_the_goal_is_still_reached(sim_name, solver):
    config = LoopConfig(sim=sim_name, inject=Injection(drop_moves=(0,)))
    report = run_episode(THREE, config, seed=0, solver=solver)
    assert report.moves[0].failure is Failure.DROPPED
    assert report.faults == ("drop@0",)
    assert report.replans >= 1 and len(report.plans) >= 2
    assert report.reached_goal, report.reason


@pytest.mark.sim
def test_a_nudged_block_is_seen_and_the_plan_is_repaired(solver):
    config = LoopConfig(inject=Injection(nudge_moves=(1,)))  # move 1 stacks a on c
    report = run_episode(THREE, config, seed=0, solver=solver)
    assert report.faults == ("nudge@1",)
    assert report.replans >= 1 and report.reached_goal, report.reason


@pytest.mark.sim
def test_observation_noise_perturbs_the_observed_poses_only():
    episode = Episode(THREE, LoopConfig(inject=Injection(noise=1.0, noise_sigma=0.01)), seed=0)
    try:
        truth = episode.sim.truth
        with truth.scoring():
            before = truth.block_poses()
        seen = episode.eyes.poses()  # the mocap oracle, plus noise
        offsets = [np.linalg.norm(np.subtract(seen[x].xyz, before[x].xyz)) for x in before]
        assert 0.0 < max(offsets) < 0.1
        with truth.scoring():
            assert truth.block_poses() == before
    finally:
        episode.sim.close()


@pytest.mark.sim
def test_an_out_of_reach_episode_stops_with_a_clear_reason(solver, monkeypatch):
    import tamp.loop.episode as episode

    far = {"a": Pose((1.4, 0.0, 0.025)), "b": Pose((0.5, 0.0, 0.025))}
    monkeypatch.setattr(episode, "layout", lambda *a, **k: far)
    problem = Problem("far", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    report = run_episode(problem, LoopConfig(), seed=0, solver=solver)
    assert report.status is EpisodeStatus.OUT_OF_REACH and not report.reached_goal
    assert "ik_infeasible" in report.reason and "pre_grasp" in report.reason


@pytest.mark.sim
def test_a_loose_block_is_tidied_onto_the_table_and_the_episode_goes_on(solver, monkeypatch):
    import tamp.loop.observe as observe
    from tamp.world.convert.from_poses import Reading

    real, calls = observe.read_state, []

    def once_loose(entities, poses, config):
        calls.append(1)
        if len(calls) == 1:  # the first observation, after move 0: c "leans"
            return Reading(None, ("block c leans",), ("c",))
        return real(entities, poses, config)

    monkeypatch.setattr(observe, "read_state", once_loose)
    events: list[str] = []
    report = run_episode(THREE, LoopConfig(), seed=0, solver=solver, on_event=events.append)
    assert any(str(m.move) == "move(c -> table)" and m.ok for m in report.moves)
    assert any(e.startswith("tidy c onto the table: ") for e in events)
    assert report.reached_goal, report.reason


def test_the_camera_refuses_more_blocks_than_it_has_colours_before_any_simulator_starts():
    names = tuple("abcdefghi")  # 9 blocks; the camera tells 8 apart by colour
    problem = Problem("nine", "blocksworld", names, (TABLE,) * 9, (("a", "b"),))
    with pytest.raises(TampError, match="camera tells at most 8"):
        Episode(problem, LoopConfig(observe="camera"))


def test_the_executor_says_when_it_put_a_block_on_another_table_place_than_named():
    from tamp.loop.execute import placed_elsewhere
    from tamp.scene import PlacedMove

    named = PlacedMove("b", TABLE, (0.40, 0.0), "slot1")
    assert placed_elsewhere(named, Pose((0.40, 0.0, 0.025))) == {}
    assert placed_elsewhere(named, Pose((0.56, 0.12, 0.025))) == {"placed_at": (0.56, 0.12)}
    assert placed_elsewhere(Move("b", TABLE), Pose((0.56, 0.12, 0.025))) == {}


@pytest.mark.sim
def test_a_block_left_on_another_table_place_than_planned_triggers_a_replan(monkeypatch):
    """A move that named a table place (`PlacedMove`) and went through, but whose block the
    executor put on another slot (``placed_at``: the next free one): the state is the planned
    one, yet the plan's later moves assumed the block on its place, so the loop replans and
    says why. A block put on its place, or a move onto a block, goes on."""
    from tamp.scene import PlacedMove
    from tamp.world.convert.from_poses import Reading

    episode = Episode(THREE, LoopConfig(), seed=0)
    try:
        state = (TABLE, TABLE, TABLE)
        monkeypatch.setattr(episode, "observe", lambda: Reading(state))
        there = PlacedMove("b", TABLE, (0.40, 0.0), "slot1")
        away = ExecutionResult(there, True, evidence={"placed_at": (0.56, 0.12)})
        assert episode._elsewhere(there, ExecutionResult(there, True)) is None
        assert episode._elsewhere(there, away) == "slot1"
        assert episode._elsewhere(there, replace(away, ok=False)) is None
        cases = (
            (ExecutionResult(there, True), 0),
            (ExecutionResult(Move("b", "c"), True), 0),
            (away, 1),
        )
        for done, replans in cases:
            p = Progress(state, first_solved=True, queue=[A_B])
            episode.check(p, done.move, done, state)
            assert p.replans == replans and p.queue == ([] if replans else [A_B])
            assert not p.stopped
    finally:
        episode.sim.close()


@pytest.mark.sim
def test_an_episode_leaves_torchs_thread_count_to_its_caller(solver):
    """Library code changes no process-wide setting: the episode plans with the thread count
    its caller chose (``tamp run`` and the benchmarks choose one thread) and leaves it so."""
    import torch

    two = Problem("two", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    before, seen = torch.get_num_threads(), []
    torch.set_num_threads(2)
    try:
        report = run_episode(
            two,
            LoopConfig(),
            0,
            solver=solver,
            on_event=lambda _: seen.append(torch.get_num_threads()),
        )
        after = torch.get_num_threads()
    finally:
        torch.set_num_threads(before)
    assert report.reached_goal, report.reason
    assert seen and set(seen) == {2} and after == 2


@pytest.mark.sim
def test_a_no_plan_stopped_by_the_time_limit_says_so(solver):
    planner = replace(LoopConfig().planner, time_limit_s=1e-9, fallback=False)
    report = run_episode(THREE, LoopConfig(planner=planner), seed=0, solver=solver)
    assert report.status is EpisodeStatus.NO_PLAN and not report.moves
    assert "time limit (1e-09 s) reached: stopped at the 1e-09 s time limit" in report.reason


def test_a_fallback_the_deadline_stops_says_time_limit_in_its_stats(monkeypatch):
    import time
    from types import SimpleNamespace

    import task.planner.loop as loop
    from task.config import PlannerConfig
    from task.planner import plan
    from task.symbolic.lazy_search import LazyResult, SearchStatus

    late = [0.0]  # seconds the planner's clock is ahead of the real one
    monkeypatch.setattr(
        loop, "time", SimpleNamespace(perf_counter=lambda: time.perf_counter() + late[0])
    )

    def out_of_time(*args, **kwargs):  # the fallback search runs past the deadline
        late[0] = 100.0
        return LazyResult(SearchStatus.BUDGET, (), 1, 0, 0, 100.0, "the deadline ran out")

    monkeypatch.setattr(loop, "fall_back", out_of_time)
    config = PlannerConfig(horizon=1, iters=2, max_windows=1, time_limit_s=60.0, fallback=True)
    result = plan(THREE, config)
    assert not result.solved and result.stats["fallback"]["trigger"] == "windows"
    assert result.stats["time_limit"].startswith("stopped at the 60 s time limit")
