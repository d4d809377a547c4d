"""Differentiable collision proxy of the Panda against boxes: a sphere model and exact box SDFs.

The arm is the union of the G spheres in `robots.panda_spheres.SPHERES` (centre ``a_s`` in link
frame ``l(s)``, radius ``r_s``); pytorch-kinematics gives every link frame ``T_l(q)`` of the IK
chain, so the centres ``x_s(q) = T_l(s)(q) a_s`` (the fingers ride on ``panda_hand`` at a fixed
opening) are differentiable in q. Obstacles are axis-aligned boxes in the base frame, centres
``c_o`` (O, 3) and half extents ``h_o`` (O, 3). With the exact box signed distance

    sdf_o(x) = ||max(|x - c_o| - h_o, 0)||_2 + min(max_i (|x - c_o| - h_o)_i, 0)

(negative inside: minus the depth to the nearest face), a configuration costs

    Phi(q) = sum_s sum_o h(sdf_o(x_s(q)) - r_s)                               (m)

    h(D) = -D + eps / 2               D < 0          (penetration: linear, slope -1)
         = (eps - D)^2 / (2 eps)      0 <= D <= eps  (inside the margin: quadratic)
         = 0                          D > eps

the obstacle cost of CHOMP (Ratliff, Zucker, Bagnell, Srinivasa, ICRA 2009), continuously
differentiable, exactly zero with more than ``eps`` clearance, and with a bounded gradient
however deep a sphere is. Every vertex of the collision meshes lies within 2 cm of a sphere
(1.7 cm at most at q_home; tests/motion/test_spheres.py), so with ``eps`` of 2 cm Phi is > 0
about when the meshes come within reach of a box. A held block is not modelled.

`box_contacts` splits Phi by box, Phi_o(q) = sum_s h(sdf_o(x_s(q)) - r_s) (so Phi = sum_o Phi_o),
and gives the deepest penetration max_s (r_s - sdf_o(x_s(q))) (0 when clear) of each box, for
boxes shared by all configurations (O, 3) or one set per configuration (B, O, 3).
"""

from __future__ import annotations

from typing import NamedTuple

import torch

from motion.errors import MotionError
from motion.ik import IKSolver
from robots.panda import PANDA
from robots.panda_spheres import FINGER_ORIGIN, FINGERS, SPHERES

_HAND = "panda_hand"
_FRAMES = tuple(dict.fromkeys(_HAND if link in FINGERS else link for link, _, _ in SPHERES))
_INDEX = torch.tensor(
    [_FRAMES.index(_HAND if link in FINGERS else link) for link, _, _ in SPHERES]
)  # (G,) frame of each sphere
# (G, 3) centres in their frame; a finger's centre moves to panda_hand's frame, fingers closed
_LOCAL = torch.tensor(
    [(a[0], a[1], a[2] + FINGER_ORIGIN) if link in FINGERS else a for link, a, _ in SPHERES],
    dtype=torch.float64,
)
_SLIDE = torch.tensor(
    [(0.0, {FINGERS[0]: 1.0, FINGERS[1]: -1.0}.get(link, 0.0), 0.0) for link, _, _ in SPHERES],
    dtype=torch.float64,
)  # (G, 3): how a centre moves per m of finger opening
RADII = torch.tensor([r for _, _, r in SPHERES], dtype=torch.float64)  # (G,) m


def _tensor(x, shape: tuple[int | None, ...], name: str) -> torch.Tensor:
    """``x`` as a finite float64 tensor of ``shape`` (None: any size; keeps the autograd graph)."""
    t = torch.as_tensor(x).to(torch.float64)
    if t.ndim != len(shape) or any(w not in (None, s) for w, s in zip(shape, t.shape, strict=True)):
        want = ", ".join("*" if w is None else str(w) for w in shape)
        raise MotionError(f"{name} has shape {tuple(t.shape)}; expected ({want})")
    if not torch.isfinite(t).all():
        raise MotionError(f"{name} contains NaN or inf")
    return t


def boxes(centres, half) -> tuple[torch.Tensor, torch.Tensor]:
    """Checked obstacle boxes: centres (O, 3) and half extents (O, 3) > 0, float64, base frame."""
    c = _tensor(centres, (None, 3), "box centres")
    h = _tensor(half, (c.shape[0], 3), "box half extents")
    if (h <= 0).any():
        raise MotionError("box half extents must be > 0 m")
    return c, h


def sphere_positions(solver: IKSolver, q: torch.Tensor, finger: float = PANDA.finger_open):
    """World centres (B, G, 3) of the sphere model at q (B, J), differentiable in q.

    ``finger`` is the opening per finger in m (0.04: open, as cuRobo locks it). The radii are
    `RADII` (G,), in the row order of `robots.panda_spheres.SPHERES`.
    """
    q = _tensor(q, (None, solver.dof), "q")
    frames = solver.chain.forward_kinematics(q, end_only=False)  # name -> Transform3d
    missing = [n for n in _FRAMES if n not in frames]
    if missing:
        raise MotionError(f"the IK chain lacks frames {missing}; it has {sorted(frames)}")
    t = torch.stack([frames[n].get_matrix() for n in _FRAMES], dim=1)  # (B, F, 4, 4)
    t = t[:, _INDEX]  # (B, G, 4, 4)
    local = _LOCAL + float(finger) * _SLIDE  # (G, 3)
    return (t[..., :3, :3] @ local[:, :, None])[..., 0] + t[..., :3, 3]  # (B, G, 3)


