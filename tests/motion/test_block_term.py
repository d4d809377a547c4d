"""The move cost's block term: the other blocks priced at the grasp and the release only."""

from __future__ import annotations

from dataclasses import replace

import pytest
import torch

from motion.cost import (
    Blocks,
    Bodies,
    MoveCostConfig,
    block_depths,
    block_term,
    move_costs_batch,
    site_solutions,
)
from motion.errors import MotionError
from motion.spheres import box_contacts
from robots.panda import PANDA

S = 0.05  # block edge, m
FAR = (0.68, 0.0, S / 2)  # a block in the far row
HELD = (0.40, 0.25, S / 2)  # the block that moves, well away from everything
TABLE = (0.40, -0.25, S / 2)  # a free table place
ON = MoveCostConfig(block_weight=1.0)


def _scene(near: int) -> tuple[torch.Tensor, torch.Tensor, Blocks]:
    """Picks (1, N, 3), places (1, N + 1, 3) and blocks: block 0 in the far row, block 1 the
    held one, blocks 2.. a tower of ``near`` blocks in front of block 0 (x = 0.56 m)."""
    rows = [FAR, HELD] + [(0.56, 0.0, S / 2 + k * S) for k in range(near)]
    c = torch.tensor([rows], dtype=torch.float64)  # (1, N, 3)
    under = torch.tensor([[-1, -1] + [-1] * (near > 0) + list(range(2, 1 + near))])  # (1, N)
    on = c + torch.tensor([0.0, 0.0, S], dtype=torch.float64)  # (1, N, 3)
    places = torch.cat([on, torch.tensor([[TABLE]], dtype=torch.float64)], dim=1)
    return c, places, Blocks(c, torch.full_like(c, S / 2), under)


def _term(solver, near: int):
    picks, places, blocks = _scene(near)
    q, _ = site_solutions(solver, PANDA.q_home, picks, places)
    return block_term(solver, q.reshape(1, -1, 7), blocks), q, blocks


def _freeze_ik(monkeypatch, solver) -> None:
    real, cache = solver.solve, []
    monkeypatch.setattr(
        solver, "solve", lambda t, q: cache[0] if cache else cache.append(real(t, q)) or cache[0]
    )


def test_a_release_behind_a_tall_near_tower_costs_and_penetrates_a_low_one_does_not(solver):
    tall, _, _ = _term(solver, near=6)
    low, _, _ = _term(solver, near=2)
    # the held block (1) onto the far block (0): the forearm comes down onto the near tower
    assert tall.cost[0, 1, 0] > 0.1 and tall.depth[0, 1, 0] > 0.02
    assert low.cost[0, 1, 0] == 0 and low.depth[0, 1, 0] == 0
    # the same block to the free table place, away from the towers, pays nothing either way
    n = 2 + 6
    assert tall.cost[0, 1, n] == 0 and tall.depth[0, 1, n] == 0


def test_the_term_is_the_sum_over_the_counted_blocks_at_both_ends(solver):
    # brute force: each move's own box set at the grasp (without x and the block under x) and
    # at the release (without x and y), one box_contacts call per end
    term, q, blocks = _term(solver, near=5)
    c, under = blocks.centres[0], blocks.under[0].tolist()
    n = c.shape[0]
    for x in range(n):
        for y in range(n + 1):
            grasp = [b for b in range(n) if b not in (x, under[x])]
            release = [b for b in range(n) if b not in (x, y)]
            want = torch.zeros((), dtype=torch.float64)
            for site, keep in ((x, grasp), (n + y, release)):
                found = box_contacts(solver, q[site : site + 1], c[keep], blocks.half[0][keep])
                want = want + found.cost.sum()
            torch.testing.assert_close(term.cost[0, x, y], want, atol=1e-12, rtol=0)


