"""Motion-aware planning's move costs from the scene (`tamp.arm.costs`): predicted poses, the
cost matrix's shape and meaning, blocked places under a shelf, and an episode planned with
them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.arm.arm import Arm
from tamp.arm.costs import ARM, BLOCKED, ArmCosts
from tamp.arm.predict import predict_poses
from tamp.loop import LoopConfig, run_episode
from tamp.obstacles import with_scene
from tamp.scene import SceneConfig, layout
from task.config import PlannerConfig
from task.problem import TABLE, Problem

SCENE = SceneConfig()
FOUR = Problem(
    "four", "blocksworld", ("a", "b", "c", "d"), ("b", TABLE, TABLE, TABLE), (("b", "c"),)
)


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


def test_predicted_poses_keep_towers_in_place_and_put_new_ones_on_free_slots():
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 4, 9])
    same = predict_poses(FOUR.entities, FOUR.init, poses, SCENE)
    for x in FOUR.entities:
        assert np.allclose(same[x].xyz, poses[x].xyz, atol=1e-9)
    moved = predict_poses(FOUR.entities, (TABLE, "c", TABLE, TABLE), poses, SCENE)
    assert np.allclose(moved["b"].xyz[:2], poses["c"].xyz[:2])  # b now stands on c
    assert moved["b"].xyz[2] == pytest.approx(0.075)
    assert min(np.linalg.norm(moved["a"].xy - p.xy) for k, p in moved.items() if k != "a") > 0.1


def test_costs_are_one_matrix_per_problem_and_a_far_place_costs_more(solver):
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])  # a-b, c, d
    source = ArmCosts([FOUR], [poses], SCENE, Arm(solver, PANDA.q_home))
    window = source([0], [FOUR.init])
    c = window.compute()
    assert c.shape == (1, 4, 5) and torch.isfinite(c).all() and window.parameters() == []
    # c stands next to a's tower (slot 1), d at the far end (slot 9)
    assert c[0, 0, 2] < c[0, 0, 3]
    assert torch.equal(source([0], [FOUR.init]).compute(), c)  # a new window: the same costs


def test_a_tower_at_its_slots_clearance_blocks_one_more_block(solver):
    shelf = with_scene(SCENE, "shelf")
    five = Problem(
        "five", "blocksworld", tuple("abcdef"), (TABLE, "a", "b", "c", "d", TABLE), (("f", "e"),)
    )
    poses = layout(five.entities, five.init, SCENE, seed=0, slots=[8, 0])  # the tower under it
    c = ArmCosts([five], [poses], shelf, Arm(solver, PANDA.q_home))([0], [five.init]).compute()
    assert shelf.capacity(poses["a"].xy) == 5
    assert c[0, 5, 4] >= BLOCKED and c[0, 5, 6] < BLOCKED  # f onto e (6th), f onto the table


def test_a_motion_aware_episode_takes_the_move_the_arm_prefers(solver):
    """a must leave b: onto d or onto the table, two moves either way. Planning for the task
    alone, this episode (seed 0) puts a onto d; with the arm's costs it puts a on a table
    place that the arm prices below a onto d, at that place's centre, and both moves run."""
    from tamp.scene import PlacedMove
    from tamp.slots import slotted

    config = LoopConfig(planner=PlannerConfig(lambda_motion=0.05))
    report = run_episode(FOUR, config, seed=0, solver=solver)
    assert report.reached_goal and len(report.moves) == 2 and all(m.ok for m in report.moves)
    first = report.moves[0].move
    assert isinstance(first, PlacedMove) and first.entity == "a" and first.target == TABLE
    poses = layout(FOUR.entities, FOUR.init, config.scene, 0)  # the episode's layout
    problem, at = slotted(FOUR, FOUR.init, poses, config.scene)
    source = ArmCosts([problem], [poses], config.scene, Arm(solver, PANDA.q_home), places=[at])
    c = source([0], [problem.init]).compute()[0]
    assert first.at == at[first.place]
    assert c[0, problem.n + problem.fixed.index(first.place)] < c[0, 3]  # below a onto d


