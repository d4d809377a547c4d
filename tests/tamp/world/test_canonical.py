"""The canonical problems (`tamp.world.canonical`): every variant of every problem is a valid
scene whose state the geometry explains and whose goal is unmet; each is hard for the
geometric reason it claims (measured with the reference hand model, footprints and reach
only, no simulator); the shipped seed-0 files equal the generator's; Hanoi writes PDDL the
symbolic side solves in 2^n - 1 moves."""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import replace

import pytest

from motion.grasps import FINGER_SPARE, STROKE
from tamp.scene import Pose
from tamp.world.canonical import (
    APPROACH,
    FINGER_IN,
    FINGER_OUT,
    PROBLEMS,
    SCENES_DIR,
    CanonicalProblem,
    centre_first,
    free_top_axes,
    generate,
    hanoi_pddl,
    in_view,
    shipped,
    top_reach,
    write_all,
)
from tamp.world.geometry import footprint_gap, of_box, of_movable
from tamp.world.load import MAX_REACH, MIN_REACH, load_scene, scene_dict
from tamp.world.relations import read_facts
from tamp.world.schema import Movable, Region, Scene
from task.errors import ProblemError
from task.symbolic import pddl_io
from task.symbolic.pickplace import hanoi
from task.symbolic.search import optimal_length_strips

SEEDS = range(10)
FINGER = FINGER_OUT - FINGER_IN  # m, a finger's thickness along the closing axis


@functools.cache
def _variant(name: str, seed: int, **size) -> CanonicalProblem:
    return generate(name, seed, **size)


def _centre(r: Region) -> tuple[float, float]:
    return (r.lo[0] + r.hi[0]) / 2, (r.lo[1] + r.hi[1]) / 2


def _moved(scene: Scene, poses: dict[str, Pose]) -> Scene:
    objects = tuple(replace(o, pose=poses.get(o.name, o.pose)) for o in scene.objects)
    return replace(scene, objects=objects)


@pytest.mark.parametrize("name", PROBLEMS)
def test_every_variant_is_a_valid_scene_with_an_unmet_goal(name):
    for seed in SEEDS:
        p = _variant(name, seed)
        assert (p.name, p.seed) == (name, seed) and p.note and "\n" not in p.note
        assert load_scene(scene_dict(p.scene)) == p.scene  # the loader's checks, round trip
        facts = read_facts(p.scene)
        assert not facts.unexplained, facts.issues
        assert len(facts.supports) == len(p.scene.objects)
        assert p.goal.unmet(facts)
        far = 0.705 if name == "tall" else 0.7  # tall: at the edge, still inside MAX_REACH
        for o in p.scene.objects:
            assert 0.35 <= o.reach <= far < MAX_REACH and MIN_REACH < 0.35, (seed, o.name)
        named = {a[2] for a in p.goal.atoms if a[0] == "in"}
        for r in p.scene.regions:
            if r.name in named:
                assert 0.35 <= math.hypot(*_centre(r)) <= 0.7, (seed, r.name)


@pytest.mark.parametrize("name", PROBLEMS)
def test_seeds_give_different_variants(name):
    scenes = {repr(scene_dict(replace(_variant(name, s).scene, name="x"))) for s in SEEDS}
    assert len(scenes) == len(SEEDS)


@pytest.mark.parametrize("name", PROBLEMS)
def test_the_camera_sees_every_object(name):
    for seed in SEEDS:
        scene = _variant(name, seed).scene
        pts = [
            (x, y, z)
            for o in scene.objects
            for x, y in of_movable(o).corners()
            for z in (o.bottom, o.top)
        ]
        assert in_view(pts, scene.camera.eye, scene.camera.target, scene.camera), seed


def test_the_shipped_files_are_the_generators_seed_0(tmp_path):
    written = write_all(tmp_path)
    assert sorted(p.name for p in written) == sorted(p.name for p in SCENES_DIR.iterdir())
    for path in written:
        assert path.read_text() == (SCENES_DIR / path.name).read_text(), path.name
    for name in PROBLEMS:
        scene, goal = shipped(name)
        p = _variant(name, 0)
        assert (scene, goal) == (p.scene, p.goal)


