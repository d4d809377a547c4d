"""Differentiable motion cost of every candidate block move, for joint task-motion optimisation.

A task planner that moves block ``x`` onto target ``y`` can add the arm's effort to its
objective. For picks ``p_x`` (block centres now) and places ``u_y`` (where a block's centre goes
when placed onto ``y``), with top-down TCP targets ``T(.)`` and IK solutions ``q(.)``:

    c(x, y) = joint_weight * ||q(u_y) - q(p_x)||_2                      (rad, over the J joints)
            + reach_weight * (r(p_x) + r(u_y))                          (m, IK position residual)
            + infeasible * ([IK of p_x failed] + [IK of u_y failed])    (constant, no gradient)

    r(t) = ||FK(q(t))[:3, 3] - t||_2

With obstacle boxes and ``collision_weight > 0`` the move also pays for the arm's clearance along
the straight joint segment from the grasp to the release configuration, S points, ends included:

            + collision_weight * (1/S) sum_{k=0}^{S-1} Phi(q(p_x) + k/(S-1) (q(u_y) - q(p_x)))

with Phi the CHOMP cost of the sphere model against the boxes (`motion.spheres`, in m: summed
over spheres and boxes, linear in penetration depth, zero beyond ``collision_margin``).

All ``N + Y`` targets are solved in one batched, detached `IKSolver.solve` call; the solutions
then pass through one differentiable Gauss-Newton step (`motion.ik.ik_refine`), so the cost is
differentiable in the picks and places with ``d q / d t = pinv(J)`` at the detached solution.
The gradient is that of the refined cost with the detached solution held fixed: where the IK
solver switches branch under a perturbation of a target the cost itself jumps. A target whose
IK failed skips the refinement (the pinv step near the stretched-arm singularity is unbounded)
and keeps its best attempt q*, so r(t) = ||FK(q*) - t|| still pulls it toward the workspace.

It is an approximation of a `motion.pick_place` move: only the transit from the grasp
configuration to the release configuration counts (approach, descend, lift, lower and retreat
are ignored), the hand yaw is 0 everywhere (a cube's yaw barely changes the joint distance),
the release gap is ignored, and the straight joint segment stands in for the timed trajectory.
That segment runs from block to block at table height, where the real move lifts first: the
collision term prices a low sweep (the sphere model has open fingers and no held block).

With ``blocks`` (the problems' blocks as axis-aligned boxes) and ``block_weight > 0`` the move
also pays for the arm's clearance to the other blocks at its two ends only, Phi_b being the part
of Phi due to block b (`motion.spheres.box_contacts`):

            + block_weight * (sum_{b not in {x, under(x)}} Phi_b(q(p_x))
                              + sum_{b not in {x, y}} Phi_b(q(u_y)))

(a table target y stands for no block). At the grasp the fingers straddle x and come within
the margin of the block under it; at the release x is in the hand and y under it. The segment
between the ends is not priced against blocks: at table height it would cross towers the real
move lifts over. The fingers are open at both ends: the hand comes down open to the grasp and
opens at the release before it retreats (`motion.pick_place`). `block_term` also gives the
deepest penetration into a counted block at either end, for a caller that rules moves out.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import torch

from motion.errors import MotionError
from motion.ik import IKSolver, ik_refine
from motion.spheres import box_contacts, boxes, collision_cost

_TOP_DOWN = ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, -1.0))  # Rz(0) Rx(pi)


@dataclass(frozen=True)
class MoveCostConfig:
    """Weights of the move cost (see the module docstring for the equation)."""

    joint_weight: float = 1.0  # cost per rad of L2 joint distance, grasp -> release configuration
    reach_weight: float = 10.0  # cost per m of IK position residual at the pick or the place
    infeasible: float = 10.0  # added per pick or place whose IK does not converge (no gradient)
    collision_weight: float = 0.0  # cost per m of Phi, the sphere model's obstacle cost (0: off)
    collision_margin: float = 0.02  # m, eps of Phi: the clearance below which a sphere costs
    collision_points: int = 5  # S configurations along the grasp -> release segment, ends included
    block_weight: float = 0.0  # cost per m of Phi against the blocks at the two ends (0: off)


class Blocks(NamedTuple):
    """The N blocks of P problems as axis-aligned boxes, for the block term (module docstring).

    Block x of problem p is the one picked at ``picks[p, x]``; a target y < N is that block.
    """

    centres: torch.Tensor  # (P, N, 3) m
    half: torch.Tensor  # (P, N, 3) m, half extents (a turned block: its bounding box's)
    under: torch.Tensor  # (P, N) long: the block x stands on, -1 on the table


class Bodies(NamedTuple):
    """What the arm's configurations are priced against besides reach (`move_costs_batch`):
    ``obstacles``, (centres (O, 3), half extents (O, 3)) of axis-aligned boxes in the base
    frame, and the problems' ``blocks``; None: not priced."""

    obstacles: tuple | None = None
    blocks: Blocks | None = None


