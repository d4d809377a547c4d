"""The sphere model of the Panda and its collision proxy: box SDF, CHOMP cost, meshes, gradients."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from motion.errors import MotionError
from motion.spheres import (
    RADII,
    box_contacts,
    box_sdf,
    chomp_potential,
    collision_cost,
    sphere_positions,
)
from robots.panda import PANDA, data_dir
from robots.panda_spheres import FINGERS, SPHERES

HOME = torch.tensor([PANDA.q_home], dtype=torch.float64)  # (1, J)
Q_SOME = (0.4, -0.3, -0.5, -2.0, 0.6, 2.2, -0.3)  # an arbitrary configuration inside the limits


def _t(rows) -> torch.Tensor:
    return torch.tensor(rows, dtype=torch.float64)


def _box_at_link4(solver, half=0.03):
    """A cube of half extent ``half`` centred on the first panda_link4 sphere at q_home."""
    k = next(i for i, (link, _, _) in enumerate(SPHERES) if link == "panda_link4")
    centre = sphere_positions(solver, HOME)[0, k]  # (3,)
    return centre[None].detach(), _t([[half] * 3])  # (1, 3), (1, 3)


def test_box_sdf_is_exact_on_known_points():
    centres, half = _t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), _t([[0.1, 0.2, 0.3], [0.1, 0.1, 0.1]])
    points = _t(
        [
            [0.0, 0.0, 0.0],  # centre of box 0: depth to its nearest face (x) is 0.1
            [0.05, 0.0, 0.25],  # inside box 0: nearest face z, 0.05 away
            [0.0, 0.0, 0.5],  # above box 0's top face by 0.2
            [0.4, 0.5, 0.0],  # beyond box 0's corner edge: (0.3, 0.3) outside in x and y
            [0.1, 0.0, 0.0],  # on box 0's face
        ]
    )
    sdf = box_sdf(points, centres, half)  # (5, 2)
    want0 = [-0.1, -0.05, 0.2, math.hypot(0.3, 0.3), 0.0]
    want1 = [0.9, math.hypot(0.85, 0.15), math.hypot(0.9, 0.4), math.hypot(0.5, 0.4), 0.8]
    np.testing.assert_allclose(sdf.numpy(), np.array([want0, want1]).T, atol=1e-12)


def test_chomp_potential_is_linear_inside_quadratic_in_the_margin_and_zero_beyond():
    d = _t([-0.01, 0.0, 0.01, 0.02, 0.05]).requires_grad_()
    h = chomp_potential(d, margin=0.02)
    np.testing.assert_allclose(h.detach().numpy(), [0.02, 0.01, 0.0025, 0.0, 0.0], atol=1e-15)
    (grad,) = torch.autograd.grad(h.sum(), d)
    np.testing.assert_allclose(grad.numpy(), [-1.0, -1.0, -0.5, 0.0, 0.0], atol=1e-12)  # C1


def test_sphere_positions_have_one_centre_per_row_and_move_the_fingers(solver):
    open_ = sphere_positions(solver, HOME)  # (1, S, 3)
    assert open_.shape == (1, len(SPHERES), 3) and RADII.shape == (len(SPHERES),)
    closed = sphere_positions(solver, HOME, finger=0.0)
    moved = (open_ - closed).norm(dim=-1)[0]  # (S,)
    fingers = torch.tensor([link in FINGERS for link, _, _ in SPHERES])
    torch.testing.assert_close(moved[fingers], torch.full((4,), 0.04, dtype=torch.float64))
    assert (moved[~fingers] == 0).all()


def test_collision_cost_is_zero_far_away_and_positive_with_a_box_across_the_arm(solver):
    q = torch.cat([HOME, _t([Q_SOME])])  # (2, J)
    far = collision_cost(solver, q, _t([[2.0, 2.0, 0.5]]), _t([[0.1, 0.1, 0.1]]))
    assert torch.equal(far, torch.zeros(2, dtype=torch.float64))
    none = collision_cost(solver, q, torch.zeros(0, 3), torch.zeros(0, 3))
    assert torch.equal(none, torch.zeros(2, dtype=torch.float64))
    centre, half = _box_at_link4(solver)
    phi = collision_cost(solver, HOME, centre, half)  # (1,)
    # the sphere under the box is at least its radius + the box's half extent deep in it
    assert phi[0] > 0.052 + 0.03
    smaller = collision_cost(solver, HOME, centre, half / 2)
    assert 0 < smaller[0] < phi[0]


def test_collision_cost_gradient_matches_finite_differences(solver):
    centre, half = _box_at_link4(solver, half=0.05)
    centre = centre + _t([0.03, -0.02, 0.01])  # off-centre: no ties between faces
    q = torch.cat([HOME, _t([Q_SOME])]).requires_grad_()  # (2, J), the second far from the box
    assert collision_cost(solver, q, centre, half)[0] > 0

    def phi(qq):
        return collision_cost(solver, qq, centre, half, margin=0.03)

    assert torch.autograd.gradcheck(phi, (q,), eps=1e-6, atol=1e-6)


def test_a_step_against_the_gradient_moves_the_arm_out_of_the_box(solver):
    centre, half = _box_at_link4(solver)
    q = HOME.clone().requires_grad_()
    phi = collision_cost(solver, q, centre, half)[0]
    (grad,) = torch.autograd.grad(phi, q)
    step = q.detach() - 0.05 * grad / grad.norm()  # 0.05 rad
    assert collision_cost(solver, step, centre, half)[0] < phi.detach()


def _three_boxes(solver):
    """Boxes (3, 3) x 2: one deep in the arm at q_home, one grazing it, one far away."""
    centre, half = _box_at_link4(solver, half=0.04)
    x = sphere_positions(solver, HOME)[0]  # (G, 3)
    k = int((x[:, 2] - RADII).argmin())  # the lowest sphere: a fingertip
    graze = x[k : k + 1] - _t([[0.0, 0.0, RADII[k] + 0.01 + 0.04]])  # 1 cm under it
    centres = torch.cat([centre + _t([[0.01, -0.02, 0.0]]), graze, _t([[2.0, 2.0, 0.5]])])
    return centres, half.expand(3, 3)


def test_the_per_box_costs_sum_to_phi_and_the_depth_is_the_deepest_sphere(solver):
    centres, half = _three_boxes(solver)
    q = torch.cat([HOME, _t([Q_SOME])])  # (2, J)
    per_box = box_contacts(solver, q, centres, half).cost  # (2, 3)
    assert per_box.shape == (2, 3) and per_box[0, 0] > 0 and per_box[0, 1] > 0
    assert (per_box[:, 2] == 0).all()
    torch.testing.assert_close(
        per_box.sum(1), collision_cost(solver, q, centres, half), atol=1e-14, rtol=0
    )
    depth = box_contacts(solver, q, centres, half).depth  # (2, 3)
    gap = box_sdf(sphere_positions(solver, q), centres, half) - RADII[:, None]  # (2, G, 3)
    torch.testing.assert_close(depth, (-gap).amax(1).clamp(min=0.0), atol=0, rtol=0)
    assert depth[0, 0] > 0.05 and depth[0, 1] == 0 and not depth.requires_grad


def test_boxes_of_each_configuration_match_shared_boxes_row_by_row(solver):
    centres, half = _three_boxes(solver)
    q = torch.cat([HOME, _t([Q_SOME])]).requires_grad_()  # (2, J)
    own = torch.stack([centres, centres + _t([[0.0, 0.0, 5.0]])])  # (2, 3, 3): row 1's far off
    got = box_contacts(solver, q, own, half.expand(2, 3, 3)).cost  # (2, 3)
    torch.testing.assert_close(got[0], box_contacts(solver, q[:1], centres, half).cost[0])
    assert (got[1] == 0).all()
    (grad,) = torch.autograd.grad(got.sum(), q)
    assert grad[0].norm() > 0 and (grad[1] == 0).all()


@pytest.mark.parametrize(
    ("q", "centres", "half", "message"),
    [
        (torch.zeros(1, 6), torch.zeros(1, 3), torch.ones(1, 3), "q has shape"),
        (HOME, torch.zeros(1, 2), torch.ones(1, 3), "box centres has shape"),
        (HOME, torch.zeros(2, 3), torch.ones(1, 3), "box half extents has shape"),
        (HOME, torch.zeros(1, 3), torch.zeros(1, 3), "must be > 0"),
        (HOME, torch.full((1, 3), math.nan), torch.ones(1, 3), "contains NaN"),
        (HOME, torch.zeros(2, 1, 3), torch.ones(2, 1, 3), "box centres has shape"),
        (HOME, torch.zeros(1, 2, 3), torch.ones(1, 3, 3), "box half extents has shape"),
    ],
)
def test_misuse_names_the_bad_input(solver, q, centres, half, message):
    with pytest.raises(MotionError, match=message):
        collision_cost(solver, q, centres, half)
    with pytest.raises(MotionError, match=message):
        box_contacts(solver, q, centres, half)


def test_a_margin_of_zero_is_refused():
    with pytest.raises(MotionError, match="margin must be > 0"):
        chomp_potential(torch.zeros(1), 0.0)


# ---- against PyBullet's collision meshes of the same URDF ----------------------------------


def _obj_vertices(name: str) -> np.ndarray:
    """Vertices (V, 3) of a collision mesh of pybullet_data's Panda."""
    path = data_dir() / "franka_panda" / "meshes" / "collision" / name
    rows = [line.split()[1:4] for line in path.read_text().splitlines() if line.startswith("v ")]
    return np.array(rows, dtype=float)


