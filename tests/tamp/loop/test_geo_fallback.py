"""The loop's world as a geometric scene (`tamp.loop.geo_fallback`), the executor's geometric
fallback (`tamp.loop.execute`: a move top-down grasps over the highest stack cannot make, made with
another grasp and a lower transit) and the motion-aware prices that agree with it
(`tamp.arm.costs.ArmCosts`' ``grasps``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.arm.arm import Arm
from tamp.arm.costs import BLOCKED, DETOUR, ArmCosts
from tamp.loop.geo_fallback import CHOICES, blocks_goal, geo_fallback, world_scene
from tamp.obstacles import with_scene
from tamp.scene import PlacedMove, Pose, SceneConfig, layout
from tamp.slots import slotted
from tamp.world.convert.from_poses import read_state
from tamp.world.relations import read_facts
from task.problem import TABLE, Problem

CRAMPED = with_scene(SceneConfig(), "cramped")
TALL = Problem(
    "tall", "blocksworld", tuple("abcdefg"), (TABLE, "a", "b", "c", "d", "e", "f"), (("a", "g"),)
)


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


def test_the_world_scene_reads_the_loops_state_with_the_scenes_slots():
    problem = Problem("three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("c", "b"),))
    poses = layout(problem.entities, problem.init, CRAMPED, seed=0)
    low = poses["b"]
    poses["b"] = Pose((low.xyz[0], low.xyz[1], low.xyz[2] - 0.009), low.yaw)  # sunk 9 mm
    assert read_state(problem.entities, poses, CRAMPED).state == problem.init
    scene = world_scene(problem.entities, poses, CRAMPED)
    assert [o.name for o in scene.objects] == list(problem.entities)
    assert scene.object("b").pose.xyz[2] == pytest.approx(0.075)  # its level, snapped
    assert scene.slots.xs == CRAMPED.slot_xs and scene.slots.ys == CRAMPED.slot_ys
    facts = read_facts(scene)
    assert dict(facts.supports) == dict(zip(problem.entities, problem.init, strict=True))
    assert blocks_goal(problem).atoms == (("on", "c", "b"),)
    assert blocks_goal(replace(problem, goal=(("a", TABLE),))).atoms == (("ontable", "a"),)


def _tall(slot: int = 0):
    """A 7-block tower on slot ``slot`` of the cramped table (0: the near (0.40, -0.12), 4: the
    far (0.72, -0.12)): the poses, the slotted problem, its places and the far row's places."""
    poses = layout(TALL.entities, TALL.init, CRAMPED, seed=0, slots=[slot])
    current, at = slotted(TALL, TALL.init, poses, CRAMPED)
    far = [k for k in current.fixed if at[k][0] > 0.7]
    return poses, current, at, far


def test_a_place_only_other_grasps_reach_stays_open_with_them(solver):
    """Over a 7-block tower the far row is out of top-down reach at hover height (ruled out
    without the executor's other grasps); a tilted or side grasp at the block's own height
    reaches it, so with them the move is priced, not ruled out."""
    poses, current, at, far = _tall()
    top, cols = TALL.entities.index("g"), [TALL.n + current.fixed.index(k) for k in far]
    for grasps, blocked in (((), True), (CHOICES, False)):
        source = ArmCosts(
            [current], [poses], CRAMPED, Arm(solver, PANDA.q_home, grasps=grasps), places=[at]
        )
        matrix = source([0], [current.init]).compute()[0]
        assert bool((matrix[top, cols] >= BLOCKED).all()) == blocked


def test_the_top_of_a_far_tower_only_other_grasps_reach_is_priced_a_detour(solver):
    """A 7-block tower on the far row: no top-down IK reaches its top block at all (priced
    without IK, as much as ruled out); a tilted grasp does, so with the executor's other grasps
    its moves are open at `DETOUR` more."""
    poses, current, at, _ = _tall(slot=4)
    top = TALL.entities.index("g")
    rows = {}
    for grasps in ((), CHOICES):
        source = ArmCosts(
            [current], [poses], CRAMPED, Arm(solver, PANDA.q_home, grasps=grasps), places=[at]
        )
        rows[grasps] = source([0], [current.init]).compute()[0][top]
    near = TALL.n + current.fixed.index("slot0")
    assert rows[()][near] >= BLOCKED
    assert DETOUR <= rows[CHOICES][near] < BLOCKED


@pytest.mark.sim
def test_the_executor_makes_a_move_top_down_grasps_cannot(solver):
    """A 7-block tower on a far slot, its top block to a near one: top-down, the hand cannot
    reach the top from above (no IK at the pre-grasp); the geometric fallback makes the move
    (a tilted grasp), touching nothing."""
    from robots.collision import PandaCollision
    from tamp.loop.execute import ExecConfig, ExecTools, execute_move
    from tamp.outcome import Failure
    from tamp.sim import make_simulator

    poses, _, at, _ = _tall(slot=4)
    move = PlacedMove("g", TABLE, at["slot0"], "slot0")
    for fallback in (False, True):
        sim = make_simulator("pybullet", TALL.entities, poses, CRAMPED)
        with sim, PandaCollision() as model:
            observe = sim.truth._read_poses  # the test is the pose sensor
            config = replace(ExecConfig(), geo_fallback=fallback)
            geo = geo_fallback(solver, model, config.guard)
            tools = ExecTools(solver, CRAMPED, model, geo)
            done = execute_move(sim, move, observe, tools, config)
            state = read_state(TALL.entities, observe(), CRAMPED).state
            if not fallback:
                assert done.failure is Failure.IK_INFEASIBLE
                assert state == TALL.init and done.sim_time_s == 0
                continue
            assert done.ok, done.evidence
            assert done.evidence["grasp"].startswith("tilt") and sim.touched == {}
            assert state == (*TALL.init[:-1], TABLE)
            xy = observe()["g"].xy
            assert np.linalg.norm(xy - np.asarray(at["slot0"])) < 0.015