NO_BODIES = Bodies()  # reach and joint distance alone


def top_down_targets(xyz: torch.Tensor) -> torch.Tensor:
    """Top-down TCP poses (..., 4, 4) at ``xyz`` (..., 3), yaw 0, differentiable in ``xyz``.

    The rotation is that of `motion.ik.top_down_pose` with yaw 0: R = Rx(pi) = diag(1, -1, -1).
    """
    if xyz.ndim < 1 or xyz.shape[-1] != 3:
        raise MotionError(f"xyz has shape {tuple(xyz.shape)}; expected (..., 3)")
    lead = xyz.shape[:-1]
    rot = torch.tensor(_TOP_DOWN, dtype=xyz.dtype, device=xyz.device).expand(*lead, 3, 3)
    top = torch.cat([rot, xyz[..., :, None]], dim=-1)  # (..., 3, 4)
    last = torch.tensor((0.0, 0.0, 0.0, 1.0), dtype=xyz.dtype, device=xyz.device)
    return torch.cat([top, last.expand(*lead, 1, 4)], dim=-2)  # (..., 4, 4)


def _points(x, ndim: int, name: str) -> torch.Tensor:
    """``x`` as a finite float64 tensor of ``ndim`` axes ending in 3 (keeps the autograd graph)."""
    t = torch.as_tensor(x).to(torch.float64)
    if t.ndim != ndim or t.shape[-1] != 3:
        want = "(P, N, 3)" if ndim == 3 else "(N, 3)"
        raise MotionError(f"{name} has shape {tuple(t.shape)}; expected {want}")
    if not torch.isfinite(t).all():
        raise MotionError(f"{name} contains NaN or inf")
    return t


def move_costs_batch(
    solver: IKSolver,
    q_ref,
    picks: torch.Tensor,
    places: torch.Tensor,
    config: MoveCostConfig = MoveCostConfig(),
    bodies: Bodies = NO_BODIES,
    solved: tuple[torch.Tensor, torch.Tensor] | None = None,
) -> torch.Tensor:
    """Costs (P, N, Y) float64 of P problems at once: picks (P, N, 3), places (P, Y, 3).

    One batched IK call covers all ``P * (N + Y)`` targets, seeded from ``q_ref`` (J,) plus the
    solver's own seeds; see `move_costs` for one problem and the module docstring for c(x, y).
    ``bodies.obstacles`` is (centres (O, 3), half extents (O, 3)) of axis-aligned boxes in the
    base frame, priced when ``config.collision_weight > 0``; None or O = 0 adds nothing.
    ``solved``: the detached solutions of targets near these (`site_solutions`), reused instead
    of solving (an optimiser moving the places a little calls this at every step).
    ``bodies.blocks``: the problems' blocks, priced at the grasp and release configurations
    when ``config.block_weight > 0`` (`block_term`).
    """
    obstacles, blocks = bodies
    picks = _points(picks, 3, "picks")  # (P, N, 3)
    places = _points(places, 3, "places")  # (P, Y, 3)
    if picks.shape[0] != places.shape[0]:
        raise MotionError(
            f"picks has {picks.shape[0]} problems and places {places.shape[0]}; expected equal"
        )
    p, n, y = picks.shape[0], picks.shape[1], places.shape[1]
    if p * (n + y) == 0:
        return torch.zeros((p, n, y), dtype=torch.float64)
    xyz = torch.cat([picks, places], dim=1).reshape(-1, 3)  # (P * (N + Y), 3)
    targets = top_down_targets(xyz)  # (B, 4, 4), B = P * (N + Y)
    q_star, ok = solved if solved is not None else site_solutions(solver, q_ref, picks, places)
    # A failed row keeps its best attempt: the arm is stretched near a singularity there, where
    # the pinv step is unbounded; its residual still pulls the target back toward the workspace.
    q = torch.where(ok[:, None], ik_refine(solver, q_star, targets), q_star)  # (B, J)
    reached = solver.fk_tensor(q)[:, :3, 3]  # (B, 3)
    residual = torch.linalg.vector_norm(reached - xyz, dim=-1)  # (B,)
    failed = (~ok).to(torch.float64)  # (B,)
    site = config.reach_weight * residual + config.infeasible * failed  # (B,)
    site = site.reshape(p, n + y)  # (P, N + Y)
    q = q.reshape(p, n + y, -1)  # (P, N + Y, J)
    q_pick, q_place = q[:, :n], q[:, n:]  # (P, N, J), (P, Y, J)
    dist = torch.linalg.vector_norm(q_place[:, None] - q_pick[:, :, None], dim=-1)  # (P, N, Y)
    cost = config.joint_weight * dist + site[:, :n, None] + site[:, None, n:]  # (P, N, Y)
    if config.collision_weight != 0.0 and obstacles is not None:
        centres, half = boxes(*obstacles)
        if centres.shape[0] > 0:
            cost = cost + config.collision_weight * _sweep(solver, q, n, centres, half, config)
    if config.block_weight != 0.0 and blocks is not None:
        if torch.as_tensor(blocks.centres).shape[1:2] != (n,):
            raise MotionError(
                f"blocks have centres {tuple(blocks.centres.shape)}; expected "
                f"({p}, {n}, 3), one per pick"
            )
        term = block_term(solver, q, blocks, config.collision_margin)
        cost = cost + config.block_weight * term.cost
    return cost


