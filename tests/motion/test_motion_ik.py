"""IK and FK of the Panda TCP: home pose, batched convergence, limits, misuse, the refine step."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
import torch

from motion.errors import MotionError
from motion.ik import grasp_yaw, ik_refine, pose_yaw, top_down_pose
from robots.panda import PANDA

HOME_TCP = (0.307, 0.0, 0.485)


def _random_top_down(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    xyz = rng.uniform((0.35, -0.3, 0.03), (0.65, 0.3, 0.25), size=(n, 3))
    yaw = rng.uniform(-math.pi, math.pi, size=n)
    return np.stack([top_down_pose(p, y) for p, y in zip(xyz, yaw, strict=True)])  # (n, 4, 4)


def test_import_motion_stays_light():
    code = "import sys, motion; print([m for m in ('torch', 'ruckig') if m in sys.modules])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_fk_of_home_is_top_down_in_front_of_the_robot(solver):
    h = solver.fk(PANDA.q_home)
    assert h.shape == (1, 4, 4)
    np.testing.assert_allclose(h[0, :3, 3], HOME_TCP, atol=1e-3)
    np.testing.assert_allclose(h[0, :3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-3)
    np.testing.assert_allclose(top_down_pose(HOME_TCP, 0.0), h[0], atol=1e-3)
    assert solver.fk(np.tile(PANDA.q_home, (3, 1))).shape == (3, 4, 4)


def test_ik_converges_on_100_random_top_down_targets(solver):
    targets = _random_top_down(100, seed=1)
    result = solver.solve(targets, PANDA.q_home)
    assert result.ok.all()
    assert result.q.shape == (100, 7)
    reached = solver.fk(result.q)
    np.testing.assert_allclose(reached[:, :3, 3], targets[:, :3, 3], atol=1e-3)
    np.testing.assert_allclose(reached[:, :3, :3], targets[:, :3, :3], atol=1e-2)
    assert (result.pos_err < 1e-4).all() and (result.rot_err < 1e-3).all()
    assert all(PANDA.clamp_error(q) is None for q in result.q)


def test_ik_prefers_the_solution_closest_to_the_current_configuration(solver):
    q_now = np.array(PANDA.q_home) + 0.05
    result = solver.solve(solver.fk(q_now), q_now)
    assert result.ok[0]
    np.testing.assert_allclose(result.q[0], q_now, atol=1e-3)


def test_unreachable_target_is_a_status_not_an_exception(solver):
    targets = np.stack([top_down_pose((2.0, 0.0, 0.3), 0.0), top_down_pose((0.5, 0.0, 0.1), 0.3)])
    result = solver.solve(targets, PANDA.q_home)
    assert result.ok.tolist() == [False, True]
    assert result.pos_err[0] > 0.5
    assert np.isfinite(result.q).all()


@pytest.mark.parametrize(
    ("targets", "q_current"),
    [
        (np.zeros((2, 3, 4)), PANDA.q_home),
        (np.zeros(4), PANDA.q_home),
        (np.eye(4)[None], PANDA.q_home[:6]),
        (np.eye(4)[None], np.tile(PANDA.q_home, (2, 1))),
        (np.full((1, 4, 4), np.nan), PANDA.q_home),
        (2.0 * np.eye(4)[None], PANDA.q_home),  # rotation block not orthonormal
    ],
)
def test_bad_shapes_raise_motion_error(solver, targets, q_current):
    with pytest.raises(MotionError):
        solver.solve(targets, q_current)


@pytest.mark.parametrize("q", [np.zeros(6), np.zeros((2, 3, 7)), [[0.0] * 7, [0.0] * 6]])
def test_fk_rejects_bad_shapes(solver, q):
    with pytest.raises(MotionError):
        solver.fk(q)


@pytest.mark.parametrize("block_yaw", [-3.0, -1.2, -0.4, 0.0, 0.3, 0.9, 2.0, 3.1])
@pytest.mark.parametrize("hand_yaw", [-1.5, 0.0, 0.5, 2.0])
def test_grasp_yaw_is_an_equivalent_yaw_near_the_hand(block_yaw, hand_yaw):
    yaw = grasp_yaw(block_yaw, hand_yaw)
    quarter = math.pi / 2
    assert abs(math.remainder(yaw - block_yaw, quarter)) < 1e-9
    assert -math.pi / 4 - 1e-9 <= yaw < 3 * math.pi / 4
    others = [yaw + quarter, yaw - quarter]
    others = [c for c in others if -math.pi / 4 - 1e-9 <= c < 3 * math.pi / 4]
    gap = abs(math.remainder(yaw - hand_yaw, 2 * math.pi))
    assert all(gap <= abs(math.remainder(c - hand_yaw, 2 * math.pi)) + 1e-9 for c in others)


def test_pose_yaw_inverts_top_down_pose():
    for yaw in (-2.5, -0.3, 0.0, 1.0, 3.0):
        assert math.isclose(pose_yaw(top_down_pose((0.5, 0.0, 0.1), yaw)), yaw, abs_tol=1e-12)


def _solved(solver, n: int, seed: int):
    targets = _random_top_down(n, seed)
    result = solver.solve(targets, PANDA.q_home)
    assert result.ok.all()
    return torch.from_numpy(result.q.copy()), torch.from_numpy(targets)


def test_ik_refine_is_a_fixed_point_at_the_solution(solver):
    q_star, targets = _solved(solver, 3, seed=2)
    q = ik_refine(solver, q_star, targets)
    torch.testing.assert_close(q, q_star, atol=1e-5, rtol=0.0)


def test_ik_refine_gradients_match_finite_differences(solver):
    q_star, targets = _solved(solver, 2, seed=3)
    targets = targets.clone().requires_grad_(True)
    assert torch.autograd.gradcheck(lambda t: ik_refine(solver, q_star, t), (targets,))


def test_ik_refine_follows_a_moved_target_to_first_order(solver):
    q_star, targets = _solved(solver, 4, seed=4)
    moved = targets.clone()
    moved[:, :3, 3] += torch.tensor([1e-3, -1e-3, 2e-3], dtype=torch.float64)
    reached = solver.fk_tensor(ik_refine(solver, q_star, moved)).detach()
    err = (reached[:, :3, 3] - moved[:, :3, 3]).norm(dim=-1)
    assert (err < 2e-5).all()  # second order in the 2.4 mm step


def test_ik_refine_rejects_bad_shapes(solver):
    q_star, targets = _solved(solver, 2, seed=5)
    with pytest.raises(MotionError):
        ik_refine(solver, q_star[0], targets)
    with pytest.raises(MotionError):
        ik_refine(solver, q_star, targets[:1])


def test_follow_tracks_a_vertical_line_on_one_branch(solver):
    start = solver.solve(top_down_pose((0.5, 0.1, 0.05), 0.3)[None], np.asarray(PANDA.q_home))
    assert start.ok[0]
    line = np.stack([top_down_pose((0.5, 0.1, 0.05 + 0.02 * k), 0.3) for k in range(1, 11)])
    out = solver.follow(line, start.q[0])
    assert out.ok.all()
    np.testing.assert_allclose(solver.fk(out.q)[:, :3, 3], line[:, :3, 3], atol=1e-4)
    knots = np.vstack([start.q, out.q])  # (11, J)
    assert np.abs(np.diff(knots, axis=0)).max() < 0.2  # no branch switch between 2 cm knots


def test_follow_reports_targets_it_cannot_reach(solver):
    far = top_down_pose((2.0, 0.0, 0.1), 0.0)[None]
    assert not solver.follow(far, np.asarray(PANDA.q_home)).ok[0]


def test_from_seeds_solves_each_pose_on_its_own_seeds_branch(solver):
    """Two seeds of one top-down pose: each converges to a solution of that pose near its own
    seed (another posture of the arm), not to one answer for both."""
    pose = top_down_pose((0.5, -0.1, 0.1), 0.0)
    near = solver.solve(pose[None], PANDA.q_home).q[0]
    other = near + np.array([-1.0, 0.0, 1.5, 0.0, 1.2, 0.0, 0.0])  # the elbow swung aside
    found = solver.from_seeds(np.stack([pose, pose]), np.stack([near, other]))
    assert found.ok.all()
    np.testing.assert_allclose(solver.fk(found.q)[:, :3, 3], [pose[:3, 3]] * 2, atol=2e-4)
    assert np.abs(found.q[0] - near).max() < 1e-3
    assert np.abs(found.q[1] - found.q[0]).max() > 0.5  # a different posture of the same pose
    with pytest.raises(MotionError, match="2 seeds for 1 targets"):
        solver.from_seeds(pose[None], np.stack([near, other]))


def test_building_a_solver_leaves_mujoco_importable_and_headless():
    """pytorch_kinematics imports mujoco; a solver built first (``MUJOCO_GL`` unset) leaves
    ``sys.modules`` without a placeholder for it, and mujoco on the simulators' headless
    default (EGL), so a MuJoCo simulator made afterwards still renders offscreen."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import sys; from motion.ik import IKSolver; IKSolver(); "
        "print(sys.modules.get('mujoco', 0) is not None); "
        "import mujoco.rendering.classic.gl_context as g; print(g._MUJOCO_GL)"
    )
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    root = Path(__file__).resolve().parents[2]
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=root, check=True
    )
    assert out.stdout.split() == ["True", "egl"]
