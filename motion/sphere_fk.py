"""Batched forward kinematics of the Panda's sphere model, for `motion.sphere_check`.

The URDF's joint origins (parsed once by `_chain`, revolute joints as quarter-turn rotations and
offsets), the link frames `PARTS` in the order `SphereCollision` uses, and the spheres of
`robots.panda_spheres` (cuRobo's SPHERES plus the COVER rows) per link in its own frame, and
`_links`: the world frames of every link and the TCP for B configurations at once (float32;
`_frames` batch-last); the model's fixed geometry: bounding spheres (`_bound`), each link's
26-DOP (`_dops`), its spheres in clusters (`_clusters`), turns about z (`_turn`); and the
checks' distance tests: the separating-axis test of two boxes (`_obb_gap`), points against
turned boxes (`_box_gap`) and axis-aligned ones (`_box_sdf`, `_near_box`), and the 26-DOP's
bound (`_dop_gap`), the last four without BLAS (OpenBLAS spreads a large product over more
threads).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence

import numpy as np

from motion.errors import MotionError
from robots.panda import PandaSpec, data_dir, urdf_path
from robots.panda_spheres import COVER, FINGER_ORIGIN, FINGERS, SPHERES

_ARM = tuple(f"panda_link{i}" for i in range(1, 8))
_HAND = "panda_hand"
PARTS = ("panda_link0", *_ARM, _HAND, *FINGERS)  # (L,) the links, as PandaCollision.parts
_FLOAT = np.float32  # the checks' precision: 0.1 um at 1 m, against the 1.5 cm cover gap
SLACK = 1e-5  # m added to a culling test's reach (`_near_box`): far above float32 rounding


def _onehot(rows: np.ndarray) -> np.ndarray:
    """(3, 3) with a 1 in row rows[a] of each column a."""
    out = np.zeros((3, 3))
    out[rows, np.arange(3)] = 1.0
    return out


def _rpy(rpy: Sequence[float]) -> np.ndarray:
    """URDF roll-pitch-yaw as a rotation (3, 3): Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _chain(spec: PandaSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The joint origins of the URDF: revolute (J, 3, 3) rotations and (J, 3) offsets from link
    i-1 to link i (before the joint's turn about z), and panda_link7 -> panda_hand, and
    panda_hand -> TCP as (4, 4) transforms."""
    joints = {}
    for joint in ET.parse(urdf_path(spec)).getroot().iter("joint"):
        origin = joint.find("origin")
        xyz = [float(v) for v in origin.get("xyz", "0 0 0").split()]
        rpy = [float(v) for v in origin.get("rpy", "0 0 0").split()]
        child = joint.find("child").get("link")
        transform = np.eye(4)
        transform[:3, :3], transform[:3, 3] = _rpy(rpy), xyz
        joints[child] = (joint.find("parent").get("link"), transform, joint.get("type"))

    def path(frm: str, to: str) -> np.ndarray:
        out = np.eye(4)
        while to != frm:
            parent, transform, _ = joints[to]
            out, to = transform @ out, parent
        return out

    arm = [joints[link][1] for link in _ARM]
    if any(joints[link][2] != "revolute" for link in _ARM):
        raise MotionError(f"expected revolute joints into {_ARM} in {urdf_path(spec)}")
    rot = np.stack([t[:3, :3] for t in arm])  # (J, 3, 3)
    off = np.stack([t[:3, 3] for t in arm])  # (J, 3)
    return rot, off, path(_ARM[-1], _HAND), path(_HAND, spec.tcp_link)


def _link_spheres():
    """Per link: sphere centres (S_l, 3) in its frame and radii (S_l,), fingers in their own."""
    rows = (*SPHERES, *COVER)
    out = {}
    for link in PARTS:
        centres = np.array([a for name, a, _ in rows if name == link], dtype=float)
        radii = np.array([r for name, _, r in rows if name == link], dtype=float)
        out[link] = (centres.reshape(-1, 3), radii)
    return out


_MESHES = {f"panda_link{i}": f"link{i}.obj" for i in range(8)} | {
    _HAND: "hand.obj",
    FINGERS[0]: "finger.obj",
    FINGERS[1]: "finger.obj",
}


def _directions() -> np.ndarray:
    """The 26 unit directions of a 26-DOP (26, 3): faces, edges and corners of a cube."""
    grid = np.stack(np.meshgrid(*[(-1.0, 0.0, 1.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    grid = grid[np.abs(grid).sum(1) > 0]
    return grid / np.linalg.norm(grid, axis=1, keepdims=True)


def _dops() -> tuple[np.ndarray, np.ndarray]:
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


def _bound(centres: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, float]:
    """A sphere (centre (3,), radius) holding all the given spheres: around their box's middle."""
    mid = (np.min(centres - radii[:, None], 0) + np.max(centres + radii[:, None], 0)) / 2
    return mid, float((np.linalg.norm(centres - mid, axis=1) + radii).max())


def _clusters(spheres, size: int):
    """Each link's spheres (`_link_spheres`) in clusters of at most ``size`` along the link's
    longest direction: per cluster its link (C,), centres (C, size, 3) padded by repeating its
    first, radii (C, size), count (C,) and bounding sphere (`_bound`: (C, 3), (C,)); per link
    its first cluster (L,) and number of them (L,)."""
    link_of, local, radii, count, mids, reach = [], [], [], [], [], []
    first, parts = np.zeros(len(PARTS), dtype=int), np.zeros(len(PARTS), dtype=int)
    for link, name in enumerate(PARTS):
        centres, r = spheres[name]
        first[link], parts[link] = len(link_of), -(-len(r) // size)  # ceil
        spread = centres - centres.mean(0)
        axis = np.linalg.svd(spread, full_matrices=False)[2][0] if len(r) > 1 else np.eye(3)[0]
        for chunk in np.array_split(np.argsort(spread @ axis, kind="stable"), parts[link]):
            rows = np.where(np.arange(size) < chunk.size, np.arange(size), 0)
            mid, far = _bound(centres[chunk], r[chunk])
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


def _turn(yaw: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) about z by ``yaw`` (...)."""
    c, s = np.cos(yaw), np.sin(yaw)
    z, o = np.zeros_like(yaw), np.ones_like(yaw)
    return np.stack([c, -s, z, s, c, z, z, z, o], -1).reshape(*yaw.shape, 3, 3)


def _obb_gap(r_a, t_a, half_a, r_b, c_b, h_b) -> np.ndarray:
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


def _links(
    q: np.ndarray, fingers: float, off, swaps, hand_t, tcp_t
) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (B, L + 1, 3, 3) and origins (B, L + 1, 3) of the frames of
    `PARTS` (fingers at ``fingers`` m each), then of the TCP, from `_chain`'s offsets ``off``
    (J, 3), the joint origins' axis ``swaps`` and the hand and TCP transforms (4, 4).

    Computed batch-last (`_frames`), then transposed once."""
    rot, pos = _frames(q, fingers, off, swaps, hand_t, tcp_t)
    return _batch_first(rot, pos)


def _batch_first(rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`_frames`' (F, 3, 3, B) and (F, 3, B) as contiguous (B, F, 3, 3) and (B, F, 3): the
    checks gather frames by configuration."""
    return np.ascontiguousarray(rot.transpose(3, 0, 1, 2)), np.ascontiguousarray(
        pos.transpose(2, 0, 1)
    )


def _frames(
    q: np.ndarray, fingers: float, off, swaps, hand_t, tcp_t
) -> tuple[np.ndarray, np.ndarray]:
    """`_links`' frames batch-last: rotations (F, 3, 3, B) and origins (F, 3, B), F = L + 1,
    every quantity a contiguous row of B numbers."""
    n = q.shape[0]
    rot = np.empty((len(PARTS) + 1, 3, 3, n), dtype=_FLOAT)  # (F, 3, 3, B)
    pos = np.empty((len(PARTS) + 1, 3, n), dtype=_FLOAT)  # (F, 3, B)
    qt = np.ascontiguousarray(q.T, dtype=_FLOAT)  # (J, B)
    c, s = np.cos(qt), np.sin(qt)  # (J, B) each
    rot[0], pos[0] = np.eye(3, dtype=_FLOAT)[..., None], 0.0  # panda_link0 is the base frame
    cols = [np.repeat(np.eye(3, dtype=_FLOAT)[:, a, None], n, 1) for a in range(3)]  # (3, B)
    t = np.zeros((3, n), _FLOAT)
    for j in range(7):
        for axis, v in enumerate(off[j]):  # the joint's origin, in the parent frame
            if v:
                t = t + v * cols[axis]  # (3, B)
        # the origin's rotation is a signed permutation: it only reorders the axes
        cols = [cols[k] if sign > 0 else -cols[k] for k, sign in swaps[j]]
        x, y = cols[0], cols[1]
        cols = [x * c[j] + y * s[j], y * c[j] - x * s[j], cols[2]]  # the turn about z
        for axis in range(3):
            rot[j + 1, :, axis] = cols[axis]
        pos[j + 1] = t
    hand = len(_ARM) + 1
    _compose(rot[hand - 1], pos[hand - 1], hand_t, rot[hand], pos[hand])
    for k, sign in ((hand + 1, 1.0), (hand + 2, -1.0)):  # the fingers slide along hand y
        rot[k] = rot[hand]
        pos[k] = pos[hand] + (sign * fingers) * rot[hand, :, 1] + FINGER_ORIGIN * rot[hand, :, 2]
    _compose(rot[hand], pos[hand], tcp_t, rot[-1], pos[-1])
    return rot, pos


def _compose(r: np.ndarray, t: np.ndarray, transform: np.ndarray, r_out, t_out) -> None:
    """Frames r (3, 3, B), t (3, B) followed by a fixed (4, 4) ``transform``, into r_out, t_out
    (the transform's zero entries skipped)."""
    for a in range(4):
        out = t_out if a == 3 else r_out[:, a]  # (3, B)
        terms = [(k, float(transform[k, a])) for k in range(3) if transform[k, a] != 0]
        value = t.copy() if a == 3 else np.zeros_like(t)
        for k, w in terms:
            value += w * r[:, k] if w != 1.0 else r[:, k]
        out[:] = value


def _box_gap(d: np.ndarray, cos, sin, half, reach, exact: bool) -> np.ndarray:
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


def _box_sdf(points: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Signed distances (...) of points (..., 3) in a box's frame to it, half extents (..., 3)."""
    d = np.abs(points) - half
    outside = np.sqrt(np.square(np.maximum(d, 0.0)).sum(-1))
    return outside + np.minimum(d.max(-1), 0.0)


def _near_box(d: np.ndarray, half: np.ndarray, reach) -> np.ndarray:
    """(...) bool: whether points at offsets d (..., 3) from an axis-aligned box's centre, half
    extents ``half`` (..., 3), lie closer than ``reach`` (...) > 0 to it (inside counts):
    `_box_sdf` < reach, axis by axis and squared (no square root, no reduction over the
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


def _dop_gap(points: np.ndarray, directions: np.ndarray, support: np.ndarray) -> np.ndarray:
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