def _sweep(solver, q, n: int, centres, half, config: MoveCostConfig) -> torch.Tensor:
    """(P, N, Y) mean of Phi over the S points of each grasp -> release joint segment.

    ``q`` (P, N + Y, J) holds the grasp then the release configurations; the ends are priced
    once per site, the S - 2 inner points once per move, all in one batched call.
    """
    n_s = config.collision_points
    if n_s < 2:
        raise MotionError(f"collision_points is {n_s}; expected >= 2 (the segment's two ends)")
    p, y, j = q.shape[0], q.shape[1] - n, q.shape[2]
    q_pick, q_place = q[:, :n, None, None], q[:, None, n:, None]  # (P, N, 1, 1, J), (P, 1, Y, 1, J)
    t = torch.linspace(0.0, 1.0, n_s, dtype=q.dtype)[1:-1, None]  # (S - 2, 1)
    inner = q_pick + t * (q_place - q_pick)  # (P, N, Y, S - 2, J)
    qs = torch.cat([q.reshape(-1, j), inner.reshape(-1, j)])  # (P (N + Y) + P N Y (S - 2), J)
    m = config.collision_margin
    phi = collision_cost(solver, qs, centres, half, m)  # (P (N + Y) + P N Y (S - 2),)
    ends = phi[: p * (n + y)].reshape(p, n + y)  # (P, N + Y)
    mid = phi[p * (n + y) :].reshape(p, n, y, n_s - 2).sum(-1)  # (P, N, Y)
    return (ends[:, :n, None] + ends[:, None, n:] + mid) / n_s  # (P, N, Y)


class BlockTerm(NamedTuple):
    """The block term of every move x -> y (see the module docstring)."""

    cost: torch.Tensor  # (P, N, Y) m: Phi against the counted blocks, grasp plus release end
    depth: torch.Tensor  # (P, N, Y) m, detached: the deepest penetration into a counted block


