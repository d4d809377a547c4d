"""Discretised placements (`tamp.geo.places`): inside their region, free of the other objects,
supported on objects, table spots off the regions, names stable across world states."""

from __future__ import annotations

import itertools
import math

import pytest

from tamp.geo.places import REGION_GAP, TABLE_CLEARANCE, candidate_places
from tamp.geo.types import TABLE, moved
from tamp.scene import Pose
from tamp.world.geometry import footprint_gap, inside, of_movable
from tamp.world.relations import read_facts
from tamp.world.schema import SceneFileError
from tests.tamp.geo.geo_scenes import alcove, blocked, cube, scene

TRAY = {
    "name": "tray",
    "min": [0.45, 0.15],
    "max": [0.65, 0.35],
    "wall_height": 0.03,
    "wall_thickness": 0.01,
}


def test_region_places_lie_inside_the_walls_free_of_the_object_already_there():
    s = scene(cube("a", 0.5, 0.2), cube("b", 0.4, -0.1), regions=[TRAY])
    places = candidate_places(s, "b", "tray", n=20)
    assert len(places) >= 6
    for p in places:
        after = moved(s, "b", p.pose)
        assert inside(after.region("tray"), after.object("b"))
        assert footprint_gap(of_movable(after.object("b")), of_movable(s.object("a"))) > 0
        assert dict(read_facts(after).supports)["b"] == "tray"
    grid = [p for p in places if ".g" in p.name]
    for p, q in itertools.combinations(grid, 2):
        assert max(abs(p.xyz[0] - q.xyz[0]), abs(p.xyz[1] - q.xyz[1])) >= 0.05 + REGION_GAP - 1e-9
    assert len({p.name for p in places}) == len(places)


def test_region_places_pack_against_walls_and_objects_then_grid_then_samples():
    s = scene(cube("a", 0.5, 0.2), cube("b", 0.4, -0.1), regions=[TRAY])
    places = candidate_places(s, "b", "tray", n=60)
    packed = [p for p in places if ".p" in p.name]
    grid = [p for p in places if ".g" in p.name]
    drawn = [p for p in places if ".s" in p.name]
    assert places == (*packed, *grid, *drawn) and packed and grid and drawn
    # flush against the walls (2 mm in) and 4 mm beside a
    xs = {round(p.xyz[0], 4) for p in packed}
    assert {0.487, 0.613, 0.554} <= xs
    assert "tray.p554_187" in {p.name for p in packed}  # named by its position, in mm

    def far(p):
        return math.dist(p.xyz[:2], (0.55, 0.25))

    assert [far(p) for p in grid] == sorted(far(p) for p in grid)


@pytest.mark.parametrize("inner_first", [False, True])
def test_nested_regions_offer_the_inner_one_and_the_outer_ones_free_part(inner_first):
    """Places in the alcove rest in it (and in the desk around it); places in the desk keep
    out of the alcove, so each place's support is the region it was asked for."""
    s = alcove(cube("a", 0.5, -0.15), cube("b", 0.6, 0.25), inner_first=inner_first)
    into = candidate_places(s, "a", "alcove", n=20)
    assert into
    for p in into:
        facts = read_facts(moved(s, "a", p.pose))
        assert dict(facts.supports)["a"] == "alcove"
        assert facts.holds(("in", "a", "alcove")) and facts.holds(("in", "a", "desk"))
    s = moved(s, "a", into[0].pose)
    out = candidate_places(s, "a", "desk", n=40)
    assert len(out) >= 10
    for p in out:
        after = moved(s, "a", p.pose)
        assert not inside(after.region("alcove"), after.object("a"))
        assert dict(read_facts(after).supports)["a"] == "desk"


