"""The table as the planner's K base slots (`tamp.slots`): places read from observed poses,
moves onto a place carried to the executor, failed moves priced out, and a cramped scene where
the unlimited-table plan runs out of slots and the slotted one does not."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import torch

from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.arm.arm import Arm
from tamp.arm.costs import BLOCKED, ArmCosts
from tamp.arm.failures import failed_key
from tamp.loop import LoopConfig, run_episode
from tamp.obstacles import with_scene
from tamp.scene import PlacedMove, Pose, SceneConfig, layout, place_pose, plain_move
from tamp.slots import places, plan_on_places, slotted
from task.config import PlannerConfig
from task.domains import blocksworld as bw
from task.problem import TABLE, Move, Problem
from tests.tamp.test_arm_costs import FOUR, SCENE  # the same four-block layout


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


def test_every_tower_base_is_on_the_slot_it_stands_on_and_free_slots_are_places():
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[3, 5, 9])  # a-b, c, d
    at, where = places(FOUR, FOUR.init, poses, SCENE)
    assert where == {"b": "slot3", "c": "slot5", "d": "slot9"}
    assert len(at) == len(SCENE.slots) and at["slot9"] == SCENE.slots[9]
    problem, at2 = slotted(FOUR, FOUR.init, poses, SCENE)
    assert problem.init == ("b", "slot3", "slot5", "slot9") and at2 == at
    assert bw.slotted(problem) and problem.fixed == tuple(at)


def test_a_tower_off_every_slot_keeps_its_own_place_and_crowds_the_slot_beside_it():
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    poses["d"] = Pose((0.48, 0.08, 0.025), 0.0)  # amid slots 2, 3, 7 and 8, 11 cm from each
    at, where = places(FOUR, FOUR.init, poses, SCENE)
    assert where["d"] == "spot_d" and at["spot_d"] == (0.48, 0.08) and len(at) == 11
    poses["d"] = Pose((0.44, 0.0, 0.025), 0.0)  # 4 cm from slot 2
    at, where = places(FOUR, FOUR.init, poses, SCENE)
    assert where["d"] == "slot2"  # within half the slot spacing: on the slot
    poses["d"] = Pose((0.40, 0.08, 0.025), 0.0)  # halfway between slots 2 and 3 in y
    at, where = places(FOUR, FOUR.init, poses, SCENE)
    assert where["d"] == "spot_d" and "slot2" not in at and "slot3" not in at


def test_a_place_goes_to_the_executor_as_a_table_move_at_its_position():
    at = {"slot4": (0.4, 0.32)}
    move = plain_move(Move("a", "slot4"), at)
    assert isinstance(move, PlacedMove) and move.target == TABLE and move.at == (0.4, 0.32)
    assert str(move) == "move(a -> table)" and plain_move(Move("a", "b"), at) == Move("a", "b")
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    chosen = place_pose(PlacedMove("a", TABLE, SCENE.slots[6]), poses, SCENE)
    assert np.allclose(chosen.xyz, (*SCENE.slots[6], 0.025))
    default = place_pose(Move("a", TABLE), poses, SCENE)
    assert not np.allclose(default.xy, SCENE.slots[6])  # the hint, not the default, chose it
    taken = place_pose(PlacedMove("a", TABLE, SCENE.slots[9]), poses, SCENE)  # d stands there
    assert np.allclose(taken.xyz, default.xyz)  # falls back to the best free slot


def test_slot_columns_are_priced_at_their_own_places(solver):
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    problem, at = slotted(FOUR, FOUR.init, poses, SCENE)
    c = ArmCosts([problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at])(
        [0], [problem.init]
    )
    c = c.compute()[0]
    assert c.shape == (4, 4 + len(at))
    col = {k: 4 + j for j, k in enumerate(problem.fixed)}
    # a stands on slot 0's tower: the slot beside it is cheaper than the far end of the table
    assert c[0, col["slot1"] if "slot1" in col else col["slot2"]] < c[0, col["slot8"]]


def test_a_move_the_arm_failed_is_priced_out_in_that_state_only(solver):
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    problem, at = slotted(FOUR, FOUR.init, poses, SCENE)
    failed = PlacedMove("a", TABLE, at["slot7"])
    avoid = {FOUR.init: {failed_key(failed), failed_key(Move("a", "d"))}}
    plain = ArmCosts([problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at])
    priced = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home, avoid=avoid), places=[at]
    )
    before, after = plain([0], [problem.init]).compute()[0], priced([0], [problem.init]).compute()
    diff = (after[0] - before).numpy()
    j = 4 + problem.fixed.index("slot7")
    assert diff[0, j] == pytest.approx(BLOCKED) and diff[0, 3] == pytest.approx(BLOCKED)
    assert np.count_nonzero(diff) == 2
    other = bw.apply_move(problem, problem.init, Move("a", "slot2"))
    assert priced([0], [other]).compute()[0, 0, j] < BLOCKED


def test_a_move_its_check_ahead_fails_is_priced_out_where_it_was_checked(solver):
    """`ArmCosts.verify` hands the executor's check the poses it predicts in the state (a
    block moved to a place stands at the place's centre) and the move as the executor gets
    it (onto the table at the place); a move the check fails is `BLOCKED` in that state from
    then on, checked once, and other states are not touched."""
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    problem, at = slotted(FOUR, FOUR.init, poses, SCENE)
    calls = []

    def check(seen, move):
        calls.append((dict(seen), move))
        return move.entity != "c"  # c cannot be moved, say

    source = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home, check=check), places=[at]
    )
    moved = bw.apply_move(problem, problem.init, Move("a", "slot2"))
    before = source([0], [moved]).compute()[0].clone()
    assert source.verify(0, moved, Move("b", "slot4"))
    seen, planned = calls[-1]
    assert seen["a"].xyz == pytest.approx((*at["slot2"], SCENE.block_size / 2))
    assert isinstance(planned, PlacedMove) and planned.at == at["slot4"]
    assert not source.verify(0, moved, Move("c", "b"))
    assert not source.verify(0, moved, Move("c", "b")) and len(calls) == 2  # checked once
    after = source([0], [moved]).compute()[0]
    diff = (after - before).numpy()
    assert diff[2, 1] == pytest.approx(BLOCKED) and np.count_nonzero(diff) == 1
    start = source([0], [problem.init]).compute()[0]
    assert start[2, 1] < BLOCKED  # the same move in another state: not ruled out
    never = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home, check=None), places=[at], reach=0.01
    )
    assert never.verify(0, moved, Move("c", "b"))  # no check: every move passes
    moving = ArmCosts(
        [problem],
        [poses],
        SCENE,
        Arm(solver, PANDA.q_home, check=lambda seen, move: False),
        places=[at],
        reach=0.01,
    )
    assert moving.verify(0, moved, Move("c", "b"))  # places that move are not known yet


def test_planning_on_places_names_them_and_never_needs_more_than_the_table_has(solver):
    # five single blocks on a 6-slot table; the goal is one tower: no place is needed beyond
    five = Problem(
        "five",
        "blocksworld",
        tuple("abcde"),
        (TABLE,) * 5,
        (("a", "b"), ("b", "c"), ("c", "d"), ("d", "e")),
    )
    scene = with_scene(SCENE, "cramped")
    poses = layout(five.entities, five.init, scene, seed=1)
    config = dataclasses.replace(PlannerConfig(), lambda_motion=0.05)
    result = plan_on_places(five, poses, scene, Arm(solver, PANDA.q_home), config, seed=0)
    assert result.solved and [str(m) for m in result.plan] == [
        "move(d -> e)",
        "move(c -> d)",
        "move(b -> c)",
        "move(a -> b)",
    ]


@pytest.mark.sim
def test_a_cramped_table_the_unlimited_plan_overflows_is_solved_on_its_places():
    """Ten blocks in five towers on the 6-slot ``cramped`` scene: the task-only plan puts more
    blocks on the table than there are slots (the arm finds no free slot); motion-aware
    planning on the places reaches the goal without a replan, every table move at a place."""
    import random

    from task.symbolic.generate import random_problem

    seeds = random.Random("0:10")
    problem = [random_problem(10, seeds.randrange(2**31)) for _ in range(8)][7]
    base = LoopConfig()
    base = dataclasses.replace(base, scene=with_scene(base.scene, "cramped"))
    aware = dataclasses.replace(base, planner=dataclasses.replace(base.planner, lambda_motion=0.05))
    blind = run_episode(problem, base, seed=0)  # its plans overflow the table: replans
    assert "no_free_slot" in {m.failure.value for m in blind.moves if not m.ok}
    report = run_episode(problem, aware, seed=0)
    assert report.reached_goal and report.replans == 0
    table = [m.move for m in report.moves if m.move.target == TABLE]
    assert table and all(isinstance(m, PlacedMove) for m in table)
    assert all(min(math.dist(m.at, s) for s in aware.scene.slots) < 1e-9 for m in table)


@pytest.mark.sim
def test_the_check_ahead_vets_every_planned_move_and_the_cramped_table_is_still_solved(
    monkeypatch,
):
    """`LoopConfig.check_ahead`: the executor's motion check runs on the moves the windows
    keep, on the poses the plan predicts, and the cramped ten-block episode still reaches the
    goal without a replan."""
    import random

    import tamp.loop.episode as episode
    from task.symbolic.generate import random_problem

    seeds = random.Random("0:10")
    problem = [random_problem(10, seeds.randrange(2**31)) for _ in range(8)][7]
    base = LoopConfig()
    aware = dataclasses.replace(
        base,
        scene=with_scene(base.scene, "cramped"),
        planner=dataclasses.replace(base.planner, lambda_motion=0.05),
        check_ahead=True,
    )
    checked = []
    real = episode.motion_check

    def counted(tools, move, poses, *rest):
        checked.append(move)
        return real(tools, move, poses, *rest)

    monkeypatch.setattr(episode, "motion_check", counted)
    report = run_episode(problem, aware, seed=0)
    assert report.reached_goal and report.replans == 0
    assert len(checked) >= len(report.moves)  # every executed move was checked ahead


def test_the_check_ahead_is_refused_where_it_cannot_apply():
    from task.errors import TampError

    aware = LoopConfig(planner=dataclasses.replace(PlannerConfig(), lambda_motion=0.05))
    assert dataclasses.replace(aware, check_ahead=True).check_ahead
    refused = (
        {"placements": 0.01},
        {"planner": PlannerConfig()},  # task-only: no prices, no windows to vet
        {"execution": dataclasses.replace(aware.execution, collision="off")},
    )
    for change in refused:
        with pytest.raises(TampError, match="check_ahead needs"):
            dataclasses.replace(aware, check_ahead=True, **change)


def test_random_suites_keep_the_problems_that_fit_the_scene():
    from tamp.bench.suites import generated
    from tamp.slots import fits
    from task.symbolic.generate import random_problem

    cramped = with_scene(SCENE, "cramped")
    spread = random_problem(10, 3)
    assert not fits(dataclasses.replace(spread, init=(TABLE,) * 10), cramped)  # 10 towers
    assert fits(dataclasses.replace(spread, init=(TABLE,) * 10), SceneConfig()) is False
    suite = generated([10], 3, seed=0, max_nodes=10, keep=lambda p: fits(p, cramped))
    assert len(suite.instances) == 3
    assert all(fits(i.problem, cramped) for i in suite.instances)
    assert [i.name for i in suite.instances] == [f"random-10/instance-{k}" for k in (1, 2, 3)]
    stream = [i.problem for i in generated([10], 12, seed=0, max_nodes=10).instances]
    fitting = [p.init for p in stream if fits(p, cramped)]
    assert len(fitting) < len(stream)  # the scene does reject some
    assert [i.problem.init for i in suite.instances] == fitting[:3]  # the first that fit


def test_continuous_placements_are_differentiable_offsets_the_planner_optimises(solver):
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    problem, at = slotted(FOUR, FOUR.init, poses, SCENE)
    source = ArmCosts([problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at], reach=0.02)
    window = source([0], [problem.init])  # one restart row
    (u,) = window.parameters()
    assert u.shape == (1, len(at), 2) and torch.count_nonzero(u) == 0
    fixed = ArmCosts([problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at])
    start = window.compute()
    assert torch.allclose(start, fixed([0], [problem.init]).compute(), atol=1e-6)

    def table_cost(v):  # the cost of moving block a onto every place, as a function of u
        with torch.no_grad():
            u.copy_(v)
            return float(window.compute()[0, 0, 4:].sum())

    v = torch.full_like(u, 0.3).requires_grad_(True)
    with torch.no_grad():
        u.copy_(v)
    grad = torch.autograd.grad(window.compute()[0, 0, 4:].sum(), u)[0]  # (1, K, 2)
    eps = 1e-6
    for k, d in ((0, 0), (3, 1), (7, 0)):
        up, down = v.detach().clone(), v.detach().clone()
        up[0, k, d] += eps
        down[0, k, d] -= eps
        numeric = (table_cost(up) - table_cost(down)) / (2 * eps)
        assert float(grad[0, k, d]) == pytest.approx(numeric, rel=1e-3, abs=1e-6)
    with torch.no_grad():
        u.zero_()
    opt = torch.optim.SGD(window.parameters(), lr=window.lr)
    for _ in range(20):
        opt.zero_grad()
        window.compute()[0, 0, 4:].sum().backward()
        opt.step()
    assert window.compute()[0, 0, 4:].sum() < start[0, 0, 4:].sum()
    dx, dy = (0.02 * torch.tanh(u[0, problem.fixed.index("slot2")])).tolist()
    assert 0 < math.hypot(dx, dy) <= 0.02 * math.sqrt(2)


def test_every_move_keeps_the_placement_its_window_decided(solver):
    """A plan cut after its first window and the whole plan (same seed: the same first window)
    put the first window's blocks at the same positions: later windows optimise placements of
    their own and never move an executed decision. Every table move stays within reach of its
    place's centre, and moved off it (the placements were optimised)."""
    five = Problem(
        "five",
        "blocksworld",
        tuple("abcde"),
        ("b", "c", TABLE, "e", TABLE),
        (("c", "a"), ("e", "b")),
    )
    poses = layout(five.entities, five.init, SCENE, seed=1)
    config = dataclasses.replace(PlannerConfig(), lambda_motion=0.05, restarts=2, iters=40)
    whole = plan_on_places(five, poses, SCENE, Arm(solver, PANDA.q_home), config, reach=0.02)
    first = dataclasses.replace(config, max_windows=1, fallback=False)  # the first window only
    cut = plan_on_places(five, poses, SCENE, Arm(solver, PANDA.q_home), first, reach=0.02)
    assert whole.solved and whole.stats["windows"] >= 2 and cut.stats["windows"] == 1
    table = [m for m in whole.plan if m.target == TABLE]
    early = [m for m in cut.plan if m.target == TABLE]
    assert early and len(table) > len(early)
    assert list(whole.plan.moves[: len(cut.plan)]) == list(cut.plan.moves)
    for m, decided in zip(table, early, strict=False):
        assert m.at == pytest.approx(decided.at, abs=1e-9) and m.place == decided.place
    _, centre = slotted(five, five.init, poses, SCENE)
    for m in table:
        off = math.dist(m.at, centre[m.place])
        assert 1e-4 < off <= 0.02 * math.sqrt(2) + 1e-9  # moved off the centre, within reach