def test_the_planning_loss_differentiates_through_the_arm_into_logits_and_places(monkeypatch):
    """End to end in float64: the rollout loss with the arm's move costs (pytorch-kinematics,
    one differentiable IK step) has the gradient finite differences give, for the action
    logits and for the place positions (the detached IK solution held fixed, as in
    tests/motion/test_cost.py: the gradient is that of the refined cost at fixed q*)."""
    from motion.cost import move_costs
    from task.domains import get_domain
    from task.rollout import rollout

    solver, bw = IKSolver(), get_domain("blocksworld")
    real, cache = solver.solve, []
    monkeypatch.setattr(
        solver, "solve", lambda t, q: cache[0] if cache else cache.append(real(t, q)) or cache[0]
    )
    batch = bw.encode([FOUR], [bw.initial_state(FOUR)], torch.float64)
    steps = torch.ones(1, 2, dtype=torch.bool)
    logits = torch.randn(
        (1, 2, 4, 6), generator=torch.Generator().manual_seed(0), dtype=torch.float64
    ).requires_grad_(True)
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0)
    picks = torch.tensor([poses[x].xyz for x in FOUR.entities], dtype=torch.float64)
    places = torch.cat(
        [picks + torch.tensor([0.0, 0.0, 0.05]), torch.tensor([[0.45, 0.3, 0.025]])]
    ).requires_grad_(True)
    config = PlannerConfig(horizon=2, lambda_motion=0.5)

    def loss(lg, pl):
        costs = move_costs(solver, PANDA.q_home, picks, pl)[None]  # (1, N, Y)
        return rollout(bw, lg, batch, steps, config, costs=costs).loss.sum()

    assert torch.autograd.gradcheck(loss, (logits, places), eps=1e-6, atol=1e-4)


def test_the_collision_proxy_prices_sweeps_past_the_scenes_obstacles_only(solver):
    from tamp.arm.costs import obstacle_tensors

    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 4, 9])
    costs = {}
    for name in ("tabletop", "clutter"):
        scene = with_scene(SCENE, name)
        for cfg in (ARM, replace(ARM, collision_weight=0.0)):
            source = ArmCosts([FOUR], [poses], scene, Arm(solver, PANDA.q_home), config=cfg)
            costs[name, cfg.collision_weight] = source([0], [FOUR.init]).compute()[0]
    assert obstacle_tensors(with_scene(SCENE, "tabletop"))[0].shape == (0, 3)
    assert torch.equal(costs["tabletop", 5.0], costs["tabletop", 0.0])
    extra = costs["clutter", 5.0] - costs["clutter", 0.0]
    assert (extra >= 0).all() and (extra > 0.05).any()


def test_a_place_the_hand_cannot_reach_at_hover_height_is_ruled_out(solver):
    """On the cramped scene the far row (x = 0.72 m) is reachable over a low scene but not
    over a 7-block tower, which the hand must clear while carrying a block."""
    from tamp.slots import slotted

    cramped = with_scene(SCENE, "cramped")
    low = Problem("low", "blocksworld", ("a", "b"), (TABLE, TABLE), (("a", "b"),))
    tall = Problem(
        "tall",
        "blocksworld",
        tuple("abcdefg"),
        (TABLE, "a", "b", "c", "d", "e", "f"),
        (("a", "g"),),
    )
    for problem, blocked in ((low, False), (tall, True)):
        slots = [0] if problem is tall else [0, 1]
        poses = layout(problem.entities, problem.init, cramped, seed=0, slots=slots)
        current, at = slotted(problem, problem.init, poses, cramped)
        source = ArmCosts([current], [poses], cramped, Arm(solver, PANDA.q_home), places=[at])
        matrix = source([0], [current.init]).compute()[0]
        far = [problem.n + j for j, k in enumerate(current.fixed) if at[k][0] > 0.7]
        assert len(far) == 2
        top = problem.entities[-1]  # the block on top, free to move
        assert (matrix[problem.entities.index(top), far] >= BLOCKED).all() == blocked


def _behind(near: int):
    """On the cramped table: a tower of ``near`` blocks in the middle row (0.56, -0.12), one
    block behind it in the far row (0.72, -0.12) and one to move at (0.40, 0.12); the slotted
    problem, its places, the poses, and the indices of the moving block and the far one."""
    from tamp.slots import slotted

    cramped = with_scene(SCENE, "cramped")
    names = tuple("abcdefgh"[: near + 2])
    init = (TABLE, *names[: near - 1], TABLE, TABLE)  # the tower, the far block, the mover
    problem = Problem("behind", "blocksworld", names, init, ((names[-1], names[-2]),))
    poses = layout(names, init, cramped, seed=0, slots=[2, 4, 1])
    current, at = slotted(problem, init, poses, cramped)
    return cramped, current, at, poses, near + 1, near


@pytest.mark.parametrize(("near", "blocked"), [(6, True), (3, False)])
def test_a_release_behind_a_tall_near_tower_is_ruled_out(solver, near, blocked):
    # the executor's guard finds the forearm in the near tower for 6 blocks (both grasps)
    cramped, current, at, poses, mover, far = _behind(near)
    costs = {}
    for weight in (ARM.block_weight, 0.0):
        source = ArmCosts(
            [current],
            [poses],
            cramped,
            Arm(solver, PANDA.q_home),
            config=replace(ARM, block_weight=weight),
            places=[at],
        )
        costs[weight] = source([0], [current.init]).compute()[0]
    assert bool(costs[ARM.block_weight][mover, far] >= BLOCKED) == blocked
    assert costs[0.0][mover, far] < BLOCKED  # without the blocks in the proxy: never
    extra = costs[ARM.block_weight] - costs[0.0]
    assert (extra >= 0).all() and (extra[mover, far] > 0) == blocked