@pytest.fixture(scope="module")
def bullet():
    p = pytest.importorskip("pybullet")
    from robots.pybullet_loader import load_panda

    client = p.connect(p.DIRECT)
    robot = load_panda(client)
    links = {
        p.getJointInfo(robot.body, i, physicsClientId=client)[12].decode(): i
        for i in range(p.getNumJoints(robot.body, physicsClientId=client))
    }
    yield p, client, robot, links
    p.disconnect(client)


def _pose(bullet, q, finger):
    """Put the PyBullet Panda at (q, finger); link name -> its URDF frame (R (3, 3), t (3,))."""
    p, c, robot, links = bullet
    for j, v in zip(robot.arm, q, strict=True):
        p.resetJointState(robot.body, j, v, physicsClientId=c)
    for j in robot.fingers:
        p.resetJointState(robot.body, j, finger, physicsClientId=c)
    out = {}
    for name, i in links.items():
        state = p.getLinkState(robot.body, i, computeForwardKinematics=1, physicsClientId=c)
        rot = np.array(p.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        out[name] = (rot, np.array(state[4]))
    return out


@pytest.mark.sim
@pytest.mark.parametrize("finger", [0.04, 0.015])
@pytest.mark.parametrize("q", [PANDA.q_home, Q_SOME], ids=["home", "some"])
def test_centres_ride_on_pybullets_link_frames(solver, bullet, q, finger):
    frames = _pose(bullet, q, finger)
    want = np.array([frames[link][0] @ a + frames[link][1] for link, a, _ in SPHERES])  # (S, 3)
    got = sphere_positions(solver, _t([q]), finger)[0].numpy()
    np.testing.assert_allclose(got, want, atol=1e-6)


@pytest.mark.sim
@pytest.mark.parametrize("q", [PANDA.q_home, Q_SOME], ids=["home", "some"])
def test_spheres_cover_the_collision_meshes_to_within_two_cm(solver, bullet, q):
    # the margin of the cost (2 cm by default) makes up for what the spheres leave out
    frames = _pose(bullet, q, PANDA.finger_open)
    centres = sphere_positions(solver, _t([q]))[0].numpy()  # (S, 3)
    radii = RADII.numpy()
    meshes = {f"panda_link{i}": f"link{i}.obj" for i in range(1, 8)}
    meshes |= {"panda_hand": "hand.obj", FINGERS[0]: "finger.obj"}
    for link, name in meshes.items():
        rot, t = frames[link]
        v = _obj_vertices(name) @ rot.T + t  # (V, 3) in the world
        gap = np.linalg.norm(v[:, None] - centres[None], axis=-1) - radii  # (V, S)
        assert gap.min(1).max() < 0.02, link  # every vertex within 2 cm of some sphere


@pytest.mark.sim
def test_every_sphere_overlaps_its_own_link(bullet):
    p, c, robot, links = bullet
    frames = _pose(bullet, PANDA.q_home, PANDA.finger_open)
    probe = p.createCollisionShape(p.GEOM_SPHERE, radius=1e-4, physicsClientId=c)
    ball = p.createMultiBody(0, probe, -1, [0.0, 0.0, -5.0], physicsClientId=c)
    for link, a, r in SPHERES:
        rot, t = frames[link]
        p.resetBasePositionAndOrientation(
            ball, (rot @ a + t).tolist(), [0, 0, 0, 1], physicsClientId=c
        )
        pts = p.getClosestPoints(ball, robot.body, 1.0, -1, links[link], physicsClientId=c)
        assert min(pt[8] for pt in pts) < r, link  # centre nearer the link's mesh than r
    p.removeBody(ball, physicsClientId=c)
