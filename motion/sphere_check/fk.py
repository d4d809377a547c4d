"""Batched forward kinematics of the Panda's sphere model, for `motion.sphere_check`.

The URDF's joint origins (parsed once by `chain`, revolute joints as quarter-turn rotations and
offsets), the link frames `PARTS` in the order `SphereCollision` uses, the spheres of
`robots.panda_spheres` (cuRobo's SPHERES plus the COVER rows) per link in its own frame
(`link_spheres`), and `links`: the world frames of every link and the TCP for B configurations at
once (float32, `FLOAT`; `frames` batch-last, `batch_first` to gather them by configuration).
The model's fixed bounding volumes and the checks' distance tests are `motion.sphere_check.bounds`.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence

import numpy as np

from motion.errors import MotionError
from robots.panda import PandaSpec, urdf_path
from robots.panda_spheres import COVER, FINGER_ORIGIN, FINGERS, SPHERES

_ARM = tuple(f"panda_link{i}" for i in range(1, 8))
_HAND = "panda_hand"
PARTS = ("panda_link0", *_ARM, _HAND, *FINGERS)  # (L,) the links, as PandaCollision.parts
FLOAT = np.float32  # the checks' precision: 0.1 um at 1 m, against the 1.5 cm cover gap


def onehot(rows: np.ndarray) -> np.ndarray:
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


def chain(spec: PandaSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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


def link_spheres():
    """Per link: sphere centres (S_l, 3) in its frame and radii (S_l,), fingers in their own."""
    rows = (*SPHERES, *COVER)
    out = {}
    for link in PARTS:
        centres = np.array([a for name, a, _ in rows if name == link], dtype=float)
        radii = np.array([r for name, _, r in rows if name == link], dtype=float)
        out[link] = (centres.reshape(-1, 3), radii)
    return out


def links(
    q: np.ndarray, fingers: float, off, swaps, hand_t, tcp_t
) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (B, L + 1, 3, 3) and origins (B, L + 1, 3) of the frames of
    `PARTS` (fingers at ``fingers`` m each), then of the TCP, from `chain`'s offsets ``off``
    (J, 3), the joint origins' axis ``swaps`` and the hand and TCP transforms (4, 4).

    Computed batch-last (`frames`), then transposed once."""
    rot, pos = frames(q, fingers, off, swaps, hand_t, tcp_t)
    return batch_first(rot, pos)


def batch_first(rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`frames`' (F, 3, 3, B) and (F, 3, B) as contiguous (B, F, 3, 3) and (B, F, 3): the
    checks gather frames by configuration."""
    return np.ascontiguousarray(rot.transpose(3, 0, 1, 2)), np.ascontiguousarray(
        pos.transpose(2, 0, 1)
    )


def frames(
    q: np.ndarray, fingers: float, off, swaps, hand_t, tcp_t
) -> tuple[np.ndarray, np.ndarray]:
    """`links`' frames batch-last: rotations (F, 3, 3, B) and origins (F, 3, B), F = L + 1,
    every quantity a contiguous row of B numbers."""
    n = q.shape[0]
    rot = np.empty((len(PARTS) + 1, 3, 3, n), dtype=FLOAT)  # (F, 3, 3, B)
    pos = np.empty((len(PARTS) + 1, 3, n), dtype=FLOAT)  # (F, 3, B)
    qt = np.ascontiguousarray(q.T, dtype=FLOAT)  # (J, B)
    c, s = np.cos(qt), np.sin(qt)  # (J, B) each
    rot[0], pos[0] = np.eye(3, dtype=FLOAT)[..., None], 0.0  # panda_link0 is the base frame
    cols = [np.repeat(np.eye(3, dtype=FLOAT)[:, a, None], n, 1) for a in range(3)]  # (3, B)
    t = np.zeros((3, n), FLOAT)
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
