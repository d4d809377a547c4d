"""Collision model of the Panda against boxes, to check joint paths before they run.

The arm's geometry is the pybullet_data Panda URDF's collision meshes (one convex hull per link),
loaded by `robots.pybullet_loader.load_panda` into a private ``p.DIRECT`` client and queried with
PyBullet's ``getClosestPoints``; nothing is stepped. World frame = robot base frame; the table is
a 6 m slab with its top at z = 0 (link0 stands on it: that pair is always ignored). Boxes come
from `PandaCollision.set_boxes`; a held box (`PandaCollision.hold`) rides in the hand, at the
TCP or at a grasp's pose relative to it. A contact counts when the closest distance is below
``margin`` (robot or held box vs the scene, held box vs arm) or below ``self_margin`` (link vs
link; default 0 as in MoveIt, so a larger scene margin never makes q_home self-colliding). Only
pairs whose AABBs come within the threshold reach the narrow phase.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np
import pybullet as p

from robots.errors import RobotError
from robots.panda import PANDA, PandaSpec
from robots.pybullet_loader import load_panda

TABLE = "table"
HELD = "held"
HAND = ("panda_hand", "panda_leftfinger", "panda_rightfinger")

# Link pairs never checked for self-collision, derived the way MoveIt's setup assistant does it
# (tests/robots/test_collision.py::test_disabled_pairs_match_their_derivation recomputes them):
# adjacent links (panda_link8 has no geometry, so link7-hand are adjacent), pairs penetrating in
# >= 99 % of 1000 configurations drawn uniformly within the datasheet limits (seed 0, fingers
# uniform in [0, 0.04] m: exactly the adjacent pairs), and pairs penetrating at q_home with the
# fingers open or closed (the two fingers, which touch when closed).
DISABLED_PAIRS = frozenset(
    map(
        frozenset,
        (
            ("panda_link0", "panda_link1"),
            ("panda_link1", "panda_link2"),
            ("panda_link2", "panda_link3"),
            ("panda_link3", "panda_link4"),
            ("panda_link4", "panda_link5"),
            ("panda_link5", "panda_link6"),
            ("panda_link6", "panda_link7"),
            ("panda_link7", "panda_hand"),
            ("panda_hand", "panda_leftfinger"),
            ("panda_hand", "panda_rightfinger"),
            ("panda_leftfinger", "panda_rightfinger"),
        ),
    )
)
_TABLE_HALF = (3.0, 3.0, 0.5)  # m; its top face is z = 0
Ignore = Collection[tuple[str, str]]  # (part, other) pairs to skip


def densify(path: np.ndarray, fs: np.ndarray, max_step: float):
    """A joint path (S, J) and its finger openings (S,) densified so no joint moves more than
    ``max_step`` rad: the waypoint each point leads to (N,), the points (N, J), openings (N,)."""
    n = np.ceil(np.abs(np.diff(path, axis=0)).max(-1) / max_step - 1e-9)  # (S-1,)
    n = np.maximum(n, 1).astype(int)
    seg = np.concatenate([[0], np.repeat(np.arange(1, len(path)), n)])  # (N,) waypoint
    t = np.concatenate([[1.0], *(np.arange(1, k + 1) / k for k in n)])  # (N,)
    prev = np.maximum(seg - 1, 0)
    qs = path[prev] + t[:, None] * (path[seg] - path[prev])  # (N, J)
    f = fs[prev] + t * (fs[seg] - fs[prev])  # (N,)
    return seg, qs, f


@dataclass(frozen=True)
class Box:
    """A box in the world (a block or an obstacle), turned by ``yaw`` about world z."""

    name: str
    centre: tuple[float, float, float]
    half: tuple[float, float, float]  # half extents, m
    yaw: float = 0.0


@dataclass(frozen=True)
class Contact:
    """One predicted collision: a robot link or "held" against a box, "table" or a link."""

    part: str
    other: str
    distance: float  # m, signed (negative: penetration), as PyBullet's closest points say


@dataclass(frozen=True)
class PathCheck:
    """Result of `PandaCollision.check_path`; ``index`` is the first waypoint not reached safely."""

    ok: bool
    index: int | None  # collision on the segment (path[index-1], path[index]]; None when ok
    q: tuple[float, ...] | None  # the colliding (possibly interpolated) configuration
    contact: Contact | None  # the deepest contact there
    checked: int  # configurations checked after densifying
    failure: str = ""


def _finite(values, n: int, positive: bool = False) -> bool:
    try:
        v = [float(x) for x in values]
    except (TypeError, ValueError):
        return False
    return len(v) == n and all(math.isfinite(x) and (x > 0 or not positive) for x in v)


def _pose(pose) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """A (4, 4) rigid transform as PyBullet's (position (3,), quaternion (x, y, z, w))."""
    try:
        h = np.asarray(pose, dtype=float)
    except (TypeError, ValueError):
        h = np.full(1, np.nan)
    if h.shape != (4, 4) or not np.isfinite(h).all():
        raise RobotError(f"held pose must be a finite (4, 4) transform, got shape {h.shape}")
    r = h[:3, :3]
    if np.abs(r @ r.T - np.eye(3)).max() > 1e-6 or np.linalg.det(r) < 0:
        raise RobotError("held pose's rotation block is not a rotation (tolerance 1e-6)")
    # the quaternion from the largest of w, x, y, z (Shepperd), well conditioned everywhere
    t = np.trace(r)
    k = int(np.argmax([t, r[0, 0], r[1, 1], r[2, 2]]))
    if k == 0:
        w = math.sqrt(1.0 + t) / 2
        q = (
            (r[2, 1] - r[1, 2]) / (4 * w),
            (r[0, 2] - r[2, 0]) / (4 * w),
            (r[1, 0] - r[0, 1]) / (4 * w),
            w,
        )
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        v = [0.0, 0.0, 0.0]
        v[i] = math.sqrt(1.0 + r[i, i] - r[j, j] - r[m, m]) / 2
        v[j] = (r[j, i] + r[i, j]) / (4 * v[i])
        v[m] = (r[m, i] + r[i, m]) / (4 * v[i])
        q = (*v, (r[m, j] - r[j, m]) / (4 * v[i]))
    return tuple(float(x) for x in h[:3, 3]), tuple(float(x) for x in q)