def block_term(
    solver: IKSolver, q: torch.Tensor, blocks: Blocks, margin: float = 0.02
) -> BlockTerm:
    """`BlockTerm` of the grasp configurations ``q[:, :N]`` and the release configurations
    ``q[:, N:]`` (q: (P, N + Y, J)) against ``blocks``, fingers open at both ends.

    One `motion.spheres.box_contacts` call over the P (N + Y) configurations, each against its
    own problem's N boxes; the sums over the counted blocks are masked (P, N, Y, N) sums.
    """
    c, h = (torch.as_tensor(t, dtype=torch.float64) for t in blocks[:2])
    under, (p, sites, j) = torch.as_tensor(blocks.under), q.shape
    n = c.shape[1] if c.ndim == 3 else -1
    if tuple(c.shape) != (p, n, 3) or tuple(h.shape) != (p, n, 3) or n > sites:
        raise MotionError(
            f"blocks have centres {tuple(c.shape)}, half extents {tuple(h.shape)}"
            f"; expected (P, N, 3) each, P = {p}, N <= {sites}"
        )
    if tuple(under.shape) != (p, n) or not ((under >= -1) & (under < n)).all():
        raise MotionError(f"blocks.under must be (P, N) = {(p, n)} indices in -1..{n - 1}")
    y = sites - n
    if n == 0:
        zero = torch.zeros((p, 0, y), dtype=torch.float64)
        return BlockTerm(zero, zero)
    expand = (p, sites, n, 3)
    found = box_contacts(
        solver,
        q.reshape(-1, j),
        c[:, None].expand(expand).reshape(-1, n, 3),
        h[:, None].expand(expand).reshape(-1, n, 3),
        margin,
    )
    cost, depth = (t.reshape(p, sites, n) for t in found)  # (P, N + Y, N): site by block
    eye = torch.eye(n, dtype=torch.bool)  # (N, N): x == b
    b = torch.arange(n)
    keep_pick = ~eye & (under[:, :, None] != b)  # (P, N, N): neither x nor the block under x
    keep_place = ~eye[:, None] & (torch.arange(y)[:, None] != b)  # (N, Y, N): neither x nor y
    pick_cost = torch.where(keep_pick, cost[:, :n], 0.0).sum(-1)  # (P, N)
    place_cost = torch.where(keep_place, cost[:, None, n:], 0.0).sum(-1)  # (P, N, Y)
    pick_depth = torch.where(keep_pick, depth[:, :n], 0.0).amax(-1)  # (P, N)
    place_depth = torch.where(keep_place, depth[:, None, n:], 0.0).amax(-1)  # (P, N, Y)
    return BlockTerm(
        pick_cost[:, :, None] + place_cost, torch.maximum(pick_depth[:, :, None], place_depth)
    )


def block_depths(solver: IKSolver, solved, blocks: Blocks) -> torch.Tensor:
    """(P, N, Y) `BlockTerm.depth` at the detached solutions ``solved`` (`site_solutions`),
    0 for a move whose grasp or release IK failed (the arm never takes that configuration)."""
    q_star, ok = solved
    p, n = blocks.centres.shape[:2]
    with torch.no_grad():
        depth = block_term(solver, q_star.reshape(p, -1, q_star.shape[-1]), blocks).depth
    ok = ok.reshape(p, -1)  # (P, N + Y)
    return torch.where(ok[:, :n, None] & ok[:, None, n:], depth, 0.0)  # (P, N, Y)


def site_solutions(
    solver: IKSolver, q_ref, picks: torch.Tensor, places: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """Detached IK solutions q* (P * (N + Y), J) and their success flags (P * (N + Y),) of the
    top-down grasps at picks (P, N, 3) then places (P, Y, 3), one batched call."""
    xyz = torch.cat([_points(picks, 3, "picks"), _points(places, 3, "places")], dim=1)
    targets = top_down_targets(xyz.detach().reshape(-1, 3))  # (B, 4, 4)
    found = solver.solve(targets.numpy(), np.asarray(q_ref, dtype=np.float64))
    return torch.from_numpy(np.array(found.q)), torch.from_numpy(np.array(found.ok))


def move_costs(
    solver: IKSolver,
    q_ref,
    picks: torch.Tensor,
    places: torch.Tensor,
    config: MoveCostConfig = MoveCostConfig(),
    obstacles: tuple | None = None,
) -> torch.Tensor:
    """Costs (N, Y) float64 of moving the block at picks[x] so that its centre ends at places[y].

    ``picks`` (N, 3) are block centres now; ``places`` (Y, 3) are where a block's centre goes
    when placed onto target y (the caller computes them: on a block, its centre + block_size up;
    on the table, a free spot). ``q_ref`` (J,) seeds the IK. Differentiable w.r.t. picks and
    places through `motion.ik.ik_refine`:

        c(x, y) = joint_weight * ||q(place_y) - q(pick_x)||
                + reach_weight * (r(pick_x) + r(place_y)) + infeasible * (not converged)
                + collision_weight * mean_k Phi(q_k)    (boxes ``obstacles``, see move_costs_batch)
    """
    picks = _points(picks, 2, "picks")  # (N, 3)
    places = _points(places, 2, "places")  # (Y, 3)
    c = move_costs_batch(solver, q_ref, picks[None], places[None], config, Bodies(obstacles))
    return c[0]  # (N, Y)
