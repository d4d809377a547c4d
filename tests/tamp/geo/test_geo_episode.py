"""A geometric TAMP episode in PyBullet (`tamp.geo.episode.run_geo_episode`): the baseline
reaches a hemmed-in target's goal with no collision; task-only planning with execution fails
on it, each try refused by the executor's check before the arm moves."""

from __future__ import annotations

import numpy as np
import pytest

from tamp.geo.config import GeoEpisodeConfig
from tamp.geo.episode import planner_by_name, run_geo_episode
from tamp.geo.search import SearchConfig
from tamp.geo.types import GeoLimits
from tamp.modes import GeoPlanner
from tamp.outcome import EpisodeStatus, Failure
from tamp.world.goal import parse_goal
from task.errors import TampError
from tests.tamp.geo.geo_scenes import hemmed, tools

SMALL = SearchConfig(choices=("top",), places=4, max_time_s=60.0)


@pytest.mark.sim
def test_search_then_check_reaches_the_goal_in_pybullet_without_a_collision():
    s = hemmed()
    config = GeoEpisodeConfig("search-then-check", "pybullet", search=SMALL)
    report = run_geo_episode(s, parse_goal("(in t goal)", s), config, tools=tools())
    assert report.reached_goal and report.status is EpisodeStatus.GOAL_REACHED, report
    assert report.collisions == 0 and report.touched == {}
    assert report.motion_failures == 0
    assert [m.move.split()[1] for m in report.moves][-1] == "t"
    assert report.moves[0].move.split()[1] in {"w", "n"}
    assert report.plan_length == 2 and report.arm_path_rad > 0
    assert report.sim_time_s > 0 and len(report.plan_times_s) == 1


@pytest.mark.sim
def test_task_only_planning_fails_on_it_and_says_why():
    s = hemmed()
    config = GeoEpisodeConfig("soft", "pybullet", limits=GeoLimits(max_replans=1), search=SMALL)
    report = run_geo_episode(s, parse_goal("(in t goal)", s), config, tools=tools())
    assert not report.reached_goal and report.status is EpisodeStatus.REPLAN_BUDGET
    assert {m.failure for m in report.moves} == {Failure.COLLISION}
    assert all(m.move.startswith("move t -> goal") for m in report.moves)
    assert report.collisions == 0 and report.arm_path_rad == 0  # refused before moving


def test_an_unknown_planner_lists_the_valid_ones():
    with pytest.raises(TampError, match=r"unknown planner 'sfot' \(valid: motion-aware, "):
        planner_by_name("sfot")
    assert planner_by_name(GeoPlanner.SOFT) is planner_by_name("soft")


class _ArmOnly:
    """A stand-in simulator: the arm at ``q``, trajectories run by jumping to their end."""

    dt = 0.002

    def __init__(self, q) -> None:
        self.q, self.runs = np.asarray(q, dtype=np.float64), []

    def arm_q(self):
        return self.q.copy()

    def run(self, trajectory, gripper, *args, **kwargs):
        self.runs.append((trajectory, gripper))
        self.q = trajectory.positions[-1].copy()
        return 0.0


def test_the_empty_hand_goes_home_along_a_guarded_move_to_check_a_move_again():
    from robots.panda import PANDA
    from tamp.geo.episode import _go_home

    away = PANDA.q_home + np.array([0.6, 0.2, -0.3, 0.2, 0.1, -0.2, 0.4])
    sim = _ArmOnly(away)
    path = _go_home(sim, hemmed(), tools())
    assert path >= np.linalg.norm(away - PANDA.q_home) - 1e-9  # rad: at least the straight way
    np.testing.assert_allclose(sim.q, PANDA.q_home, atol=1e-9)
    assert [g for _, g in sim.runs] == ["open"]
    assert _go_home(sim, hemmed(), tools()) == 0.0  # at home already: nothing runs
    assert len(sim.runs) == 1