def test_a_placed_window_at_zero_offsets_prices_like_a_fixed_one_blocks_included(solver):
    cramped, current, at, poses, mover, far = _behind(6)
    fixed = ArmCosts([current], [poses], cramped, Arm(solver, PANDA.q_home), places=[at])
    placed = ArmCosts(
        [current], [poses], cramped, Arm(solver, PANDA.q_home), places=[at], reach=0.03
    )
    window = placed([0], [current.init])
    c = window.compute()
    torch.testing.assert_close(c, fixed([0], [current.init]).compute(), atol=1e-9, rtol=0)
    assert c[0, mover, far] >= BLOCKED
    (grad,) = torch.autograd.grad(c[0, mover, current.n :].sum(), window.parameters())
    assert torch.isfinite(grad).all()


def test_each_point_is_solved_once_per_source_with_the_batched_reach(solver, monkeypatch):
    """A search prices many states whose blocks stand on the same spots: each point's IK is
    solved once per source. Whether it is reached is what a batched call says; a second state
    with the same points solves nothing."""
    import tamp.arm.sites as sites
    from motion.cost import site_solutions

    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 4, 9])
    source = ArmCosts([FOUR], [poses], SCENE, Arm(solver, PANDA.q_home))
    picks = torch.tensor([[poses[x].xyz for x in FOUR.entities]], dtype=torch.float64)
    places = torch.tensor([[(0.5, 0.0, 0.025), (2.0, 0.0, 0.025)]], dtype=torch.float64)
    q, ok = source.sites.solve(picks, places)
    ok_all = site_solutions(solver, PANDA.q_home, picks, places)[1]
    assert torch.equal(ok, ok_all) and not ok[-1] and ok[:-1].all()  # 2 m away: out of reach
    reached = solver.fk(q[ok].numpy())[:, :3, 3]
    assert np.allclose(reached, torch.cat([picks, places], 1)[0][ok].numpy(), atol=2e-3)
    calls = []
    monkeypatch.setattr(sites, "site_solutions", lambda *a: calls.append(a) or (q, ok))
    again = source.sites.solve(picks.flip(1), places)  # the same points, another order
    assert calls == [] and torch.equal(again[0][:4], q[:4].flip(0))


def test_a_failed_move_is_ruled_out_wherever_it_would_be_the_same(solver):
    """``failed``: a move the arm failed stays ruled out in any state where its block is
    picked where it was, the blocks then around it still there, and goes where it was to go,
    the blocks then around that still there; a pick that failed with every grasp rules out
    every move of its block there. Once a neighbour has gone, or the block stands elsewhere,
    it may be tried again."""
    from tamp.arm.failures import FailedMove, Site
    from tamp.scene import Pose

    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])  # a-b, c, d
    site = Site.at(poses["c"].xyz, poses, "c")
    assert [name for name, _ in site.around] == ["a", "b"]  # d stands at the far end
    assert site.matches(poses["c"].xyz, poses, "c")
    nudged = {**poses, "a": Pose(tuple(np.add(poses["a"].xyz, (0.005, 0.0, 0.0))))}
    assert site.matches(poses["c"].xyz, nudged, "c")  # observation noise
    assert not site.matches(poses["c"].xyz, {k: v for k, v in poses.items() if k != "a"}, "c")
    assert not site.matches(np.add(poses["c"].xyz, (0.0, 0.05, 0.0)), poses, "c")
    crowded = {**poses, "d": Pose(tuple(np.add(poses["c"].xyz, (0.1, 0.0, 0.0))))}
    assert site.matches(poses["c"].xyz, crowded, "c")  # another block near: no easier

    onto_d = np.add(poses["d"].xyz, (0.0, 0.0, SCENE.block_size))
    plain = ArmCosts([FOUR], [poses], SCENE, Arm(solver, PANDA.q_home))([0], [FOUR.init]).compute()[
        0
    ]
    assert (plain[2] < BLOCKED).all()
    for pick_only, ruled in ((False, [3]), (True, [0, 1, 2, 3, 4])):
        failed = FailedMove.of("c", poses, onto_d, pick_only)
        source = ArmCosts([FOUR], [poses], SCENE, Arm(solver, PANDA.q_home, failed=[failed]))
        c = source([0], [FOUR.init]).compute()[0]
        assert [j for j in range(5) if c[2, j] >= BLOCKED] == ruled  # columns a, b, c, d, table
        torch.testing.assert_close(c[[0, 1, 3]], plain[[0, 1, 3]], atol=0, rtol=0)
        # a off b onto the table: c's pick site is no longer what it was
        after = source([0], [(TABLE, TABLE, TABLE, TABLE)]).compute()[0]
        assert (after[2, [0, 1, 3]] < BLOCKED).all()
