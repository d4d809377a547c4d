"""The differentiable move cost: shapes, distance ordering, unreachable targets, gradients."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from motion.cost import MoveCostConfig, move_costs, move_costs_batch, top_down_targets
from motion.errors import MotionError
from motion.ik import top_down_pose
from robots.panda import PANDA

PICKS = ((0.50, 0.00, 0.025), (0.45, 0.10, 0.025))  # block centres on the table
PLACES = ((0.50, -0.05, 0.075), (0.40, -0.20, 0.025))  # on a block / a free table spot


def _t(rows) -> torch.Tensor:
    return torch.tensor(rows, dtype=torch.float64)


def _freeze_ik(monkeypatch, solver) -> None:
    """Make ``solver.solve`` return its first answer from then on: the detached q* held fixed."""
    real, cache = solver.solve, []

    def frozen(targets, q_current):
        if not cache:
            cache.append(real(targets, q_current))
        return cache[0]

    monkeypatch.setattr(solver, "solve", frozen)


def test_top_down_targets_match_top_down_pose_and_carry_gradients():
    xyz = _t([[[0.4, 0.1, 0.2], [0.5, -0.1, 0.03]]]).requires_grad_()  # (1, 2, 3)
    h = top_down_targets(xyz)
    assert h.shape == (1, 2, 4, 4) and h.dtype == torch.float64
    for k in range(2):
        np.testing.assert_allclose(h[0, k].detach().numpy(), top_down_pose(xyz[0, k].tolist(), 0.0))
    h[..., :3, 3].sum().backward()
    np.testing.assert_allclose(xyz.grad.numpy(), np.ones((1, 2, 3)))


def test_costs_have_shape_n_by_y_and_are_finite_and_non_negative(solver):
    picks = _t((*PICKS, (0.55, -0.15, 0.075)))  # (3, 3)
    places = _t((*PLACES, (0.6, 0.2, 0.025), (0.35, 0.0, 0.125)))  # (4, 3)
    c = move_costs(solver, PANDA.q_home, picks, places)
    assert c.shape == (3, 4) and c.dtype == torch.float64
    assert torch.isfinite(c).all() and (c >= 0).all()
    assert (c < MoveCostConfig().infeasible / 2).all()  # all reachable: no penalty anywhere


def test_a_far_place_costs_more_than_a_near_one(solver):
    picks = _t([PICKS[0]])  # (1, 3)
    places = _t([(0.50, dy, 0.075) for dy in (0.05, 0.15, 0.25)])  # (3, 3), ever farther
    c = move_costs(solver, PANDA.q_home, picks, places)[0]  # (3,)
    assert c[0] < c[1] < c[2]


def test_an_unreachable_place_costs_more_than_half_the_infeasibility_penalty(solver):
    config = MoveCostConfig()
    places = _t((*PLACES, (1.5, 0.0, 0.025)))  # (3, 3): the last is beyond the arm's reach
    c = move_costs(solver, PANDA.q_home, _t(PICKS), places, config)
    assert torch.isfinite(c).all()
    assert (c[:, 2] > config.infeasible / 2).all()  # its column says so
    assert (c[:, :2] < config.infeasible / 2).all()  # and only its column
    # 1.5 m lies ~0.6 m beyond the reach of ~0.9 m: the residual alone weighs in
    assert (c[:, 2] > config.infeasible + config.reach_weight * 0.5).all()


def test_batch_over_problems_matches_one_problem_at_a_time(solver):
    picks = torch.stack([_t(PICKS), _t(PICKS) + _t([0.05, 0.0, 0.0])])  # (2, 2, 3)
    places = torch.stack([_t(PLACES), _t(PLACES) - _t([0.0, 0.05, 0.0])])  # (2, 2, 3)
    batch = move_costs_batch(solver, PANDA.q_home, picks, places)  # (2, 2, 2)
    for p in range(2):
        one = move_costs(solver, PANDA.q_home, picks[p], places[p])
        torch.testing.assert_close(batch[p], one, atol=1e-9, rtol=0)


def test_gradient_matches_finite_differences_with_the_ik_solution_held_fixed(solver, monkeypatch):
    # The inner IK solve reruns on every perturbed input and may land elsewhere on the Panda's
    # 1-D self-motion manifold (early stopping at the tolerance): the refined q keeps that
    # null-space drift, so finite differences of the full function differ by ~1e-2. The gradient
    # is that of the refined cost with the detached solution q* fixed; check exactly that, with
    # an unreachable place (its row keeps q*, its residual still has a gradient) included.
    _freeze_ik(monkeypatch, solver)
    picks = _t(PICKS).requires_grad_()  # (2, 3)
    places = _t((*PLACES, (1.5, 0.0, 0.025))).requires_grad_()  # (3, 3)

    def cost(a, b):
        return move_costs(solver, PANDA.q_home, a, b)

    assert torch.autograd.gradcheck(cost, (picks, places), eps=1e-6, atol=1e-4)


def test_a_step_against_the_gradient_lowers_the_cost(solver):
    picks = _t([PICKS[0]])  # (1, 3)
    places = _t([(0.40, -0.20, 0.075)]).requires_grad_()  # (1, 3)
    c = move_costs(solver, PANDA.q_home, picks, places)[0, 0]
    (grad,) = torch.autograd.grad(c, places)
    assert grad.norm() > 0
    toward = (picks - places).detach()
    assert (grad * toward).sum() < 0  # descending moves the place toward the pick
    step = places.detach() - 0.005 * grad / grad.norm()  # 5 mm, IK re-solved from scratch
    assert move_costs(solver, PANDA.q_home, picks, step)[0, 0] < c.detach()


POST = (_t([[0.5, 0.0, 0.1]]), _t([[0.03, 0.03, 0.1]]))  # a 20 cm post at y = 0
FAR = (_t([[2.0, 2.0, 0.1]]), _t([[0.03, 0.03, 0.1]]))
SWEPT = _t([(0.5, -0.2, 0.025), (0.45, 0.25, 0.025)])  # (2, 3): one each side of the post
ACROSS = _t([(0.5, 0.2, 0.075), (0.4, 0.35, 0.025)])  # (2, 3): both on the second one's side


@pytest.mark.parametrize("obstacles", [None, POST, FAR], ids=["none", "post", "far"])
def test_a_collision_weight_of_zero_or_no_obstacles_leave_the_costs_unchanged(solver, obstacles):
    old = move_costs(solver, PANDA.q_home, SWEPT, ACROSS)
    off = move_costs(solver, PANDA.q_home, SWEPT, ACROSS, MoveCostConfig(), obstacles)
    assert torch.equal(off, old)
    on = MoveCostConfig(collision_weight=1.0)
    if obstacles is not POST:  # nothing there, or nothing within the margin: exactly no change
        assert torch.equal(move_costs(solver, PANDA.q_home, SWEPT, ACROSS, on, obstacles), old)


def test_a_post_across_the_transit_raises_only_the_moves_past_it(solver):
    config = MoveCostConfig(collision_weight=1.0)
    old = move_costs(solver, PANDA.q_home, SWEPT, ACROSS)
    extra = move_costs(solver, PANDA.q_home, SWEPT, ACROSS, config, POST) - old  # (2, 2)
    assert (extra[0] > 0.05).all()  # from y = -0.2 across the post
    assert (extra[1] == 0).all()  # on its own side, more than the margin away
    # the ends alone do not see it: only the inner points of the joint segment do
    ends = replace(config, collision_points=2)
    assert torch.equal(move_costs(solver, PANDA.q_home, SWEPT, ACROSS, ends, POST), old)


def test_gradient_of_the_collision_term_matches_finite_differences(solver, monkeypatch):
    _freeze_ik(monkeypatch, solver)  # the detached q* held fixed, as above
    config = MoveCostConfig(collision_weight=1.0)
    picks = SWEPT.clone().requires_grad_()
    places = ACROSS.clone().requires_grad_()

    def cost(a, b):
        on = move_costs(solver, PANDA.q_home, a, b, config, POST)
        return on - move_costs(solver, PANDA.q_home, a, b)  # the collision term alone

    assert (cost(picks, places)[0] > 0).all()
    assert torch.autograd.gradcheck(cost, (picks, places), eps=1e-6, atol=1e-4)


@pytest.mark.parametrize(
    ("config", "obstacles", "message"),
    [
        (MoveCostConfig(collision_weight=1.0, collision_points=1), POST, "collision_points"),
        (MoveCostConfig(collision_weight=1.0), (torch.zeros(1, 2), torch.ones(1, 3)), "centres"),
        (MoveCostConfig(collision_weight=1.0), (torch.zeros(1, 3), -torch.ones(1, 3)), "> 0"),
    ],
)
def test_collision_misuse_names_the_bad_input(solver, config, obstacles, message):
    with pytest.raises(MotionError, match=message):
        move_costs(solver, PANDA.q_home, _t(PICKS), _t(PLACES), config, obstacles)


@pytest.mark.parametrize(
    ("picks", "places", "message"),
    [
        (torch.zeros(2, 2), torch.zeros(1, 3), "picks has shape"),
        (torch.zeros(2, 3), torch.zeros(3), "places has shape"),
        (torch.full((1, 3), float("nan")), torch.zeros(1, 3), "picks contains NaN"),
    ],
)
def test_misuse_names_the_bad_input(solver, picks, places, message):
    with pytest.raises(MotionError, match=message):
        move_costs(solver, PANDA.q_home, picks, places)