def test_with_other_grasps_a_top_down_release_into_a_neighbour_is_priced_not_ruled_out(solver):
    """A release behind a 6-block tower whose top-down configuration reaches into it is ruled
    out for a top-down executor; with the executor's other grasps it costs `DETOUR` more and
    is still open (a failure there rules it out, `ArmCosts.avoid`)."""
    from tests.tamp.test_arm_costs import _behind

    cramped, current, at, poses, mover, far = _behind(6)
    costs = {}
    for grasps in ((), CHOICES):
        source = ArmCosts(
            [current], [poses], cramped, Arm(solver, PANDA.q_home, grasps=grasps), places=[at]
        )
        costs[grasps] = source([0], [current.init]).compute()[0]
    assert costs[()][mover, far] >= BLOCKED
    assert DETOUR <= costs[CHOICES][mover, far] < BLOCKED


def test_a_block_no_grasp_reaches_fails_on_the_pick_side_whatever_the_place(solver):
    """A block beyond the arm's reach: the top-down pick has no IK and every grasp of the
    geometric fallback fails on the pick side, so the failure is the pick's (`failed_pick`:
    the loop then rules out every move of the block while it stands there). A move that
    failed on the place side, or without the fallback's verdict, is not."""
    from robots.collision import PandaCollision
    from tamp.loop.execute import (
        ExecConfig,
        ExecTools,
        ExecutionResult,
        execute_move,
        failed_pick,
    )
    from tamp.outcome import Failure
    from tamp.sim import make_simulator

    poses = {"a": Pose((0.95, 0.3, 0.025)), "b": Pose((0.4, 0.0, 0.025))}
    move = PlacedMove("a", TABLE, (0.4, -0.24), "slot0")
    sim = make_simulator("pybullet", ("a", "b"), poses, CRAMPED)
    with sim, PandaCollision() as model:
        observe = sim.truth._read_poses
        geo = geo_fallback(solver, model, ExecConfig().guard)
        tools = ExecTools(solver, CRAMPED, model, geo)
        done = execute_move(sim, move, observe, tools, ExecConfig())
    assert done.failure is Failure.IK_INFEASIBLE and done.evidence["waypoint"] == "pre_grasp"
    assert done.evidence["geo"]["sides"] == ["pick"] and failed_pick(done)
    place_side = {**done.evidence, "geo": {**done.evidence["geo"], "sides": ["pick", "place"]}}
    assert not failed_pick(replace(done, evidence=place_side))
    alone = {k: v for k, v in done.evidence.items() if k != "geo"}
    assert not failed_pick(replace(done, evidence=alone))
    assert not failed_pick(ExecutionResult(move, True))


def test_the_check_ahead_finds_what_the_executor_finds_without_running(solver):
    """`motion_check`, the planner's check ahead (no simulator): the far tower's top block to
    a near slot passes through the geometric fallback's tilted grasp (and fails top-down
    alone, as `execute_move` does), a block beyond the arm's reach fails on its IK."""
    from robots.collision import PandaCollision
    from tamp.loop.execute import ExecConfig, ExecTools, motion_check
    from tamp.outcome import Failure

    poses, _, at, _ = _tall(slot=4)
    move = PlacedMove("g", TABLE, at["slot0"], "slot0")
    far = {"a": Pose((0.95, 0.3, 0.025)), "b": Pose((0.4, 0.0, 0.025))}
    away = PlacedMove("a", TABLE, (0.4, -0.24), "slot0")
    alone = replace(ExecConfig(), geo_fallback=False)
    with PandaCollision() as model:
        q, geo = PANDA.q_home, geo_fallback(solver, model, ExecConfig().guard)
        tools, top_down = ExecTools(solver, CRAMPED, model, geo), ExecTools(solver, CRAMPED, model)
        assert motion_check(tools, move, poses, q, ExecConfig()) is None
        found = motion_check(tools, move, poses, q, alone)
        assert found is Failure.IK_INFEASIBLE
        found = motion_check(top_down, move, poses, q, ExecConfig())
        assert found is Failure.IK_INFEASIBLE  # no fallback given: top-down alone
        found = motion_check(tools, away, far, q, ExecConfig())
        assert found is Failure.IK_INFEASIBLE


@pytest.mark.sim
@pytest.mark.parametrize("fallback", [True, False])
def test_the_episode_gives_its_executor_the_geometric_fallback(solver, monkeypatch, fallback):
    """The executor imports nothing of the geometric room: the episode builds the fallback
    (`tamp.loop.geo_fallback.GeoFallback`) and gives it to every move, and none when it is off."""
    from tamp.loop import LoopConfig, episode, run_episode
    from tamp.loop.execute import ExecConfig
    from tamp.loop.geo_fallback import GeoFallback

    given, real = [], episode.execute_move

    def spy(*args, **kwargs):
        given.append(args[3].fallback)
        return real(*args, **kwargs)

    monkeypatch.setattr(episode, "execute_move", spy)
    two = Problem("two", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    config = LoopConfig(execution=replace(ExecConfig(), geo_fallback=fallback))
    report = run_episode(two, config, seed=0, solver=solver)
    assert report.reached_goal and given
    if fallback:
        assert all(isinstance(f, GeoFallback) for f in given)
    else:
        assert given == [None] * len(given)