def test_a_corrected_place_runs_only_where_the_guard_finds_it_free():
    """The place side moved by a few millimetres passes the guard; moved 7 cm onto the
    neighbour it would put the held cube (and the fingers) into, it does not."""
    from motion.pick_place import corrected_place
    from tamp.geo.check import check_move, support_box
    from tamp.geo.episode import _free
    from tamp.geo.types import TABLE, GeoMove, Place

    scene, kit = hemmed(), tools()
    move = GeoMove("n", Place("table.x", TABLE, (0.62, 0.0, 0.025), 0.0))
    verdict = check_move(scene, move, kit)
    assert verdict.ok, verdict.evidence
    above = next(p for p in verdict.motion if p.name == "transit").trajectory.positions[-1]
    support = support_box(scene, TABLE)
    for shift, free in (((0.002, 0.0), True), ((-0.07, 0.0), False)):
        tail = corrected_place(kit.solver, above, verdict.motion, shift)
        assert tail is not None
        assert _free(scene, move, verdict.grasp, support, kit, tail) is free, shift


def test_the_episode_limits_default_to_geo_limits():
    """One home for the limits ``tamp run``, ``tamp bench tamp`` and `tamp.api.run`
    run with: the episode config's defaults are `GeoLimits`', and its planner's time too."""
    import inspect

    config = inspect.signature(run_geo_episode).parameters["config"].default
    assert config == GeoEpisodeConfig() and config.limits == GeoLimits()
    assert config.search_config().max_time_s == GeoLimits().planning_s
    assert GeoEpisodeConfig(seed=7).search_config().seed == 7


@pytest.mark.sim
def test_a_plan_stopped_by_the_time_limit_says_so_in_the_no_plan_reason():
    s = hemmed()
    search = SearchConfig(choices=("top",), places=4, max_time_s=1e-9)
    report = run_geo_episode(
        s,
        parse_goal("(in t goal)", s),
        GeoEpisodeConfig(planner="search-then-check", search=search),
        tools=tools(),
    )
    assert report.status is EpisodeStatus.NO_PLAN, report
    assert report.reason.startswith("time limit (1e-09 s) reached; budget:"), report.reason


def _tray_scene():
    """One cube on the table beside the 20 cm tray (the scene file of ``tamp run``'s tests)."""
    from tamp.world.load import load_scene
    from tests.tamp.world.test_load import TRAY, cube, scene

    return load_scene(scene(cube("a", 0.45, -0.2, 0.025), regions=[TRAY]))


@pytest.mark.sim
def test_an_object_nudged_out_of_its_region_is_seen_and_planned_again():
    """The loop's nudge fault: after the move, the experimenter pushes the placed cube 20 cm
    (out of the 20 cm tray whichever way); the sensor sees it, the robot plans again and puts
    it back; the report lists the fault as the loop does."""
    s = _tray_scene()
    config = GeoEpisodeConfig(nudges=(0,), nudge_m=0.2)  # ours, its default budgets
    report = run_geo_episode(s, parse_goal("(in a tray)", s), config, tools=tools())
    assert report.faults == ("nudge@0",)
    assert report.replans == 1 and len(report.plans) == 2, report.plans
    assert [m.ok for m in report.moves] == [True, True]  # the nudge is no failure of the move
    assert report.reached_goal and report.status is EpisodeStatus.GOAL_REACHED


def test_pose_noise_moves_every_observed_position_when_drawn():
    from tamp.geo.episode import PoseNoise
    from tamp.scene import Pose

    poses = {"a": Pose((0.4, 0.1, 0.025), 0.3), "b": Pose((0.5, -0.1, 0.075), 0.0)}
    noisy = PoseNoise(1.0, 0.01, np.random.default_rng(0))(poses)
    for name, pose in poses.items():
        shift = np.subtract(noisy[name].xyz, pose.xyz)
        assert 0 < np.abs(shift).max() < 0.05 and noisy[name].yaw == pose.yaw
    rng = np.random.default_rng(0)
    assert PoseNoise(0.0, 0.01, rng)(poses) == poses
    assert rng.random() == np.random.default_rng(0).random(2)[1]  # the draw was consumed
