"""`motion.sphere_check`: the batched sphere-model checker against PyBullet's mesh model.

The main test samples configurations with boxes placed right beside the arm's links (some
touching, some a few cm off), with and without a held block, and asks both models: the spheres
may refuse a configuration the meshes accept (a false "collision"), never the other way round.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from motion.errors import MotionError
from motion.sphere_check import Screened, SphereCollision
from motion.sphere_check.bounds import dop_gap
from motion.sphere_check.collision import CHUNK
from motion.sphere_check.fk import PARTS
from motion.sphere_check.model import APART, APART_CLEARANCE
from robots.collision import Box
from robots.panda import PANDA, data_dir
from robots.panda_spheres import COVER, COVER_GAP, FINGERS, SPHERES

HOME = np.asarray(PANDA.q_home)
LO, HI = np.asarray(PANDA.q_min), np.asarray(PANDA.q_max)


@pytest.fixture(scope="module")
def spheres():
    return SphereCollision(margin=0.01)


def near_arm_scenes(model: SphereCollision, n_scenes: int, per_scene: int, seed: int):
    """Scenes of 1 or 2 boxes placed beside random links of a random configuration (each box's
    face between 1 cm inside and 10 cm off a sphere's surface), and ``per_scene``
    configurations near that one (0.05 rad noise): yields (boxes, held, q (per_scene, J))."""
    rng = np.random.default_rng(seed)
    for s in range(n_scenes):
        q0 = np.clip(HOME + rng.normal(0.0, 0.8, 7), LO, HI)
        rot, pos = model.model.links(q0[None], PANDA.finger_open)
        boxes = []
        for k in range(int(rng.integers(1, 3))):
            link = int(rng.integers(1, len(PARTS)))
            i = model.model.start[link] + int(rng.integers(model.model.count[link]))
            centre = rot[0, link] @ model.model.local[i] + pos[0, link]  # a sphere's world centre
            half = rng.uniform(0.01, 0.06, 3)
            yaw = float(rng.uniform(-math.pi, math.pi))
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            along = (
                np.array([math.cos(yaw), math.sin(yaw), 0.0]),
                np.array([-math.sin(yaw), math.cos(yaw), 0.0]),
            )  # the box's x and y axes
            support = abs(direction @ along[0]) * half[0] + abs(direction @ along[1]) * half[1]
            support += abs(direction[2]) * half[2]  # the box's extent towards the sphere
            off = model.model.radii[i] + rng.uniform(-0.01, 0.1) + support
            at = centre + off * direction
            at[2] = max(at[2], half[2] + 0.001)  # stands on or above the table
            boxes.append(Box(f"box{k}", tuple(at), tuple(half), yaw))
        held = 0.05 if s % 3 == 0 else None
        q = np.clip(q0 + rng.normal(0.0, 0.05, (per_scene, 7)), LO, HI)
        yield boxes, held, q


def compare(mesh, spheres, n_scenes: int, per_scene: int, seed: int):
    """(false free, false collision, mesh-free, total) counts over the sampled scenes."""
    false_free = false_collision = free = total = 0
    examples = []
    for boxes, held, q in near_arm_scenes(spheres, n_scenes, per_scene, seed):
        for model in (mesh, spheres):
            model.set_boxes(boxes)
            model.hold(held)
        fingers = held / 2 if held else PANDA.finger_open
        fast = spheres.valid_batch(q, fingers)
        exact = np.array([mesh.valid(x, fingers) for x in q])
        false_free += int((fast & ~exact).sum())
        false_collision += int((~fast & exact).sum())
        free, total = free + int(exact.sum()), total + len(q)
        examples += [(boxes, held, x) for x in q[fast & ~exact]]
    return false_free, false_collision, free, total, examples


@pytest.mark.sim
def test_no_false_free_against_the_mesh_model_near_obstacles(spheres):
    """600 configurations (60 scenes, a third holding a 5 cm block) with boxes beside the arm,
    at the scene margin of 1 cm (5,000 at 1 and 2 cm with another seed for BENCHMARKS.md:
    no false free either). The spheres are grown by COVER_GAP = 1.5 cm, so a box 1-2.5 cm from
    the meshes is a false "collision" by design: these make up about 9 % of all such samples
    (about 45 % of the mesh-free ones, which are only a fifth here because every box is placed
    at most 10 cm from a link); the bounds are loose (20 % of all, 60 % of the free ones)."""
    from robots.collision import PandaCollision

    with PandaCollision(margin=0.01) as mesh:
        ff, fc, free, total, examples = compare(mesh, spheres, 60, 10, seed=1)
    assert ff == 0, examples[:3]
    assert total / 10 < free < total * 0.9  # neither all collisions nor all free
    assert fc < 0.2 * total and fc < 0.6 * free, (fc, free, total)


def test_home_is_free_and_a_box_through_the_hand_is_not(spheres):
    spheres.set_boxes([])
    spheres.hold(None)
    assert spheres.valid(HOME) and spheres.contacts(HOME) == []
    _, pos = spheres.model.links(HOME[None], PANDA.finger_open)
    hand = pos[0, PARTS.index("panda_hand")]
    spheres.set_boxes([Box("block", tuple(hand), (0.02, 0.02, 0.02))])
    assert not spheres.valid(HOME)
    hits = spheres.contacts(HOME)
    assert hits and hits[0].other == "block" and hits[0].distance < 0
    assert {c.part for c in hits} >= {"panda_hand"}
    assert spheres.valid(HOME, ignore=[("robot", "block")])
    spheres.set_boxes([])


def test_valid_batch_agrees_with_valid_row_by_row(spheres):
    rng = np.random.default_rng(0)
    q = np.clip(HOME + rng.normal(0.0, 0.7, (40, 7)), LO, HI)
    spheres.set_boxes([Box("wall", (0.45, 0.0, 0.12), (0.12, 0.01, 0.12), 0.3)])
    spheres.hold(0.05)
    batch = spheres.valid_batch(q, 0.025)
    assert batch.shape == (40,) and batch.dtype == bool
    assert 0 < batch.sum() < 40
    assert list(batch) == [spheres.valid(x, 0.025) for x in q]
    assert list(batch) == [not spheres.contacts(x, 0.025) for x in q]
    spheres.hold(None)
    spheres.set_boxes([])


def test_the_held_block_hits_the_table_and_a_box_but_not_the_hand_holding_it(spheres):
    spheres.set_boxes([])
    spheres.hold(0.05)
    assert spheres.valid(HOME, 0.025)  # the fingers close on it: no hand contact
    rot, pos = spheres.model.links(HOME[None], PANDA.finger_open)
    tcp = pos[0, -1]
    assert rot[0, -1][2, 2] < -0.99  # the TCP's z points down at home
    below = np.eye(4)
    below[2, 3] = tcp[2] - 0.01  # a block held 1 cm into the table
    spheres.hold(0.04, pose=below)
    assert [(c.part, c.other) for c in spheres.contacts(HOME, 0.02)] == [("held", "table")]
    assert spheres.valid(HOME, 0.02, ignore=[("held", "table")])
    spheres.hold(0.05)
    spheres.set_boxes([Box("b", (tcp[0] + 0.05, tcp[1], tcp[2]), (0.02, 0.02, 0.02))])
    assert {c.other for c in spheres.contacts(HOME, 0.025)} == {"b"}  # 5 mm apart
    assert "held" in {c.part for c in spheres.contacts(HOME, 0.025)}
    spheres.hold(None)
    spheres.set_boxes([])


def test_check_path_finds_the_first_blocked_waypoint(spheres):
    spheres.set_boxes([Box("wall", (0.3, 0.0, 0.55), (0.05, 0.01, 0.1))])  # at the hand
    spheres.hold(None)
    start, goal = (
        HOME + np.array([-0.8, 0, 0, 0, 0, 0, 0]),
        HOME + np.array([0.8, 0, 0, 0, 0, 0, 0]),
    )
    assert spheres.valid(start) and spheres.valid(goal)
    found = spheres.check_path(np.stack([start, goal]), max_step=0.02)
    assert not found.ok and found.index == 1 and found.contact.other == "wall"
    assert found.checked < math.ceil(1.6 / 0.02) + 1
    assert spheres.check_path(np.stack([start, start + 0.01])).ok
    spheres.set_boxes([])


def test_misuse_raises_motion_error(spheres):
    with pytest.raises(MotionError, match="repeated"):
        spheres.set_boxes([Box("a", (0, 0, 0), (1, 1, 1)), Box("a", (0, 0, 0), (1, 1, 1))])
    with pytest.raises(MotionError, match="half"):
        spheres.set_boxes([Box("a", (0, 0, 0), (0, 1, 1))])
    with pytest.raises(MotionError, match=r"shape \(B, 7\)"):
        spheres.valid_batch(HOME)
    with pytest.raises(MotionError, match="not both"):
        spheres.hold(0.05, half=(0.1, 0.1, 0.1))
    with pytest.raises(MotionError, match="boxes: none"):
        spheres.valid(HOME, ignore=[("held", "nothing")])
    with pytest.raises(MotionError, match="margins"):
        SphereCollision(margin=-0.01)


# ---- the sphere cover and the pairs left out, against the meshes -----------------------------


def _hull_samples(name: str, n: int, seed: int) -> np.ndarray:
    """Points (V + n, 3) on the convex hull of a collision mesh: its vertices, and ``n``
    area-weighted samples on its facets (the hull of scipy, PyBullet's collision shape)."""
    spatial = pytest.importorskip("scipy.spatial")
    path = data_dir() / "franka_panda" / "meshes" / "collision" / name
    rows = [line.split()[1:4] for line in path.read_text().splitlines() if line[:2] == "v "]
    v = np.array(rows, dtype=float)
    tri = v[spatial.ConvexHull(v).simplices]  # (F, 3, 3)
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    rng = np.random.default_rng(seed)
    face = rng.choice(len(tri), n, p=area / area.sum())
    u, w = rng.random((2, n))
    flip = u + w > 1
    u[flip], w[flip] = 1 - u[flip], 1 - w[flip]
    t = tri[face]
    return np.concatenate(
        [v, t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + w[:, None] * (t[:, 2] - t[:, 0])]
    )


@pytest.mark.parametrize("link", PARTS)
def test_every_hull_point_lies_within_the_cover_gap_of_its_links_spheres(link):
    name = {FINGERS[0]: "finger", FINGERS[1]: "finger", "panda_hand": "hand"}.get(link)
    points = _hull_samples(f"{name or 'link' + link[-1]}.obj", 20000, seed=7)
    if link == FINGERS[1]:  # the URDF turns the right finger's mesh by pi about z
        points = points * np.array([-1.0, -1.0, 1.0])
    rows = [(a, r) for name_, a, r in (*SPHERES, *COVER) if name_ == link]
    centres, radii = np.array([a for a, _ in rows]), np.array([r for _, r in rows])
    gap = (np.linalg.norm(points[:, None] - centres[None], axis=-1) - radii).min(1)
    assert gap.max() < COVER_GAP, (link, gap.max())


def _closest_on_grid(pair, step: float) -> float:
    """The least distance of the pair's meshes over a ``step`` rad grid of the two joints
    before the distal link (from APART's lowest angle on, where it names one), the fingers
    open and closed."""
    p = pytest.importorskip("pybullet")
    from robots.pybullet_loader import load_panda

    a, b, joint, lowest = pair
    c = p.connect(p.DIRECT)
    try:
        robot = load_panda(c)
        links = {
            p.getJointInfo(robot.body, i, physicsClientId=c)[12].decode(): i
            for i in range(p.getNumJoints(robot.body, physicsClientId=c))
        } | {"panda_link0": -1}
        i = min(max(PARTS.index(a), PARTS.index(b)), 7) - 1  # the joint into the distal link
        grid = []
        for j in (i - 1, i):
            lo = max(PANDA.q_min[j], lowest) if j == joint else PANDA.q_min[j]
            grid.append(np.arange(lo, PANDA.q_max[j] + step / 2, step).clip(lo, PANDA.q_max[j]))
        worst = math.inf
        for x in grid[0]:
            for y in grid[1]:
                for f in (0.0, 0.04):
                    q = HOME.copy()
                    q[i - 1], q[i] = x, y
                    for jn, v in zip(robot.arm, q, strict=True):
                        p.resetJointState(robot.body, jn, v, physicsClientId=c)
                    for jn in robot.fingers:
                        p.resetJointState(robot.body, jn, f, physicsClientId=c)
                    pts = p.getClosestPoints(
                        robot.body, robot.body, 0.2, links[a], links[b], physicsClientId=c
                    )
                    worst = min(worst, min((pt[8] for pt in pts), default=0.2))
    finally:
        p.disconnect(c)
    return worst


@pytest.mark.sim
@pytest.mark.parametrize("pair", APART, ids=lambda pair: f"{pair[0]}-{pair[1]}")
def test_the_pairs_left_out_stay_apart_on_a_coarse_grid(pair):
    assert _closest_on_grid(pair, 0.1) > APART_CLEARANCE + 0.005, pair


@pytest.mark.sim
@pytest.mark.slow
@pytest.mark.parametrize("pair", APART, ids=lambda pair: f"{pair[0]}-{pair[1]}")
def test_the_pairs_left_out_stay_apart_between_the_grid_points(pair):
    """APART re-derived on a 0.03 rad grid (the default run samples every 0.1 rad only): the
    least distance, less the most a point within 0.3 m of both joint axes moves to the nearest
    grid point, stays above APART_CLEARANCE."""
    step = 0.03
    assert _closest_on_grid(pair, step) - 0.3 * step * math.sqrt(2) / 2 > APART_CLEARANCE, pair


def test_screened_sends_the_scene_to_both_and_answers_batches_with_spheres():
    class Mesh:
        margin, self_margin = 0.01, 0.0

        def __init__(self):
            self.calls = []

        def set_boxes(self, boxes):
            self.calls.append(("boxes", len(boxes)))

        def hold(self, size=None, half=None, pose=None):
            self.calls.append(("hold", size))

        def valid(self, q, fingers=0.04, ignore=()):
            return "mesh"

    mesh = Mesh()
    model = Screened(mesh)
    model.set_boxes([Box("wall", (0.45, 0.0, 0.12), (0.12, 0.01, 0.12))])
    model.hold(0.05)
    model.margin = 0.03
    assert mesh.calls == [("boxes", 1), ("hold", 0.05)]
    assert mesh.margin == model.spheres.margin == 0.03
    assert model.valid(HOME) == "mesh"
    assert model.valid_batch(HOME[None], 0.025).tolist() == [True]
    mesh.close = lambda: mesh.calls.append(("close",))
    with model as same:
        assert same is model and same.self_margin == 0.0  # the mesh model's
    assert mesh.calls[-1] == ("close",)


@pytest.mark.sim
def test_the_planner_routes_around_a_box_with_spheres_and_the_mesh_model_agrees(spheres):
    """plan_path with the spheres' valid_batch: a detour around a board in the hand's way,
    found without OMPL and valid under the mesh model at the checking resolution."""
    from motion.rrt import plan_path
    from robots.collision import PandaCollision

    board = [Box("board", (0.3, 0.0, 0.55), (0.05, 0.01, 0.1))]
    start, goal = (
        HOME + np.array([-0.8, 0, 0, 0, 0, 0, 0]),
        HOME + np.array([0.8, 0, 0, 0, 0, 0, 0]),
    )
    spheres.set_boxes(board)
    spheres.hold(None)
    with PandaCollision(margin=0.01) as mesh:
        mesh.set_boxes(board)
        r = plan_path(start, goal, mesh.valid, valid_batch=spheres.valid_batch)
        assert r.ok and r.evidence["search"] in ("via", "connect"), r.evidence
        assert not mesh.check_path(np.stack([start, goal])).ok
        assert mesh.check_path(r.path, max_step=0.01).ok
    spheres.set_boxes([])


def _reference_valid(model: SphereCollision, q: np.ndarray, fingers: float) -> np.ndarray:
    """`valid_batch` without any culling (no held box): every grown sphere against the table
    and every box (exact signed distance), and every checked link pair's spheres against the
    other link's box and 26-DOP, from the same forward kinematics."""
    rot, pos = model.model.links(q.astype(np.float32), fingers)
    m, gap = model.margin, model.gap
    free = np.ones(len(q), dtype=bool)
    spheres = []
    for link in range(len(PARTS)):
        rows = slice(model.model.start[link], model.model.start[link] + model.model.count[link])
        x = np.einsum("bij,sj->bsi", rot[:, link], model.model.local[rows]) + pos[:, link, None]
        spheres.append((x, model.model.radii[rows] + gap))  # (B, S, 3), (S,)
    for link, (x, r) in enumerate(spheres):
        if link > 0:  # link0 stands on the table
            free &= ((x[..., 2] - r) >= m).all(1)
        for o in range(len(model._names) - 1):
            d = x - model._box_c[o]
            c, s = model._cos[o], model._sin[o]
            local = np.stack([c * d[..., 0] + s * d[..., 1], c * d[..., 1] - s * d[..., 0]], -1)
            local = np.concatenate([local, d[..., 2:]], -1)
            sdf = np.linalg.norm(np.maximum(np.abs(local) - model._halves[o], 0.0), axis=-1)
            sdf += np.minimum((np.abs(local) - model._halves[o]).max(-1), 0.0)
            free &= ((sdf - r) >= m).all(1)
    for k, (c_link, a_link) in enumerate(model.model.pairs):
        rule = model.model.apart_from[k]
        if model.self_margin < APART_CLEARANCE:
            checked = q[:, model.model.apart_joint[k]] < rule  # (B,)
        else:
            checked = np.ones(len(q), dtype=bool)
        x, r = spheres[a_link]
        inner = np.einsum("bji,bsj->bsi", rot[:, c_link], x - pos[:, c_link, None])
        d = np.abs(inner - model.model.aabb_c[c_link]) - model.model.aabb_h[c_link]
        box = np.linalg.norm(np.maximum(d, 0.0), axis=-1) + np.minimum(d.max(-1), 0.0)
        dop = (inner @ model.model.directions.T - model.model.dop[c_link]).max(-1)
        hit = ((box - r) < model.self_margin) & ((dop - r) < model.self_margin)
        free &= ~(hit.any(1) & checked)
    return free


@pytest.mark.parametrize("self_margin", [0.0, 0.002, 0.005])
def test_valid_batch_agrees_with_a_check_without_culling(self_margin):
    """The broad phases, buckets and clusters only skip work: 2,100 configurations beside
    boxes and about q_home (a quarter free; a 5 mm wider margin flips about 2 % of them) get
    the verdicts of every sphere tested against everything. From APART_CLEARANCE on, the
    wrist's pairs are tested too, and refuse nearly all of them."""
    model = SphereCollision(margin=0.01, self_margin=self_margin)
    rng = np.random.default_rng(6)
    free = total = 0
    for k, (boxes, _, q) in enumerate(near_arm_scenes(model, 30, 40, seed=5)):
        model.set_boxes(boxes)
        model.hold(None)
        fingers = float(rng.uniform(0.0, 0.04))
        q = np.concatenate([q, np.clip(HOME + rng.normal(0.0, 0.5, (30, 7)), LO, HI)])
        fast = model.valid_batch(q, fingers)
        assert np.array_equal(fast, _reference_valid(model, q, fingers)), k
        free, total = free + int(fast.sum()), total + len(q)
    if self_margin < APART_CLEARANCE:
        assert 0.1 * total < free < 0.9 * total
    model.set_boxes([])


def test_a_batch_of_several_chunks_gets_the_reference_verdicts():
    """valid_batch checks CHUNK configurations at a time: a batch of a little over two chunks
    (beside boxes, about q_home and across the joint box) gets the verdicts of the check
    without culling, configuration by configuration."""
    model = SphereCollision(margin=0.01)
    boxes, _, q = next(near_arm_scenes(model, 1, 40, seed=8))
    model.set_boxes(boxes)
    rng = np.random.default_rng(9)
    q = np.concatenate(
        [
            q,
            np.clip(HOME + rng.normal(0.0, 0.5, (CHUNK, 7)), LO, HI),
            rng.uniform(LO, HI, (CHUNK + 3, 7)),
        ]
    )
    fast = model.valid_batch(q, 0.02)
    assert len(fast) == len(q) > 2 * CHUNK
    assert 0 < fast.sum() < len(q)
    assert np.array_equal(fast, _reference_valid(model, q, 0.02))
    model.set_boxes([])


def test_the_26_dop_bound_equals_the_matrix_product():
    """`bounds.dop_gap` (three broadcast products, no BLAS) against the matrix product."""
    rng = np.random.default_rng(3)
    model = SphereCollision()
    p = rng.normal(0.0, 0.2, (500, 3)).astype(np.float32)
    support = model.model.dop_c[:, rng.integers(0, len(PARTS), 500)]  # (26, 500)
    want = (p.astype(float) @ model.model.directions.T.astype(float) - support.T).max(-1)
    assert np.allclose(dop_gap(p, model.model.directions, support), want, atol=1e-6)
