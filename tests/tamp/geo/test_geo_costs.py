"""The arm's prices of a bridged scene's moves (`tamp.geo.ours.costs.GeoCosts`): the direct move of
a hemmed-in target is IMPOSSIBLE (and the full check agrees) until a neighbour has moved, and
the failure memory rules a move out only under the grasp and place that failed."""

from __future__ import annotations

import numpy as np
import pytest

from motion.grasps import grasps, world_tcp
from tamp.geo.check import check_move
from tamp.geo.ours.bridge import bridge
from tamp.geo.ours.costs import GeoCosts, hand_in_world, hand_obbs, hand_shape
from tamp.world.goal import parse_goal
from task.costs import IMPOSSIBLE
from task.domains import blocksworld as bw
from task.problem import Move
from tests.tamp.geo.geo_scenes import blocked, tools


@pytest.fixture(scope="module")
def priced():
    s = blocked()
    b = bridge(s, parse_goal("(in t goal)", s))
    kit = tools()
    return b, GeoCosts(b, kit.solver, kit.q), kit


def _price(costs: GeoCosts, state, move: Move) -> float:
    p = costs.bridged.problem
    return float(costs.price(state)[p.entities.index(move.entity), p.index(move.target)])


def test_the_direct_move_of_a_hemmed_in_target_is_impossible_until_a_neighbour_moves(priced):
    b, costs, kit = priced
    p = b.problem
    direct = Move("t", "goal.c0")  # the two-line plan: (in t goal) in one move
    assert _price(costs, p.init, direct) >= IMPOSSIBLE
    assert not costs.grasps_left(p.init, direct)
    verdict = check_move(b.scene, b.geo_move(b.scene, direct), kit)
    assert not verdict.ok  # the full check agrees: no grasp reaches t
    spot = next(x.name for x in b.sites if x.name.startswith("table."))
    away = Move("n", spot)
    assert _price(costs, p.init, away) < IMPOSSIBLE  # n can go
    after = bw.apply_move(p, p.init, away)
    assert _price(costs, after, direct) < IMPOSSIBLE  # then t can
    assert costs.stats["states"] == 2 and costs.stats["price_s"] > 0


def test_a_failure_rules_a_move_out_only_under_its_grasp_and_place(priced):
    b, _, kit = priced
    costs = GeoCosts(b, kit.solver, kit.q)
    p = b.problem
    after = bw.apply_move(p, p.init, Move("n", next(x.name for x in b.sites if "table." in x.name)))
    direct, other = Move("t", "goal.c0"), Move("t", "spot_n")
    names = costs.grasps_left(after, direct)
    assert names and _price(costs, after, direct) < IMPOSSIBLE
    for name in names[:-1]:
        costs.avoid(after, direct, name, "goal.c0")
    assert costs.grasps_left(after, direct) == names[-1:]
    assert _price(costs, after, direct) < IMPOSSIBLE  # one grasp is left
    costs.avoid(after, direct, names[-1], "goal.c0")
    assert _price(costs, after, direct) >= IMPOSSIBLE
    assert _price(costs, after, other) < IMPOSSIBLE  # t may still go to another place
    costs.avoid(after, other, None, "spot_n")  # every grasp at that place failed
    assert _price(costs, after, other) >= IMPOSSIBLE


def test_a_grasp_that_failed_on_the_pick_side_is_out_for_every_place_in_that_state(priced):
    """A grasp that failed reaching or closing on the object (side "pick") fails whatever the
    place: ruled out for the object's moves to every place in that state (nonmonotonic variant
    2 spent its replans on one place after another); a place-side failure is not."""
    b, _, kit = priced
    costs = GeoCosts(b, kit.solver, kit.q)
    p = b.problem
    after = bw.apply_move(p, p.init, Move("n", next(x.name for x in b.sites if "table." in x.name)))
    direct, other = Move("t", "goal.c0"), Move("t", "spot_n")
    names = set(costs.grasps_left(after, direct)) | set(costs.grasps_left(after, other))
    assert _price(costs, after, other) < IMPOSSIBLE
    for name in names:
        costs.avoid(after, direct, name, "goal.c0", side="pick")
    assert costs.grasps_left(after, other) == ()
    assert _price(costs, after, other) >= IMPOSSIBLE and _price(costs, after, direct) >= IMPOSSIBLE
    assert costs.price_of(after, other) >= IMPOSSIBLE
    fresh = GeoCosts(b, kit.solver, kit.q)
    for name in names:
        fresh.avoid(after, direct, name, "goal.c0", side="place")
    assert _price(fresh, after, other) < IMPOSSIBLE  # a place-side failure stays at its place


@pytest.mark.parametrize("fixed", [False, True])
def test_a_failure_no_movable_object_caused_holds_wherever_the_object_still_stands(priced, fixed):
    """t fails under one grasp after n moved away; with ``fixed`` (an IK failure, a post hit)
    the grasp stays ruled out once w has moved too (t stands where it stood), else only in
    the state it failed in; after t itself moved, it is back either way."""
    b, _, kit = priced
    costs = GeoCosts(b, kit.solver, kit.q)
    p = b.problem
    spots = [x.name for x in b.sites if x.name.startswith("table.")]
    after = bw.apply_move(p, p.init, Move("n", spots[0]))
    later = bw.apply_move(p, after, Move("w", spots[1]))
    direct = Move("t", "goal.c0")
    grasp = costs.grasps_left(after, direct)[0]
    assert grasp in costs.grasps_left(later, direct)
    costs.avoid(after, direct, grasp, "goal.c0", fixed=fixed)
    assert grasp not in costs.grasps_left(after, direct)
    assert (grasp not in costs.grasps_left(later, direct)) is fixed
    moved_t = bw.apply_move(p, later, Move("t", spots[2]))  # t stands somewhere new
    assert grasp in costs.grasps_left(moved_t, direct)