def test_bad_requests_are_one_line_listing_what_is_valid():
    with pytest.raises(ProblemError, match=r"'stacked' .*valid: blocked, packed"):
        generate("stacked", 0)
    with pytest.raises(ProblemError, match=r"'width' .*valid: n"):
        generate("blocked", 0, width=3)
    with pytest.raises(ProblemError, match=r"n must be a whole number in 4\.\.6, got 9"):
        generate("packed", 0, n=9)
    with pytest.raises(ProblemError, match=r"mode 'up' .*valid: build, down"):
        generate("tall", 0, mode="up")
    with pytest.raises(ProblemError, match="unknown canonical problem"):
        shipped("stacked")


@pytest.mark.parametrize(
    ("name", "size", "count"),
    [
        ("blocked", {"n": 3}, 4),
        ("blocked", {"n": 4}, 5),
        ("packed", {"n": 6}, 6),
        ("nonmonotonic", {"n": 3}, 4),
        ("sorting", {"n": 8, "colours": 3}, 8),
        ("tall", {"n": 10, "mode": "build"}, 10),
        ("hanoi", {"n": 3}, 3),
    ],
)
def test_sizes_set_the_counts(name, size, count):
    p = _variant(name, 1, **size)
    assert len(p.scene.objects) == count


# ---- the reference hand model --------------------------------------------------------------


def _cube(name, x, y, edge=0.05, yaw=0.0) -> Movable:
    return Movable(name, "cube", (edge,), (1.0, 0.0, 0.0), Pose((x, y, edge / 2), yaw))


def test_the_hand_model_needs_room_for_a_finger_on_both_sides():
    from tamp.world.canonical import TABLE_TOP

    alone = Scene("s", TABLE_TOP, objects=(_cube("a", 0.5, 0.0),))
    assert free_top_axes(alone, "a") == (0, 1)
    for gap, free in ((0.006, (1,)), (0.03, (1,)), (FINGER_OUT - 0.025 + 0.002, (0, 1))):
        near = replace(alone, objects=(*alone.objects, _cube("b", 0.55 + gap, 0.0)))
        assert free_top_axes(near, "a") == free, gap
    assert free_top_axes(near, "a", without=("b",)) == (0, 1)
    short = Movable("c", "cuboid", (0.04, 0.04, 0.01), (0, 0, 1), Pose((0.55 + 0.04, 0.0, 0.005)))
    low = replace(alone, objects=(*alone.objects, short))  # under the fingertips: no obstacle
    assert free_top_axes(low, "a") == (0, 1)
    wide = Movable(
        "w", "cuboid", (STROKE - 2 * FINGER_SPARE, 0.05, 0.05), (0, 0, 1), Pose((0.5, 0, 0.025))
    )
    assert free_top_axes(replace(alone, objects=(wide,)), "w") == (1,)


# ---- why each problem is hard --------------------------------------------------------------


def test_blocked_every_grasp_axis_of_the_target_has_a_neighbour_within_a_finger():
    for seed in SEEDS:
        p = _variant("blocked", seed)
        t = p.scene.object("t")
        neighbours = [o for o in p.scene.objects if o.name != "t"]
        sides = {}
        for o in neighbours:
            gap = footprint_gap(of_movable(t), of_movable(o))
            assert 0.002 < gap < FINGER / 2 and o.top >= t.top - 1e-9, (seed, o.name)
            dx, dy = o.pose.xyz[0] - t.pose.xyz[0], o.pose.xyz[1] - t.pose.xyz[1]
            c, s = math.cos(t.pose.yaw), math.sin(t.pose.yaw)
            u, v = c * dx + s * dy, -s * dx + c * dy
            sides[(0, u > 0) if abs(u) > abs(v) else (1, v > 0)] = o.name
        assert all((axis, True) in sides or (axis, False) in sides for axis in (0, 1)), seed
        assert free_top_axes(p.scene, "t", pad=-0.003) == ()
        assert all(free_top_axes(p.scene, o.name) for o in neighbours)
        if len(neighbours) == 3:  # the neighbour facing the open side frees it, no other
            freeing = [o.name for o in neighbours if free_top_axes(p.scene, "t", without=(o.name,))]
            assert len(freeing) == 1 and freeing[0] in p.note, seed
        else:
            assert not any(free_top_axes(p.scene, "t", without=(o.name,)) for o in neighbours)
            assert free_top_axes(p.scene, "t", without=(sides[0, True], sides[0, False]))
        assert p.goal.atoms == (("in", "t", "goal_zone"),)


