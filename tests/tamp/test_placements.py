"""Continuous table placements (`tamp.arm.costs` with ``reach`` > 0, `tamp.slots`): each
restart row optimises its own offsets, fresh in every window; a committed move keeps the
position its row decided; a failed move at an offset position is priced out at its place."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.arm.arm import Arm
from tamp.arm.costs import BLOCKED, ArmCosts
from tamp.arm.failures import failed_key
from tamp.scene import PlacedMove, layout
from tamp.slots import slotted
from task.problem import TABLE, Move
from tests.tamp.test_arm_costs import FOUR, SCENE

REACH = 0.02


@pytest.fixture(scope="module")
def solver() -> IKSolver:
    return IKSolver()


@pytest.fixture(scope="module")
def four():
    """FOUR on slots 0, 1, 9 (a on b at slot 0, c at slot 1, d at slot 9), slotted."""
    poses = layout(FOUR.entities, FOUR.init, SCENE, seed=0, slots=[0, 1, 9])
    problem, at = slotted(FOUR, FOUR.init, poses, SCENE)
    return problem, at, poses


def test_each_restart_row_optimises_its_own_placements_fresh_every_window(solver, four):
    problem, at, poses = four
    source = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at], reach=REACH
    )
    window = source([0], [problem.init], 3)
    (u,) = window.parameters()
    c = window.compute()
    assert u.shape == (3, len(at), 2) and c.shape == (3, problem.n, problem.n + len(at))
    assert torch.equal(c[0], c[1]) and torch.equal(c[1], c[2])  # all start at the centres
    (grad,) = torch.autograd.grad(c[1, 0, problem.n :].sum(), u)  # row 1's table costs
    assert grad[1].abs().sum() > 0
    assert torch.count_nonzero(grad[0]) == 0 and torch.count_nonzero(grad[2]) == 0
    with torch.no_grad():
        u[1].fill_(1.0)
    moved = window.compute()
    assert torch.equal(moved[0], c[0]) and not torch.equal(moved[1], c[1])
    again = source([0], [problem.init], 3)  # the next window starts from the centres again
    (fresh,) = again.parameters()
    assert fresh is not u and torch.count_nonzero(fresh) == 0
    torch.testing.assert_close(again.compute(), c, atol=0, rtol=0)


def test_a_committed_move_keeps_the_position_of_the_row_it_came_from(solver, four):
    problem, at, poses = four
    source = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at], reach=REACH
    )
    window = source([0], [problem.init], 3)
    (u,) = window.parameters()
    with torch.no_grad():
        u.copy_(torch.linspace(-2.0, 2.0, u.numel(), dtype=u.dtype).reshape(u.shape))
    k = problem.fixed.index("slot4")
    window.commit([2], [(Move("a", "slot4"), Move("b", "c"))])
    (first, xy), (second, none) = source.decided(0)
    dx, dy = (REACH * torch.tanh(u[2, k])).tolist()
    assert first == Move("a", "slot4") and second == Move("b", "c") and none is None
    assert xy == pytest.approx((at["slot4"][0] + dx, at["slot4"][1] + dy), abs=1e-12)
    later = source([0], [("slot4", "c", "slot1", "slot9")], 3)  # a window that moves nothing
    later.commit([None], [(Move("c", "slot6"),)])  # from a retry without these costs
    assert source.decided(0)[2] == (Move("c", "slot6"), at["slot6"])


@pytest.mark.parametrize("named", [True, False])
def test_a_failed_move_at_an_offset_position_is_priced_out_at_its_place(solver, four, named):
    """The executed position of a placed move is its place's centre plus up to ``reach`` in x
    and y: the failure is matched to that place, in the state it failed in, not elsewhere."""
    problem, at, poses = four
    cx, cy = at["slot7"]
    where = (cx + 0.8 * REACH, cy - 0.9 * REACH)  # 2.4 cm from the centre
    place = {"place": "slot7"} if named else {}  # unnamed: matched by position alone
    failed = PlacedMove("a", TABLE, where, **place)
    far = PlacedMove("c", TABLE, (cx + 0.08, cy), **place)  # beyond the place's reach
    avoid = {FOUR.init: {failed_key(failed), failed_key(far)}}
    plain = ArmCosts([problem], [poses], SCENE, Arm(solver, PANDA.q_home), places=[at], reach=REACH)
    priced = ArmCosts(
        [problem], [poses], SCENE, Arm(solver, PANDA.q_home, avoid=avoid), places=[at], reach=REACH
    )
    with torch.no_grad():
        diff = priced([0], [problem.init]).compute() - plain([0], [problem.init]).compute()
    j = problem.n + problem.fixed.index("slot7")
    assert float(diff[0, 0, j]) == pytest.approx(BLOCKED)
    assert np.count_nonzero(diff.numpy()) == 1  # not c's move 8 cm away
