"""The Panda collision model: scene boxes, table, held cube, ignore pairs, paths, self-collision."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from robots.collision import DISABLED_PAIRS, HAND, Box, PandaCollision
from robots.errors import RobotError
from robots.panda import PANDA

pytestmark = pytest.mark.sim

HOME = np.asarray(PANDA.q_home)
DOWN = (0.0, 0.6, 0.0, -2.4, 0.0, 3.0, 0.785)  # hand pointing down, fingertips ~4 cm below z = 0


@pytest.fixture(scope="module")
def world():
    with PandaCollision() as pc:
        yield pc


@pytest.fixture
def pc(world):
    world.set_boxes([])
    world.hold(None)
    yield world


@pytest.fixture(scope="module")
def fk():
    """TCP position (3,) of a configuration, from a separate PyBullet client."""
    import pybullet as p

    from robots.pybullet_loader import load_panda

    c = p.connect(p.DIRECT)
    robot = load_panda(c)

    def tcp(q) -> np.ndarray:
        for j, v in zip(robot.arm, q, strict=True):
            p.resetJointState(robot.body, j, v, physicsClientId=c)
        state = p.getLinkState(robot.body, robot.tcp, computeForwardKinematics=1, physicsClientId=c)
        return np.asarray(state[4])

    yield tcp
    p.disconnect(c)


def test_home_without_boxes_is_valid(pc):
    assert pc.valid(HOME) and pc.contacts(HOME) == []
    assert pc.valid(HOME, fingers=0.0)  # closed fingers touch each other: a disabled pair


def test_box_at_the_hand_collides_with_the_hand(pc, fk):
    pc.set_boxes([Box("obstacle", tuple(fk(HOME)), (0.05, 0.05, 0.05), yaw=0.3)])
    assert not pc.valid(HOME)
    hits = pc.contacts(HOME)
    assert {c.other for c in hits} == {"obstacle"}
    assert {c.part for c in hits} <= set(HAND) and hits[0].distance < 0
    assert hits == sorted(hits, key=lambda c: c.distance)


def test_hand_through_the_table_collides_with_the_table(pc, fk):
    assert fk(DOWN)[2] < 0
    hits = pc.contacts(DOWN)
    assert hits and {c.other for c in hits} == {"table"}
    assert pc.valid(HOME)  # link0 always stands on the table


def test_ignore_pairs_skip_contacts(pc, fk):
    assert pc.valid(DOWN, ignore=[("hand", "table")])
    assert not pc.valid(DOWN, ignore=[("panda_hand", "table"), ("panda_leftfinger", "table")])
    pc.set_boxes([Box("obstacle", tuple(fk(HOME)), (0.05, 0.05, 0.05))])
    assert pc.valid(HOME, ignore={("hand", "obstacle")})
    assert pc.valid(HOME, ignore=[("robot", "obstacle")])
    assert not pc.valid(HOME, ignore=[("panda_leftfinger", "obstacle")])
    assert not pc.valid(HOME, ignore=[("hand", "table")])
    # fingers closed on a block at the TCP: only the ignore pair makes it valid
    pc.set_boxes([Box("block", tuple(fk(HOME)), (0.025, 0.025, 0.025))])
    assert pc.valid(HOME, fingers=0.04)
    assert not pc.valid(HOME, fingers=0.025)
    assert pc.valid(HOME, fingers=0.025, ignore=[("hand", "block")])


def test_held_cube_collides_where_the_bare_arm_does_not(pc, fk):
    x, y, z = fk(HOME)
    pc.set_boxes([Box("below", (x, y, z - 0.035 - 0.02), (0.05, 0.05, 0.02))])
    assert pc.valid(HOME)
    pc.hold(0.06)
    hits = pc.contacts(HOME)
    assert [(c.part, c.other) for c in hits] == [("held", "below")]
    assert pc.valid(HOME, ignore=[("held", "below")])
    pc.set_boxes([])
    assert pc.valid(HOME)  # the held cube overlaps the fingers: always ignored
    assert not pc.valid(DOWN, ignore=[("hand", "table")])  # but not the table
    pc.hold(None)
    assert pc.valid(DOWN, ignore=[("hand", "table")])


def test_check_path_reports_the_first_colliding_waypoint(pc, fk):
    path = np.repeat(HOME[None], 9, axis=0)  # (S, J): sweep joint 1 through -0.8 .. 0.8
    path[:, 0] = np.linspace(-0.8, 0.8, 9)
    pc.set_boxes(
        [Box("obstacle", tuple(fk(HOME) + np.array([0.0, 0.0, 0.06])), (0.04, 0.04, 0.04))]
    )
    res = pc.check_path(path)
    assert not res.ok and res.contact.other == "obstacle" and "obstacle" in res.failure
    assert 0 < res.index < 4 and pc.check_path(path[: res.index]).ok
    assert pc.contacts(res.q) and res.checked < 1 + 8 * 10
    over = path.copy()  # the same sweep with the hand raised 0.2 m passes around it
    over[:, 3] = -1.9
    assert fk(over[4])[2] > fk(HOME)[2] + 0.15
    ok = pc.check_path(over)
    assert ok.ok and ok.index is None and ok.contact is None and ok.checked == 1 + 8 * 10


def test_large_joint_steps_are_densified(pc):
    path = np.stack([HOME, HOME + np.eye(7)[0] * 0.5])  # (2, J)
    res = pc.check_path(path, max_step=0.02)
    assert res.ok and res.checked == 1 + 25 > len(path)
    assert pc.check_path(path, fingers=[0.04, 0.0]).ok
    assert pc.check_path(path[:1]).checked == 1


@pytest.mark.parametrize(
    "call",
    [
        lambda pc: pc.set_boxes([Box("a", (0, 0, 0), (1, 1, 1)), Box("a", (1, 0, 0), (1, 1, 1))]),
        lambda pc: pc.set_boxes([Box("table", (0, 0, 0), (1, 1, 1))]),
        lambda pc: pc.set_boxes([Box("panda_hand", (0, 0, 0), (1, 1, 1))]),
        lambda pc: pc.set_boxes([Box("a", (0, 0, 0), (1, -1, 1))]),
        lambda pc: pc.set_boxes([Box("a", (0, 0), (1, 1, 1))]),
        lambda pc: pc.set_boxes([Box("a", (0, 0, float("nan")), (1, 1, 1))]),
        lambda pc: pc.hold(-0.05),
        lambda pc: pc.check_path(np.zeros((3, 6))),
        lambda pc: pc.check_path(np.zeros(7)),
        lambda pc: pc.check_path(np.zeros((3, 7)), fingers=[0.04, 0.0]),
        lambda pc: pc.check_path(np.zeros((3, 7)), max_step=0.0),
        lambda pc: pc.valid(HOME[:6]),
        lambda pc: pc.valid(HOME, ignore=[("panda_elbow", "table")]),
        lambda pc: pc.valid(HOME, ignore=[("hand", "nothing")]),
    ],
)
def test_bad_input_raises_one_line_robot_error(pc, call):
    with pytest.raises(RobotError) as err:
        call(pc)
    assert "\n" not in str(err.value)


def test_random_configurations_sometimes_self_collide_and_home_never(pc):
    rng = np.random.default_rng(0)
    qs = rng.uniform(PANDA.q_min, PANDA.q_max, size=(200, 7))  # (B, J)
    links = set(pc.parts) - {"held"}
    own = [q for q in qs if any(c.other in links for c in pc.contacts(q))]
    assert 0 < len(own) < len(qs)
    assert all(not pc.valid(q, ignore=[("robot", "table")]) for q in own)
    assert not any(c.other in links for f in (0.0, 0.04) for c in pc.contacts(HOME, f))


def test_closed_after_close():
    pc = PandaCollision()
    pc.close()
    pc.close()
    with pytest.raises(RobotError, match="closed"):
        pc.valid(HOME)


def test_disabled_pairs_match_their_derivation():
    """Derive DISABLED_PAIRS like MoveIt's setup assistant (penetration = distance < 0).

    Adjacent links (parents without geometry collapsed), pairs penetrating in >= 99 % of 1000
    uniform configurations within the datasheet limits (fingers uniform in [0, 0.04] m, seed 0),
    and pairs penetrating at q_home with the fingers open or closed.
    """
    import pybullet as p

    from robots.pybullet_loader import load_panda

    c = p.connect(p.DIRECT)
    try:
        robot = load_panda(c)
        body = robot.body
        info = {i: p.getJointInfo(body, i, physicsClientId=c) for i in range(robot.tcp + 1)}
        name = {-1: PANDA.base_link} | {i: j[12].decode() for i, j in info.items()}
        links = [i for i in name if p.getCollisionShapeData(body, i, physicsClientId=c)]
        adjacent = set()
        for link in links:
            parent = info[link][16] if link >= 0 else None
            while parent is not None and parent not in links:
                parent = info[parent][16]
            if parent is not None:
                adjacent.add(frozenset((name[parent], name[link])))
        pairs = list(itertools.combinations(links, 2))

        def touching(q, f) -> np.ndarray:
            for j, v in zip((*robot.arm, *robot.fingers), (*q, f, f), strict=True):
                p.resetJointState(body, j, v, physicsClientId=c)
            gap = [p.getClosestPoints(body, body, 0.0, a, b, physicsClientId=c) for a, b in pairs]
            return np.array([min((pt[8] for pt in g), default=1.0) < 0 for g in gap])  # (pairs,)

        rng = np.random.default_rng(0)
        lo, hi = np.asarray(PANDA.q_min), np.asarray(PANDA.q_max)
        often = np.mean(
            [touching(rng.uniform(lo, hi), rng.uniform(0, 0.04)) for _ in range(1000)], 0
        )
        home = touching(PANDA.q_home, 0.0) | touching(PANDA.q_home, PANDA.finger_open)
        hit = (often >= 0.99) | home
        derived = adjacent | {
            frozenset((name[a], name[b])) for k, (a, b) in enumerate(pairs) if hit[k]
        }
    finally:
        p.disconnect(c)
    assert derived == DISABLED_PAIRS


def test_set_boxes_moves_reused_bodies_as_a_fresh_model_has_them(pc, fk):
    """Boxes of a shape set before are moved, not rebuilt: the contacts (names, parts,
    distances) after a sequence of scenes equal a fresh model's given the last scene alone."""
    rng = np.random.default_rng(3)
    at = fk(HOME)
    scenes = []
    for _ in range(4):
        boxes = []
        for k in range(int(rng.integers(1, 5))):
            half = (0.02, 0.02, 0.02) if k % 2 else (0.03, 0.02, 0.05)
            centre = tuple(at + rng.uniform(-0.08, 0.08, 3))
            boxes.append(Box(f"b{k}", centre, half, yaw=float(rng.uniform(-1, 1))))
        scenes.append(boxes)
    touching = 0
    for boxes in scenes:
        pc.set_boxes(boxes)
        with PandaCollision() as fresh:
            fresh.set_boxes(boxes)
            want = [(c.part, c.other, round(c.distance, 6)) for c in fresh.contacts(HOME)]
        got = [(c.part, c.other, round(c.distance, 6)) for c in pc.contacts(HOME)]
        assert got == want
        touching += bool(want)
    assert touching  # some scene puts a box against the arm: the contacts were compared