def test_a_goal_tower_taller_than_the_scene_takes_is_unsolvable_at_once(solver, monkeypatch):
    """Eight blocks on the table, the goal one tower of all eight: the scene's towers take
    seven (``max_height``), so motion-aware planning says UNSOLVABLE with the reason, without
    a search. Seven of them in one tower is within the limit."""
    import itertools

    import tamp.slots
    from tamp.slots import goal_height
    from task.problem import PlanStatus

    names = tuple("abcdefgh")
    chain = tuple(itertools.pairwise(names))  # a on b on ... on h
    eight = Problem("eight", "blocksworld", names, (TABLE,) * 8, chain)
    assert goal_height(eight) == 8 and goal_height(FOUR) == 2
    poses = layout(names, eight.init, SCENE, seed=0)
    searched = []
    monkeypatch.setattr(tamp.slots, "plan", lambda *a, **kw: searched.append(a))
    result = plan_on_places(eight, poses, SCENE, Arm(solver, PANDA.q_home), PlannerConfig())
    assert result.status is PlanStatus.UNSOLVABLE and searched == []
    assert (
        "stacks 8 blocks in one tower" in result.stats["reason"]
        and "at most 7" in result.stats["reason"]
    )
    seven = dataclasses.replace(eight, goal=chain[1:])  # b on ... on h
    assert goal_height(seven) == 7


def test_a_block_parked_twice_in_a_row_moves_once_where_the_arm_may(solver):
    """The windows commit moves one by one, so a plan may move a block twice in a row:
    `_merge_runs` makes the run one move where the same state follows and the arm's prices
    leave that move open, and leaves it where they rule the move out (a failure there)."""
    from tamp.slots import _merge_runs

    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    problem, at = slotted(FOUR, FOUR.init, poses, SCENE)
    run = [Move("a", "slot2"), Move("a", "d"), Move("b", "c")]
    costs = ArmCosts([problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at])
    assert _merge_runs(problem, run, costs) == (Move("a", "d"), Move("b", "c"))
    back = [Move("a", "slot2"), Move("a", "b"), Move("a", "d"), Move("b", "c")]
    assert _merge_runs(problem, back, costs) == (Move("a", "d"), Move("b", "c"))
    avoid = {FOUR.init: {failed_key(Move("a", "d"))}}  # a onto d failed in the initial state
    priced = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home, avoid=avoid), places=[at]
    )
    assert _merge_runs(problem, run, priced) == tuple(run)