def test_packed_fills_the_tray_and_a_centre_first_packer_gets_stuck():
    for seed in SEEDS:
        p = _variant("packed", seed)
        tray = p.scene.region("tray")
        (x0, y0), (x1, y1) = tray.inner()
        fill = sum(4 * o.half[0] * o.half[1] for o in p.scene.objects) / ((x1 - x0) * (y1 - y0))
        assert 0.6 <= fill <= 0.75, seed
        names = [o.name for o in p.scene.objects]
        assert 4 <= len(names) <= 6
        assert all(free_top_axes(p.scene, n) for n in names), seed  # each can be picked up
        biggest = sorted(names, key=lambda n: -p.scene.object(n).half[1])
        for order in (names, biggest):
            assert len(centre_first(p.scene, "tray", order)) < len(names), seed
        # the witness: every object in the tray, the goal met, each graspable among the rest
        packed = _moved(p.scene, dict(p.witness))
        assert load_scene(scene_dict(packed)) == packed
        assert p.goal.holds(read_facts(packed)), seed
        assert all(free_top_axes(packed, n) for n in names), seed
        assert len(centre_first(packed, "tray", names)) < len(names)


def test_centre_first_packs_what_fits_loosely():
    from tamp.world.canonical import TABLE_TOP

    tray = Region("tray", (0.4, -0.1), (0.6, 0.1))
    cubes = tuple(_cube(f"c{i}", 0.3, 0.3 * i - 0.3, edge=0.04) for i in range(3))
    scene = Scene("s", TABLE_TOP, regions=(tray,), objects=cubes)
    assert centre_first(scene, "tray", ["c0", "c1", "c2"]) == ("c0", "c1", "c2")


def test_nonmonotonic_the_front_objects_close_the_alcove_to_the_target():
    for seed in SEEDS:
        p = _variant("nonmonotonic", seed)
        facts = read_facts(p.scene)
        fronts = [o for o in p.scene.objects if o.name.startswith("f")]
        assert 2 <= len(fronts) <= 3
        assert all(facts.holds(("in", o.name, "alcove")) for o in [*fronts, p.scene.object("t")])
        t, f1 = p.scene.object("t"), p.scene.object("f1")
        # f1 stands right before the target, across the target's front finger
        assert footprint_gap(of_movable(t), of_movable(f1)) < FINGER / 2
        assert f1.pose.xyz[0] < t.pose.xyz[0] and f1.top > t.top
        assert abs(f1.pose.xyz[1] - t.pose.xyz[1]) + 0.01 < f1.half[1]
        # the kerbs stand within a finger of the target's sides
        kerbs = [of_box(b) for b in p.scene.obstacles if b.name in ("kerb_left", "kerb_right")]
        assert all(footprint_gap(of_movable(t), k) < FINGER / 2 for k in kerbs)
        assert free_top_axes(p.scene, "t", pad=-0.003) == ()
        assert free_top_axes(p.scene, "t", pad=-0.003, without=("f1",)) == ()
        assert free_top_axes(p.scene, "t", pad=0.003, without=("f1", "f2")) == (0,)
        assert all(free_top_axes(p.scene, o.name) == (1,) for o in fronts)
        unmet = p.goal.unmet(facts)
        assert unmet == (("in", "t", "goal_zone"),)  # the fronts' atoms hold, and must again
        assert len(p.goal.atoms) == 1 + len(fronts)


