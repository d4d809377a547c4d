"""Gradient-optimised placements in a region (`tamp.geo.ours.pack`): a region that holds five
squares only when they are placed tightly is packed from every seed, the packing loss's
gradient matches finite differences, and the sampled baseline gives the same kind of answer."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import torch

from tamp.geo.ours.pack import (
    Occupants,
    PackConfig,
    PackError,
    overlap_loss,
    pack,
    pack_sampled,
    pack_tries,
)

TIGHT = ((0.0, 0.0), (0.17, 0.105))  # five 5 cm squares fill 70 % of it: 3 + 2 in two rows
SQUARES = [(0.025, 0.025)] * 5


def _free_and_inside(region, half, xy, gap=0.0) -> bool:
    (x0, y0), (x1, y1) = region
    h = np.asarray(half)
    inside = (xy - h >= (x0 - 1e-9, y0 - 1e-9)).all() and (xy + h <= (x1 + 1e-9, y1 + 1e-9)).all()
    for i in range(len(xy)):
        for j in range(i + 1, len(xy)):
            depth = h[i] + h[j] + gap - np.abs(xy[i] - xy[j])
            if depth.min() > 1e-4:
                return False
    return bool(inside)


@pytest.mark.parametrize("seed", range(5))
def test_pack_places_five_squares_in_a_region_that_holds_them_only_tightly(seed):
    result = pack(TIGHT, SQUARES, seed=seed)
    assert result.ok and result.positions.shape == (5, 2)
    assert _free_and_inside(TIGHT, SQUARES, result.positions)  # checked independently


def test_tries_packed_together_give_each_the_packing_it_gets_alone():
    config = PackConfig(fingers=0.07, side=0.033)
    tries = [(replace(config, margin=margin), seed) for margin in (0.01, 0.0) for seed in (0, 3)]
    fixed = Occupants([(0.05, 0.05)], [(0.02, 0.02)])
    together = pack_tries(TIGHT, SQUARES[:3], fixed, tries, walled=False)
    for (at, seed), got in zip(tries, together, strict=True):
        alone = pack(TIGHT, SQUARES[:3], fixed, at, seed, walled=False)
        assert np.array_equal(got.positions, alone.positions)
        assert (got.ok, got.overlap, got.order) == (alone.ok, alone.overlap, alone.order)
        assert np.array_equal(got.yaws, alone.yaws) and np.array_equal(got.axes, alone.axes)
    with pytest.raises(PackError, match="margin and restarts only"):
        pack_tries(TIGHT, SQUARES, tries=[(config, 0), (replace(config, steps=10), 0)])


def test_pack_says_when_the_region_cannot_hold_them():
    result = pack(TIGHT, [(0.025, 0.025)] * 6, seed=0)  # a sixth square needs 3 x 2 = 0.15 x 0.1
    assert result.ok  # three by two still fits
    crowded = pack(TIGHT, [(0.025, 0.025)] * 7, seed=0)
    assert not crowded.ok and crowded.overlap > 0


def test_pack_keeps_clear_of_fixed_occupants_and_leaves_finger_room():
    fixed = [(0.025, 0.0525)]  # a square in the left end of the region
    result = pack(TIGHT, SQUARES[:3], Occupants(fixed, [(0.025, 0.025)]), seed=1)
    assert result.ok
    assert _free_and_inside(TIGHT, [(0.025, 0.025)] * 4, np.vstack([result.positions, fixed]))
    roomy = pack(((0.0, 0.0), (0.3, 0.3)), SQUARES[:2], config=PackConfig(fingers=0.07), seed=0)
    assert roomy.ok
    along = roomy.axes  # each object's closing axis: 7 cm of room along it from the edges
    for (x, y), axis in zip(roomy.positions, along, strict=True):
        at = (x, y)[axis]
        assert 0.07 - 1e-6 <= at <= 0.3 - 0.07 + 1e-6


def test_the_packing_loss_gradient_matches_finite_differences():
    gen = torch.Generator().manual_seed(0)
    xy = (0.05 * torch.rand(2, 3, 2, generator=gen, dtype=torch.float64)).requires_grad_(True)
    body = torch.full((2, 3, 2), 0.02, dtype=torch.float64)
    grown = body + torch.tensor([0.01, 0.0], dtype=torch.float64)
    fixed_xy = torch.tensor([[0.03, 0.03]], dtype=torch.float64)
    fixed_half = torch.tensor([[0.01, 0.02]], dtype=torch.float64)

    def loss(p):
        smooth = PackConfig(eps=1e-3, gap=0.002, ordered=False)
        return overlap_loss(p, grown, body, fixed_xy, fixed_half, 300.0, smooth)

    assert loss(xy).gt(0).all()  # overlapping, so the check sees a gradient
    assert torch.autograd.gradcheck(loss, (xy,), eps=1e-7, atol=1e-6)


def test_pack_sampled_is_the_same_kind_of_answer_and_refuses_what_cannot_fit():
    loose = ((0.0, 0.0), (0.4, 0.4))
    result = pack_sampled(loose, SQUARES, budget=2000, seed=0)
    assert result.ok and result.tries <= 2000
    assert _free_and_inside(loose, SQUARES, result.positions, 0.002)
    assert not pack_sampled(TIGHT, [(0.025, 0.025)] * 7, budget=300, seed=0).ok
    with pytest.raises(PackError, match=r"footprint 1 \(0.12 x 0.12 m\) does not fit") as caught:
        pack(TIGHT, [(0.02, 0.02), (0.06, 0.06)])
    assert caught.value.index == 1  # so the bridge can name the object
    assert math.isinf(pack_sampled(TIGHT, [(0.025, 0.025)] * 7, budget=300).overlap)


def test_a_free_row_with_a_placing_order_wins_over_a_lesser_overlap_without_one():
    """Packed variant 3's tray, flush: the least-overlap free row often has no placing order;
    taking the first free row that has one packs from 6 of 8 seeds (3 of 8 when only the
    least-overlap row was tried), and every packing returned as ok has a valid order."""
    from dataclasses import replace

    from tamp.geo.ours.bridge import PACK, own_footprint
    from tamp.world.canonical import generate

    made = generate("packed", 3)
    tray = made.scene.regions[0]
    feet = [own_footprint(o) for o in made.scene.objects]
    results = [
        pack(
            tray.inner(),
            feet,
            config=replace(PACK, margin=0.0),
            seed=s,
            walled=tray.wall_height > 0,
        )
        for s in range(8)
    ]
    assert sum(r.ok for r in results) >= 6
    for r in results:
        if r.ok:
            assert sorted(r.order) == list(range(len(feet)))


def test_the_fingers_close_only_across_a_side_a_grasp_closes_across():
    """The hand's room is grown along each object's closing axis: that side must be one
    `motion.grasps` makes a grasp across (narrower than the stroke less a finger's spare on
    each side). Packed variant 3's boxes are 5.8 cm by 6.8-7.7 cm: closing across a 7.3 cm
    side (the stroke alone allowed it) gave cells no grasp could fill in the packer's order."""
    from motion.grasps import FINGER_SPARE, STROKE
    from tamp.geo.ours.bridge import PACK, own_footprint
    from tamp.world.canonical import generate

    made = generate("packed", 3)
    tray = made.scene.regions[0]
    feet = np.array([own_footprint(o) for o in made.scene.objects])
    results = [pack(tray.inner(), feet, config=PACK, seed=s) for s in range(4)]
    results.append(pack_sampled(tray.inner(), feet, config=PACK, budget=600, seed=0))
    for r in results:
        for half, yaw, axis in zip(feet, r.yaws, r.axes, strict=False):
            body = half[::-1] if math.isclose(yaw, math.pi / 2) else half
            assert 2 * body[axis] + 2 * FINGER_SPARE < STROKE