def test_a_region_that_holds_one_object_places_it_centred_on_the_tight_axis():
    """A Hanoi peg under its largest disc: 4.5 mm of play a side, less than any object is
    wide. Packed flush (2 mm in), a disc released 4 mm off read as standing outside the peg
    (variant 17 of ``hanoi``); centred, it keeps the play on both sides. Along the roomy axis
    the places still pack against the edges (a wide tray's: the test above)."""
    peg = {"name": "peg", "min": [0.44, 0.10], "max": [0.515, 0.30]}  # 75 mm x 200 mm
    d, small = cube("d", 0.3, -0.1, 0.033, size=0.066), cube("small", 0.3, 0.1, 0.02, size=0.04)
    s = scene(d, small, regions=[peg])
    packed = [p for p in candidate_places(s, "d", "peg", n=20) if ".p" in p.name]
    assert packed and {round(p.xyz[0], 4) for p in packed} == {0.4775}
    assert {round(p.xyz[1], 4) for p in packed} == {0.135, 0.265}  # flush, 2 mm in


def test_without_parking_the_table_is_no_place_and_regions_are_the_fixed_targets():
    from dataclasses import replace

    from tamp.geo.places import fixed_targets

    s = scene(cube("a", 0.5, 0.2), cube("b", 0.4, -0.1), regions=[TRAY])
    assert candidate_places(s, "b", TABLE, n=4) and fixed_targets(s) == ("tray", TABLE)
    kept = replace(s, parking=False)
    assert candidate_places(kept, "b", TABLE, n=4) == ()
    assert candidate_places(kept, "b", "tray", n=4) and fixed_targets(kept) == ("tray",)


def test_a_region_too_small_for_the_object_has_no_place():
    small = {"name": "small", "min": [0.5, 0.2], "max": [0.54, 0.24]}
    s = scene(cube("a", 0.4, -0.1), regions=[small])
    assert candidate_places(s, "a", "small") == ()


def test_on_an_object_centred_on_its_top_only_when_it_fits():
    s = scene(cube("big", 0.5, 0.1, 0.03, size=0.06), cube("small", 0.4, -0.1, 0.02, size=0.04))
    (on,) = candidate_places(s, "small", "big")
    assert on.name == "on.big" and on.target == "big"
    assert on.xyz == pytest.approx((0.5, 0.1, 0.06 + 0.02))
    assert candidate_places(s, "big", "small") == ()  # it would overhang the small top
    assert candidate_places(s, "big", "big") == ()


def test_a_covered_object_is_no_place():
    s = scene(cube("a", 0.5, 0.1), cube("b", 0.5, 0.1, 0.075), cube("c", 0.4, -0.1))
    assert candidate_places(s, "c", "a") == ()
    assert len(candidate_places(s, "c", "b")) == 1


def test_table_spots_slots_first_clear_of_objects_and_regions():
    slots = {"xs": [0.4, 0.56], "ys": [-0.2, 0.0, 0.2]}
    s = scene(cube("a", 0.4, 0.0), cube("b", 0.56, 0.2), slots=slots)
    places = candidate_places(s, "a", TABLE, n=12)
    names = [p.name for p in places]
    slot_names = [n for n in names if n.startswith("table.s")]
    assert names[: len(slot_names)] == slot_names  # the slot grid first
    assert "table.s5" not in names  # (0.56, 0.2) holds b
    goal = s.region("goal")
    for p in places:
        me = of_movable(moved(s, "a", p.pose).object("a"))
        assert footprint_gap(me, of_movable(s.object("b"))) >= TABLE_CLEARANCE - 1e-9
        assert not (
            goal.lo[0] - 0.025 < p.xyz[0] < goal.hi[0] + 0.025
            and goal.lo[1] - 0.025 < p.xyz[1] < goal.hi[1] + 0.025
        )
        assert 0.3 <= math.hypot(*p.xyz[:2]) <= 0.7


def test_names_are_stable_choices_across_world_states():
    s = blocked()
    before = {p.name: p for p in candidate_places(s, "n", "goal", n=10)}
    after = moved(s, "w", Pose((0.6, 0.3, 0.025), 0.0))
    for p in candidate_places(after, "n", "goal", n=10):
        assert before.get(p.name, p) == p


def test_an_unknown_target_lists_the_valid_ones():
    with pytest.raises(SceneFileError, match=r"unknown place target .tary.*tray"):
        candidate_places(scene(cube("a", 0.5, 0.0), regions=[TRAY]), "a", "tary")