def test_sorting_posts_block_one_grasp_axis_of_every_object():
    for seed in SEEDS:
        p = _variant("sorting", seed)
        objects = p.scene.objects
        assert 4 <= len(objects) <= 8
        bare = replace(p.scene, obstacles=())
        for o in objects:
            assert len(free_top_axes(p.scene, o.name)) == 1, (seed, o.name)
            assert free_top_axes(bare, o.name) == (0, 1), (seed, o.name)
        zone = {a[1]: p.scene.region(a[2]) for a in p.goal.atoms}
        assert {a[0] for a in p.goal.atoms} == {"in"} and set(zone) == {o.name for o in objects}
        for o in objects:
            assert zone[o.name].rgb == o.rgb and zone[o.name].name.endswith("_zone")
        assert 2 <= len({o.rgb for o in objects}) <= 3


def _towers(scene: Scene) -> list[list[Movable]]:
    """Stacks of objects standing on the table, bottom first."""
    facts = read_facts(scene)
    on = {a[2]: a[1] for a in facts.atoms if a[0] == "on"}  # below -> above
    out = []
    for o in scene.objects:
        if facts.holds(("ontable", o.name)) or any(
            facts.holds(("in", o.name, r.name)) for r in scene.regions
        ):
            tower = [o]
            while tower[-1].name in on:
                tower.append(scene.object(on[tower[-1].name]))
            out.append(tower)
    return out


def test_tall_towers_stand_at_the_edge_of_reach_and_stay_reachable():
    modes = set()
    for seed in SEEDS:
        p = _variant("tall", seed)
        n = len(p.scene.objects)
        assert 8 <= n <= 10
        pad = p.scene.regions[0]
        modes.add(pad.name)
        towers = _towers(p.scene)
        if pad.name == "near_pad":  # take the far tower down
            (tower,) = towers
            base = tower[0]
            assert len(tower) == n and base.reach >= 0.645, seed
            top = tower[-1].top
            assert top + APPROACH <= top_reach(base.reach) - 0.015, seed
        else:  # build one on the far pad
            assert max(len(t) for t in towers) <= 4
            assert math.hypot(*_centre(pad)) >= 0.65, seed
            edge = p.scene.objects[0].size[0]
            top = n * edge
            assert top + APPROACH <= top_reach(math.hypot(*_centre(pad))) - 0.015, seed
        assert top > 0.3, seed
        chain = [a for a in p.goal.atoms if a[0] == "on"]
        assert len(chain) == n - 1
    assert modes == {"near_pad", "far_pad"}


def test_hanoi_discs_shrink_upwards_on_the_first_peg():
    for seed in SEEDS:
        p = _variant("hanoi", seed)
        discs = p.scene.objects
        assert 3 <= len(discs) <= 5
        (tower,) = _towers(p.scene)
        widths = [2 * max(o.half[:2]) for o in tower]
        assert all(a > b for a, b in itertools.pairwise(widths)), seed
        assert 0.039 <= widths[-1] <= 0.043 and 0.064 <= widths[0] <= 0.068
        # a peg holds one tower: the two smallest discs do not fit in it side by side
        small = sorted(2 * o.half[0] for o in discs)[:2]
        assert all(sum(small) > r.hi[0] - r.lo[0] for r in p.scene.regions), seed
        assert [o.name for o in tower] == [f"d{i}" for i in range(len(discs), 0, -1)]
        assert read_facts(p.scene).holds(("in", f"d{len(discs)}", "peg1"))
        pegs = [p.scene.region(f"peg{k}") for k in (1, 2, 3)]
        assert all(math.dist(_centre(a), _centre(b)) >= 0.1 for a, b in itertools.pairwise(pegs))
        assert all(free_top_axes(p.scene, o.name) for o in tower[-1:])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_hanoi_pddl_is_solved_in_2_to_the_n_minus_1(seed):
    p = _variant("hanoi", seed)
    domain = pddl_io.parse_domain(hanoi.domain_text(), "hanoi")
    problem = pddl_io.parse_problem(hanoi_pddl(p), "hanoi", domain)
    n = len(p.scene.objects)
    assert optimal_length_strips(domain, problem) == hanoi.optimal_length(n)


def test_hanoi_pddl_refuses_a_disc_off_the_pegs():
    p = _variant("hanoi", 0)
    off = _moved(p.scene, {"d1": Pose((0.35, -0.45, p.scene.object("d1").half[2]))})
    with pytest.raises(ProblemError, match=r"\(ontable d1\)"):
        hanoi_pddl(replace(p, scene=off))