@pytest.mark.parametrize("yaw", [0.0, 0.4])
def test_the_batched_hand_boxes_are_those_of_each_grasp_alone(yaw):
    """Every grasp's palm and finger boxes, batched in the object's frame and turned with it,
    stand where `motion.grasps.world_tcp` puts that grasp's hand alone."""
    made = grasps("cuboid", (0.02, 0.03, 0.025))
    xyz = np.array([0.5, 0.1, 0.025])
    centres, axes, halves = hand_in_world(hand_obbs(made, 0.004), xyz, yaw)  # 3 G boxes
    for i, g in enumerate(made):
        tcp = world_tcp(g, xyz, yaw)  # (4, 4)
        for k, (centre, half) in enumerate(hand_shape(g)):
            assert np.allclose(centres[3 * i + k], tcp[:3, :3] @ np.asarray(centre) + tcp[:3, 3])
            assert np.allclose(axes[3 * i + k], tcp[:3, :3])
            assert np.allclose(halves[3 * i + k], np.asarray(half) + 0.004)


def test_oriented_boxes_overlap_only_where_they_truly_interpenetrate():
    from tamp.geo.ours.costs import obb_overlap, solid_obbs
    from tamp.world.geometry import Solid

    def box(x, y, yaw, half=(0.02, 0.02, 0.02)):
        return solid_obbs([Solid("b", False, (x, y, 0.02), half, yaw)])

    def both(*boxes):
        return tuple(np.concatenate(parts) for parts in zip(*boxes, strict=True))

    quarter = np.pi / 4
    # a diamond and a square off its side: their bounding boxes overlap, they are 8 mm apart
    assert not obb_overlap(box(0.0, 0.0, quarter), box(0.04, 0.04, 0.0))[0, 0]
    # a diamond's corner 3.3 mm inside a square
    assert obb_overlap(box(0.0, 0.0, quarter), box(0.045, 0.0, 0.0))[0, 0]
    # touching faces are contact, not overlap; stacked boxes overlap in no height
    assert not obb_overlap(box(0.0, 0.0, 0.0), box(0.0399, 0.0, 0.0))[0, 0]
    high = solid_obbs([Solid("h", False, (0.0, 0.0, 0.07), (0.02, 0.02, 0.02), 0.3)])
    assert not obb_overlap(box(0.0, 0.0, 0.0), high)[0, 0]
    # batched: every pair at once, as each pair alone
    many = both(box(0.0, 0.0, 0.0), box(0.1, 0.0, 0.2), box(0.03, 0.01, 1.0))
    table = obb_overlap(many, many)
    for i in range(3):
        for j in range(3):
            one = obb_overlap(*(tuple(p[k : k + 1] for p in many) for k in (i, j)))
            assert table[i, j] == one[0, 0]
    assert table[0, 2] and not table[0, 1]


def test_the_grasps_left_of_a_move_come_in_the_candidates_order(priced):
    """Best first, as `candidate_grasps` orders them: not a set's order, which changes with the
    process's string hashing (and with it the grasp binding tries first)."""
    b, costs, _ = priced
    p = b.problem
    _, allowed = costs._priced(p.init)
    seen = 0
    for move, names in allowed.items():
        order = [g.name for g in costs.grasps[move.entity]]
        assert list(names) == [n for n in order if n in names]
        seen += len(names) > 1
    assert seen  # some move has several grasps to order


def test_a_move_into_a_cell_costs_more_per_empty_cell_of_its_region_it_closes():
    """Packed variant 2's tray: a box put in a cell whose body another empty cell's hand room
    reaches (the packer's placing-order test) costs ``order`` more per such cell, in the state's
    whole pricing and a single move's alike; once that cell is filled, nothing is added."""
    from dataclasses import replace

    from tamp.geo.ours.costs import GeoCostConfig
    from tamp.world.canonical import generate

    made = generate("packed", 2)
    b = bridge(made.scene, made.goal)
    ((_, packed),) = b.packs
    p = b.problem
    plain = GeoCosts(b, config=replace(GeoCostConfig(), order=0.0))
    ordered = GeoCosts(b)
    closes = ordered._closes(p.init)
    assert set(closes) == {c for _, c in b.cells} and any(closes.values())
    for x, cell in b.cells:
        extra = _price(ordered, p.init, Move(x, cell)) - _price(plain, p.init, Move(x, cell))
        assert extra == pytest.approx(closes[cell])
        single = ordered.price_of(p.init, Move(x, cell)) - plain.price_of(p.init, Move(x, cell))
        assert single == pytest.approx(closes[cell])
    # filling the cells in the packer's placing order (`placing_order`) closes none
    state = p.init
    for k in packed.order:
        x, cell = b.cells[k]
        assert ordered._closes(state)[cell] == 0
        state = bw.apply_move(p, state, Move(x, cell))
