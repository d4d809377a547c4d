"""The sphere model's fixed bounding volumes and the distance tests of its checks.

For `motion.sphere_check`, over the links of `motion.sphere_check.fk.PARTS`: bounding spheres
(`bound`), each link's 26-DOP from its collision mesh (`dops`), its spheres in clusters
(`clusters`), turns about z (`turn`); and the checks' distance tests: the separating-axis test
of two boxes (`obb_gap`), points against turned boxes (`box_gap`) and axis-aligned ones
(`box_sdf`, `near_box`), and the 26-DOP's bound (`dop_gap`), the last four without BLAS
(OpenBLAS spreads a large product over more threads).
"""

from __future__ import annotations

import numpy as np

from motion.sphere_check.fk import PARTS
from robots.panda import data_dir
from robots.panda_spheres import FINGERS

SLACK = 1e-5  # m added to a culling test's reach (`near_box`): far above float32 rounding

_MESHES = {f"panda_link{i}": f"link{i}.obj" for i in range(8)} | {
    "panda_hand": "hand.obj",
    FINGERS[0]: "finger.obj",
    FINGERS[1]: "finger.obj",
}


def _directions() -> np.ndarray:
    """The 26 unit directions of a 26-DOP (26, 3): faces, edges and corners of a cube."""
    grid = np.stack(np.meshgrid(*[(-1.0, 0.0, 1.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    grid = grid[np.abs(grid).sum(1) > 0]
    return grid / np.linalg.norm(grid, axis=1, keepdims=True)


def dops() -> tuple[np.ndarray, np.ndarray]:
    """Per link, the support offsets (L, 26) of its collision mesh's vertices along
    `_directions` (the 26-DOP holding its convex hull, in its frame; fingers in their own)."""
    directions = _directions()
    out = np.zeros((len(PARTS), len(directions)))
    for k, link in enumerate(PARTS):
        path = data_dir() / "franka_panda" / "meshes" / "collision" / _MESHES[link]
        rows = [line.split()[1:4] for line in path.read_text().splitlines() if line[:2] == "v "]
        v = np.array(rows, dtype=float)  # (V, 3)
        if link == FINGERS[1]:  # the URDF turns the right finger's mesh by pi about z
            v = v * np.array([-1.0, -1.0, 1.0])
        out[k] = (v @ directions.T).max(0)
    return directions, out


def bound(centres: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, float]:
    """A sphere (centre (3,), radius) holding all the given spheres: around their box's middle."""
    mid = (np.min(centres - radii[:, None], 0) + np.max(centres + radii[:, None], 0)) / 2
    return mid, float((np.linalg.norm(centres - mid, axis=1) + radii).max())


def clusters(spheres, size: int):
    """Each link's spheres (`motion.sphere_check.fk.link_spheres`) in clusters of at most ``size``
    along the link's longest direction: per cluster its link (C,), centres (C, size, 3) padded
    by repeating its first, radii (C, size), count (C,) and bounding sphere (`bound`: (C, 3),
    (C,)); per link its first cluster (L,) and number of them (L,)."""
    link_of, local, radii, count, mids, reach = [], [], [], [], [], []
    first, parts = np.zeros(len(PARTS), dtype=int), np.zeros(len(PARTS), dtype=int)
    for link, name in enumerate(PARTS):
        centres, r = spheres[name]
        first[link], parts[link] = len(link_of), -(-len(r) // size)  # ceil
        spread = centres - centres.mean(0)
        axis = np.linalg.svd(spread, full_matrices=False)[2][0] if len(r) > 1 else np.eye(3)[0]
        for chunk in np.array_split(np.argsort(spread @ axis, kind="stable"), parts[link]):
            rows = np.where(np.arange(size) < chunk.size, np.arange(size), 0)
            mid, far = bound(centres[chunk], r[chunk])
            link_of.append(link)
            local.append(centres[chunk][rows])
            radii.append(r[chunk][rows])
            count.append(chunk.size)
            mids.append(mid)
            reach.append(far)
    return (
        np.array(link_of),
        np.array(local),
        np.array(radii),
        np.array(count),
        np.array(mids),
        np.array(reach),
        first,
        parts,
    )


def turn(yaw: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) about z by ``yaw`` (...)."""
    c, s = np.cos(yaw), np.sin(yaw)
    z, o = np.zeros_like(yaw), np.ones_like(yaw)
    return np.stack([c, -s, z, s, c, z, z, z, o], -1).reshape(*yaw.shape, 3, 3)


def obb_gap(r_a, t_a, half_a, r_b, c_b, h_b) -> np.ndarray:
    """Separating-axis test of M pairs of boxes: A (rotations (M, 3, 3), centres (M, 3), half
    extents (3,)) against B (rotations (M, 3, 3), centres (M, 3), half extents (M, 3)); the
    largest separation (M,) over the 15 axes (< 0: the boxes overlap)."""
    a_axes, b_axes = np.swapaxes(r_a, 1, 2), np.swapaxes(r_b, 1, 2)  # (M, 3, 3): rows are axes
    cross = np.cross(a_axes[:, :, None], b_axes[:, None, :]).reshape(-1, 9, 3)  # (M, 9, 3)
    norm = np.linalg.norm(cross, axis=-1, keepdims=True)
    cross = np.where(norm > 1e-6, cross / np.maximum(norm, 1e-6), 0.0)
    axes = np.concatenate([a_axes, b_axes, cross], axis=1)  # (M, 15, 3)
    along = np.abs(np.einsum("mki,mi->mk", axes, c_b - t_a))  # (M, 15)
    rad_a = np.abs(np.einsum("mki,mji->mkj", axes, a_axes)) @ half_a  # (M, 15)
    rad_b = (np.abs(np.einsum("mki,mji->mkj", axes, b_axes)) * h_b[:, None]).sum(-1)
    sep = along - rad_a - rad_b  # (M, 15); a zero axis never separates
    sep = np.where(np.linalg.norm(axes, axis=-1) > 0.5, sep, -np.inf)
    return sep.max(-1)


def box_gap(d: np.ndarray, cos, sin, half, reach, exact: bool) -> np.ndarray:
    """Clearance of points at offsets d (..., 3) from the centres of boxes turned by yaws of
    cosine ``cos`` and sine ``sin`` (...) about z, half extents ``half`` (..., 3), less
    ``reach`` (...): < 0 where a ball of radius ``reach`` there meets the box. ``exact``: the
    signed distance less ``reach``; else only its sign is right (the squared distance outside
    the box less ``reach``^2, which skips the square root)."""
    u = np.abs(cos * d[..., 0] + sin * d[..., 1]) - half[..., 0]
    v = np.abs(cos * d[..., 1] - sin * d[..., 0]) - half[..., 1]
    w = np.abs(d[..., 2]) - half[..., 2]
    outside = np.square(np.maximum(u, 0.0))
    outside += np.square(np.maximum(v, 0.0))
    outside += np.square(np.maximum(w, 0.0))
    if not exact:
        return outside - np.square(reach)
    inside = np.minimum(np.maximum(np.maximum(u, v), w), 0.0)
    return np.sqrt(outside) + inside - reach


def box_sdf(points: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Signed distances (...) of points (..., 3) in a box's frame to it, half extents (..., 3)."""
    d = np.abs(points) - half
    outside = np.sqrt(np.square(np.maximum(d, 0.0)).sum(-1))
    return outside + np.minimum(d.max(-1), 0.0)


def near_box(d: np.ndarray, half: np.ndarray, reach) -> np.ndarray:
    """(...) bool: whether points at offsets d (..., 3) from an axis-aligned box's centre, half
    extents ``half`` (..., 3), lie closer than ``reach`` (...) > 0 to it (inside counts):
    `box_sdf` < reach, axis by axis and squared (no square root, no reduction over the
    short last axis). ``reach`` is widened by `SLACK`, so float rounding never drops a point
    the exact test keeps (this only decides what a finer test sees)."""
    total = None
    for axis in range(3):
        e = np.abs(d[..., axis])  # (...)
        e -= half[..., axis]
        np.maximum(e, 0.0, out=e)
        e *= e
        total = e if total is None else np.add(total, e, out=total)
    limit = np.asarray(reach, dtype=total.dtype) + SLACK
    return total < limit * limit


def dop_gap(points: np.ndarray, directions: np.ndarray, support: np.ndarray) -> np.ndarray:
    """(K,) the 26-DOP bound max_k (d_k . p - support_k) of points p (K, 3) in their DOP's
    frame, supports (26, K): three products over rows of K, the directions (26, 3) down the
    side, in place (a fresh large array costs its page faults), not a matrix product, which
    OpenBLAS would spread over a second thread."""
    out = np.multiply(directions[:, 0, None], points[:, 0])  # (26, K)
    term = np.multiply(directions[:, 1, None], points[:, 1])  # (26, K)
    out += term
    out += np.multiply(directions[:, 2, None], points[:, 2], out=term)
    out -= support
    return out.max(0)