def test_the_held_block_the_target_and_the_block_under_the_pick_are_not_counted(solver):
    # 1 stands on 0; 0 and 2 are wide slabs, so the open fingers come within the margin of 0
    # when picking 1 and of 2 when releasing onto it; the held block is between the fingers
    c = torch.tensor(
        [[(0.5, 0.0, S / 2), (0.5, 0.0, 1.5 * S), (0.5, 0.2, S / 2)]], dtype=torch.float64
    )
    half = torch.tensor([[(0.06, 0.06, S / 2), (S / 2,) * 3, (0.06, 0.06, S / 2)]])
    blocks = Blocks(c, half.double(), torch.tensor([[-1, 0, -1]]))
    on = c + torch.tensor([0.0, 0.0, S], dtype=torch.float64)  # (1, 3, 3)
    places = torch.cat([on, torch.tensor([[(0.4, -0.2, S / 2)]], dtype=torch.float64)], dim=1)
    q, _ = site_solutions(solver, PANDA.q_home, c, places)
    term = block_term(solver, q.reshape(1, 7, 7), blocks)
    everything = box_contacts(solver, q, c[0], blocks.half[0]).cost  # (7, 3): site by block
    assert everything[1, 0] > 0 and everything[1, 1] > 0  # the grasp of 1: under it and itself
    assert everything[3 + 2, 2] > 0  # the release onto 2 sees 2
    assert term.cost[0, 1, 3] == 0  # 1 to the free table place: nothing counted
    assert term.cost[0, 1, 2] == 0  # 1 onto 2: neither 0 (under 1), 1 (held) nor 2 (the target)
    assert (term.depth[0, 1:] == 0).all()
    # counted, the same contacts do cost: 1 as if it stood on the table, beside 0
    beside = block_term(solver, q.reshape(1, 7, 7), blocks._replace(under=torch.full((1, 3), -1)))
    assert beside.cost[0, 1, 3] > 0
    assert (term.depth[0, 0] > 0.02).all()  # 0 is not clear: its grasp is inside 1


def test_a_block_weight_of_zero_or_no_blocks_leave_the_costs_bit_identical(solver):
    picks, places, blocks = _scene(near=6)
    old = move_costs_batch(solver, PANDA.q_home, picks, places)
    for config, given in ((MoveCostConfig(), blocks), (ON, None)):
        assert torch.equal(
            move_costs_batch(solver, PANDA.q_home, picks, places, config, Bodies(blocks=given)), old
        )
    on = move_costs_batch(solver, PANDA.q_home, picks, places, ON, Bodies(blocks=blocks))
    assert on[0, 1, 0] > old[0, 1, 0] + 0.1


def test_the_depths_at_the_detached_solutions_rule_out_only_reached_moves(solver):
    picks, places, blocks = _scene(near=6)
    q, ok = site_solutions(solver, PANDA.q_home, picks, places)
    depth = block_depths(solver, (q, ok), blocks)
    assert depth[0, 1, 0] > 0.02 and depth.shape == (1, 8, 9)
    failed = ok.clone()
    failed[8] = False  # the release onto block 0 as if its IK had failed
    assert (block_depths(solver, (q, failed), blocks)[0, :, 0] == 0).all()


def test_gradient_of_the_block_term_matches_finite_differences(solver, monkeypatch):
    _freeze_ik(monkeypatch, solver)  # the detached q* held fixed (tests/motion/test_cost.py)
    picks, places, blocks = _scene(near=5)  # about 1 cm deep: on the linear side, no ties
    places = places.clone().requires_grad_()

    def cost(pl):
        on = move_costs_batch(solver, PANDA.q_home, picks, pl, ON, Bodies(blocks=blocks))
        return on - move_costs_batch(solver, PANDA.q_home, picks, pl)  # the block term alone

    assert cost(places)[0, 1, 0] > 0.02
    assert torch.autograd.gradcheck(cost, (places,), eps=1e-6, atol=1e-4)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"centres": torch.zeros(1, 7, 3)}, "blocks have centres"),
        ({"half": torch.zeros(1, 8, 2)}, "blocks have centres"),
        ({"under": torch.full((1, 8), 8)}, "blocks.under"),
        ({"half": torch.zeros(1, 8, 3)}, "> 0"),
    ],
)
def test_misuse_names_the_bad_input(solver, change, message):
    picks, places, blocks = _scene(near=6)
    with pytest.raises(MotionError, match=message):
        move_costs_batch(
            solver, PANDA.q_home, picks, places, ON, Bodies(blocks=blocks._replace(**change))
        )


def test_the_block_weight_scales_the_term(solver):
    picks, places, blocks = _scene(near=6)
    old = move_costs_batch(solver, PANDA.q_home, picks, places)
    one = move_costs_batch(solver, PANDA.q_home, picks, places, ON, Bodies(blocks=blocks)) - old
    five = replace(ON, block_weight=5.0)
    torch.testing.assert_close(
        move_costs_batch(solver, PANDA.q_home, picks, places, five, Bodies(blocks=blocks)) - old,
        5 * one,
    )