def box_sdf(points: torch.Tensor, centres: torch.Tensor, half: torch.Tensor) -> torch.Tensor:
    """Exact signed distances (..., O) of points (..., 3) to boxes (O, 3), (O, 3); see above.

    Differentiable except on the measure-zero sets where two faces tie; inside a box the
    outside part's norm is of a zero vector, whose gradient torch takes as 0 (not NaN).
    """
    return _sdf(points[..., None, :], centres, half)  # (..., O)


def _sdf(points: torch.Tensor, centres: torch.Tensor, half: torch.Tensor) -> torch.Tensor:
    """sdf of broadcast points (..., 3), centres (..., 3), half extents (..., 3) -> (...)."""
    d = (points - centres).abs() - half  # (..., 3)
    return torch.linalg.vector_norm(d.clamp(min=0.0), dim=-1) + d.amax(-1).clamp(max=0.0)


def chomp_potential(dist: torch.Tensor, margin: float) -> torch.Tensor:
    """The CHOMP obstacle cost h(D) of signed clearances ``dist`` (any shape), eps = margin."""
    if not margin > 0:
        raise MotionError(f"margin must be > 0 m, got {margin}")
    quad = (margin - dist).clamp(min=0.0).square() / (2.0 * margin)
    return torch.where(dist < 0, margin / 2.0 - dist, quad)


class Contacts(NamedTuple):
    """The sphere model at B configurations against O boxes, box by box."""

    cost: torch.Tensor  # (B, O) m: sum_s h(sdf_o(x_s(q)) - r_s), Phi split by box
    depth: torch.Tensor  # (B, O) m, detached: max_s (r_s - sdf_o(x_s(q))), 0 when clear


def _pairs(solver, q, centres, half, margin: float, finger: float):
    """Flat indices (M,) into B * O and the CHOMP cost (M,) of the M (configuration, box) pairs
    with a sphere closer than ``margin``, and the detached depth (B, O); ``centres`` and
    ``half`` are (O, 3), or (B, O, 3) for boxes of each configuration's own."""
    x = sphere_positions(solver, q, finger)  # (B, G, 3)
    c, h = _batched_boxes(centres, half, x.shape[0])  # (B, O, 3) each
    o_count = c.shape[1]
    with torch.no_grad():
        gap = _sdf(x[:, :, None], c[:, None], h[:, None]) - RADII[:, None]  # (B, G, O)
        near = gap < margin
        depth = (-gap).amax(1).clamp(min=0.0)  # (B, O)
    b, s, o = near.nonzero(as_tuple=True)  # (M,) each: the M pairs that cost
    clearance = _sdf(x[b, s], c[b, o], h[b, o]) - RADII[s]  # (M,)
    return b, b * o_count + o, chomp_potential(clearance, margin), depth


def _batched_boxes(centres, half, n: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Checked boxes as (B, O, 3) each from (O, 3) (shared) or (B, O, 3) (one set per row)."""
    c = torch.as_tensor(centres)
    if c.ndim != 3:
        return tuple(t.expand(n, -1, -1) for t in boxes(centres, half))
    c = _tensor(c, (n, None, 3), "box centres")
    h = _tensor(half, tuple(c.shape), "box half extents")
    if (h <= 0).any():
        raise MotionError("box half extents must be > 0 m")
    return c, h


def collision_cost(
    solver: IKSolver,
    q: torch.Tensor,
    centres: torch.Tensor,
    half: torch.Tensor,
    margin: float = 0.02,
    finger: float = PANDA.finger_open,
) -> torch.Tensor:
    """Phi(q) (B,) in m for q (B, J) against boxes centres (O, 3), half (O, 3); see above.

    All (sphere, box) pairs are measured without a graph; only the pairs closer than the margin
    (h > 0) are measured again with one, so the gradient costs little and is still exact.
    The boxes may also be (B, O, 3) each: row b of q against its own O boxes.
    """
    b, _, phi, depth = _pairs(solver, q, centres, half, margin, finger)
    return torch.zeros(depth.shape[0], dtype=phi.dtype).index_add(0, b, phi)  # (B,)


def box_contacts(
    solver: IKSolver,
    q: torch.Tensor,
    centres: torch.Tensor,
    half: torch.Tensor,
    margin: float = 0.02,
    finger: float = PANDA.finger_open,
) -> Contacts:
    """`collision_cost` box by box: Phi_o(q) (B, O), with sum_o Phi_o(q) = Phi(q), and the
    deepest sphere's penetration into each box (B, O), one forward kinematics for both.

    Boxes (O, 3) each, or (B, O, 3) each for one set per configuration (e.g. per problem).
    """
    _, flat, phi, depth = _pairs(solver, q, centres, half, margin, finger)
    cost = torch.zeros(depth.numel(), dtype=phi.dtype).index_add(0, flat, phi)  # (B * O,)
    return Contacts(cost.reshape(depth.shape), depth)  # (B, O) each