class PandaCollision:
    """The Panda, its held cube and a set of boxes in a private PyBullet client.

    ``q`` is (J,) arm joint angles, ``fingers`` the opening per finger in m. ``ignore`` holds
    (part, other) pairs to skip: part is a link name, "held", "hand" (panda_hand and both
    fingers) or "robot" (every link, not the held cube); other a box name, "table" or a link.
    """

    def __init__(self, margin: float = 0.01, spec: PandaSpec = PANDA, self_margin: float = 0.0):
        if not (_finite([margin, self_margin], 2) and margin >= 0 and self_margin >= 0):
            raise RobotError(f"margins must be finite and >= 0, got {margin}, {self_margin}")
        self.margin, self.self_margin, self.spec = float(margin), float(self_margin), spec
        self._c: int | None = p.connect(p.DIRECT)
        try:
            robot = load_panda(self._c, spec)
        except Exception:
            self.close()
            raise
        c, body = self._c, robot.body
        self._body, self._tcp = body, robot.tcp
        self._joints = [*robot.arm, *robot.fingers]
        names = {-1: spec.base_link} | {
            i: p.getJointInfo(body, i, physicsClientId=c)[12].decode()
            for i in range(p.getNumJoints(body, physicsClientId=c))
        }
        self._links = [i for i in names if p.getCollisionShapeData(body, i, physicsClientId=c)]
        self.parts = (*(names[i] for i in self._links), HELD)  # (P,) = L links + the held cube
        self._index = {n: k for k, n in enumerate(self.parts)}
        self._groups = {n: [k] for n, k in self._index.items()} | {
            "robot": list(range(len(self._links))),
            "hand": [self._index[n] for n in HAND],
        }
        held, names = self._index[HELD], self.parts
        arm = [(a, b) for b in range(held) for a in range(b)]
        arm = [(a, b) for a, b in arm if frozenset((names[a], names[b])) not in DISABLED_PAIRS]
        cube = [(held, b) for b in range(held) if names[b] not in HAND]
        self._pairs = np.array(arm + cube)  # (K, 2); the second is always a link
        self._pair_thr = np.array([self.self_margin] * len(arm) + [self.margin] * len(cube))
        self._shapes: dict[tuple, int] = {}  # half extents -> shape; PyBullet can't free them
        self._half: dict[int, tuple] = {}  # body -> its half extents (reused by shape)
        table = self._new_box((0.0, 0.0, -_TABLE_HALF[2]), _TABLE_HALF, 0.0)
        self._others: list[tuple[str, int]] = [(TABLE, table)]  # (name, body)
        self._held: int | None = None  # body of the held box
        self._held_pose: tuple | None = None  # its (position, quaternion) in the TCP frame
        self._refresh()

    def set_boxes(self, boxes: Sequence[Box]) -> None:
        """Replace all boxes (blocks and obstacles). Names must be unique and not a part name."""
        seen, reserved = set(), {*self._groups, TABLE, ""}
        for box in boxes:
            name = getattr(box, "name", None)
            if not isinstance(name, str) or name in seen | reserved:
                raise RobotError(f"box name {name!r} is empty, repeated, 'table' or a robot part")
            ok = _finite(box.centre, 3) and _finite(box.half, 3, True) and _finite([box.yaw], 1)
            if not ok:
                raise RobotError(f"box {name!r}: centre (3,), half (3,) > 0 and yaw must be finite")
            seen.add(name)
        self._check_open()
        # the old bodies by shape, reused where a new box has the same half extents (moved,
        # not rebuilt: creating a body costs about 0.3 ms, moving one a few microseconds, and
        # a check sets its scene's boxes for every phase it tests)
        spare: dict[tuple, list[int]] = {}
        for _, body in self._others[1:]:
            spare.setdefault(self._half[body], []).append(body)
        others = []
        for b in boxes:
            half = tuple(float(h) for h in b.half)
            if spare.get(half):
                body = spare[half].pop()
                orn = p.getQuaternionFromEuler((0.0, 0.0, float(b.yaw)))
                centre = [float(v) for v in b.centre]
                p.resetBasePositionAndOrientation(body, centre, orn, physicsClientId=self._c)
            else:
                body = self._new_box(b.centre, half, b.yaw)
            others.append((b.name, body))
        for bodies in spare.values():
            for body in bodies:
                p.removeBody(body, physicsClientId=self._c)
                del self._half[body]
        self._others[1:] = others
        self._refresh()

    def hold(self, size: float | None = None, half=None, pose=None) -> None:
        """Hold a box in the hand; nothing when both ``size`` and ``half`` are None.

        ``size``: a cube's edge (m), or ``half``: the box's half extents (3,) m (not both).
        ``pose``: (4, 4) the box's pose in the TCP frame (e.g. the inverse of a
        `motion.grasps.Grasp` matrix); None: centred at the TCP and turned with the hand, as
        a top-down grasp holds a block. The held block's own `Box` should leave `set_boxes`
        (or be ignored as ("held", name)).
        """
        if size is not None and half is not None:
            raise RobotError(f"hold a cube edge or half extents, not both (size {size}, {half})")
        if size is not None and not _finite([size], 1, True):
            raise RobotError(f"held cube size must be a finite edge > 0 in m or None, got {size}")
        if half is not None and not _finite(half, 3, True):
            raise RobotError(f"held box half extents must be three finite values > 0, got {half}")
        relative = None if pose is None else _pose(pose)
        self._check_open()
        if self._held is not None:
            p.removeBody(self._held, physicsClientId=self._c)
            del self._half[self._held]
            self._held = None
        self._held_pose = relative
        if size is not None or half is not None:
            extents = (size / 2,) * 3 if size is not None else tuple(half)
            self._held = self._new_box((0.0, 0.0, -10.0), extents, 0.0)

    def _new_box(self, centre, half, yaw: float) -> int:
        c, half = self._c, tuple(float(h) for h in half)
        if half not in self._shapes:
            self._shapes[half] = p.createCollisionShape(
                p.GEOM_BOX, halfExtents=half, physicsClientId=c
            )
        orn = p.getQuaternionFromEuler((0.0, 0.0, yaw))
        body = p.createMultiBody(0, self._shapes[half], -1, list(centre), orn, physicsClientId=c)
        self._half[body] = half
        return body

    def _refresh(self) -> None:
        """Cache the scene AABBs (O, 2, 3) and forget the ignore masks, which depend on them."""
        aabbs = [p.getAABB(b, physicsClientId=self._c) for _, b in self._others]
        self._other_aabb = np.array(aabbs)  # (O, 2, 3)
        self._other_names = [n for n, _ in self._others]
        self._masks: dict[frozenset, tuple[np.ndarray, np.ndarray]] = {}

    def contacts(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()) -> list[Contact]:
        """Every contact below the margins at ``q``, deepest first."""
        return sorted(self._hits(q, fingers, ignore), key=lambda c: c.distance)

    def valid(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()) -> bool:
        """True when ``q`` has no contact below the margins (stops at the first one found)."""
        return next(self._hits(q, fingers, ignore), None) is None

    def check_path(
        self, path, fingers=PANDA.finger_open, ignore: Ignore = (), max_step: float = 0.02
    ) -> PathCheck:
        """Check a joint path (S, J), densified so no joint moves more than ``max_step`` rad.

        ``fingers`` is one opening or one per waypoint (S,), interpolated like the joints.
        """
        path = np.asarray(path, dtype=float)
        n_j = len(self.spec.arm_joints)
        if path.ndim != 2 or path.shape[1] != n_j or not len(path) or not np.isfinite(path).all():
            raise RobotError(f"path must be finite (S, {n_j}) joint angles, got {path.shape}")
        if not _finite([max_step], 1, True):
            raise RobotError(f"max_step must be a finite angle > 0 rad, got {max_step}")
        try:
            fs = np.broadcast_to(np.asarray(fingers, dtype=float), (len(path),))  # (S,)
        except ValueError:
            raise RobotError(f"fingers: one opening or {len(path)}, one per waypoint") from None
        seg, qs, f = densify(path, fs, max_step)
        for k in range(len(qs)):
            if next(self._hits(qs[k], f[k], ignore), None) is not None:
                hit = self.contacts(qs[k], f[k], ignore)[0]
                why = f"{hit.part} hits {hit.other} (d = {hit.distance:+.4f} m)"
                why += f" on the way to waypoint {seg[k]}"
                return PathCheck(False, int(seg[k]), tuple(qs[k].tolist()), hit, k + 1, why)
        return PathCheck(True, None, None, None, len(qs))

    def _hits(self, q, fingers, ignore):
        """Yield contacts at (q, fingers), scene pairs first; AABBs prune the narrow phase."""
        scene_mask, self_mask = self._mask(ignore)
        if len(q) != len(self.spec.arm_joints):
            raise RobotError(f"q must have {len(self.spec.arm_joints)} joint angles, got {len(q)}")
        c, body = self._c, self._body
        f = [float(fingers)]
        p.resetJointStatesMultiDof(
            body, self._joints, targetValues=[[float(v)] for v in q] + [f, f], physicsClientId=c
        )
        boxes = [p.getAABB(body, link, physicsClientId=c) for link in self._links]
        if self._held is not None:
            state = p.getLinkState(body, self._tcp, computeForwardKinematics=1, physicsClientId=c)
            at, turn = state[4], state[5]
            if self._held_pose is not None:
                at, turn = p.multiplyTransforms(at, turn, *self._held_pose)
            p.resetBasePositionAndOrientation(self._held, at, turn, physicsClientId=c)
            boxes.append(p.getAABB(self._held, physicsClientId=c))
        else:
            boxes.append(((math.nan,) * 3,) * 2)  # NaN overlaps nothing
        aabb = np.array(boxes)  # (P, 2, 3)
        lo, hi, m = aabb[:, 0], aabb[:, 1], self.margin
        o_lo, o_hi = self._other_aabb[:, 0], self._other_aabb[:, 1]  # (O, 3)
        near = ((lo[:, None] - m <= o_hi) & (o_lo <= hi[:, None] + m)).all(-1)  # (P, O)
        for a, o in zip(*np.nonzero(near & scene_mask), strict=True):
            d = self._closest(a, self._others[o][1], -1, m)
            if d is not None:
                yield Contact(self.parts[a], self._other_names[o], d)
        pa, pb, thr = self._pairs[:, 0], self._pairs[:, 1], self._pair_thr[:, None]
        near = ((lo[pa] - thr <= hi[pb]) & (lo[pb] <= hi[pa] + thr)).all(-1)  # (K,)
        for k in np.nonzero(near & self_mask)[0]:
            a, b = self._pairs[k]  # b is always a link; a may be the held cube
            d = self._closest(a, body, self._links[b], self._pair_thr[k])
            if d is not None:
                yield Contact(self.parts[a], self.parts[b], d)

    def _closest(self, part: int, body: int, link: int, thr: float) -> float | None:
        """Closest signed distance of ``part`` to (body, link) when below ``thr``, else None."""
        a, la = (self._held, -1) if part == len(self._links) else (self._body, self._links[part])
        pts = p.getClosestPoints(a, body, thr, la, link, physicsClientId=self._c)
        d = min((pt[8] for pt in pts), default=math.inf)
        return d if d < thr else None

    def _mask(self, ignore) -> tuple[np.ndarray, np.ndarray]:
        """Boolean masks of pairs to check, (P, O) scene and (K,) self, cached per ignore set."""
        self._check_open()
        try:
            key = ignore if isinstance(ignore, frozenset) else frozenset(ignore)
        except TypeError:
            raise RobotError(f"ignore must hold (part, other) tuples, got {ignore!r}") from None
        if key in self._masks:
            return self._masks[key]
        scene = np.ones((len(self.parts), len(self._others)), dtype=bool)  # (P, O)
        scene[self._index[self.spec.base_link], 0] = False  # link0 stands on the table
        own = np.ones(len(self._pairs), dtype=bool)  # (K,)
        for pair in key:
            part, other = pair if isinstance(pair, tuple) and len(pair) == 2 else ("", "")
            rows, col = self._groups.get(part), self._index.get(other)
            if rows is None or (col is None and other not in self._other_names):
                raise RobotError(
                    f"ignore {pair!r} is not (link|held|hand|robot, box|table|link); boxes: "
                    f"{', '.join(self._other_names[1:]) or 'none'}"
                )
            if col is None:
                scene[rows, self._other_names.index(other)] = False
            for k, (a, b) in enumerate(self._pairs if col is not None else ()):
                own[k] &= not ((a in rows and b == col) or (b in rows and a == col))
        self._masks[key] = (scene, own)
        return scene, own

    def _check_open(self) -> None:
        if self._c is None:
            raise RobotError("this PandaCollision is closed")

    def close(self) -> None:
        """Disconnect the private PyBullet client (idempotent)."""
        if self._c is not None:
            p.disconnect(self._c)
            self._c = None

    def __enter__(self) -> PandaCollision:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
