"""A batched, conservative collision checker of the Panda against boxes over a sphere model.

`SphereCollision` has the interface of `robots.collision.PandaCollision` (``set_boxes``,
``hold``, ``valid``, ``contacts``, ``check_path``, ``margin``, ``self_margin``) plus
``valid_batch(q (B, J)) -> (B,) bool``, which checks B configurations at once in numpy
(float32): forward kinematics of the 7 revolute joints (the URDF's joint origins, parsed once),
the G spheres of `robots.panda_spheres` (cuRobo's SPHERES plus the COVER rows, which also model
panda_link0), each grown by ``COVER_GAP``, and against them

- every box (a block or an obstacle, turned by ``yaw`` about z): the exact box signed distance
  of the sphere centre, less the grown radius, against ``margin``;
- the table, a plane at z = 0 (panda_link0 stands on it: that pair is skipped, as the mesh
  model does);
- the other links (self-collision, against ``self_margin``): the mesh model's link pairs (all
  but `robots.collision.DISABLED_PAIRS`), less the pairs `model.APART` proves apart at the current
  angles; a pair is the distal link's grown spheres against the 26-DOP (26 support planes)
  that holds the other link's collision hull, a lower bound of the distance to it;
- the held box (`hold`): riding in the TCP frame, against the boxes with the separating axis
  theorem (its half extents grown by the margin), against the table through its lowest corner,
  and against the links other than the hand and fingers through their grown spheres' signed
  distances in its frame.

Conservative. Every point of a link's collision hull lies within COVER_GAP (1.5 cm) of one of its
spheres, so when a mesh comes within ``margin`` of a box, a grown sphere does too: the model
says "collision" a little earlier than the mesh model, never later. tests/motion/
test_sphere_check.py compares the two on configurations beside boxes (no false "free" in 5,000
at margins of 1 and 2 cm; about 9 % of all are false "collisions", mostly boxes 1-2.5 cm off).
Its contacts' distances are lower bounds, so the mesh model stays the final word
(`motion.sphere_check.screened.Screened` pairs the two: the mesh model answers ``valid`` and
``check_path``, the spheres ``valid_batch``, which `motion.rrt.plan_path` uses to search).

Speed. `CHUNK` configurations at a time; forward kinematics and the broad phases batch-last
(`motion.sphere_check.fk`, `motion.sphere_check.bounds`); the fixed geometry of every phase is
`motion.sphere_check.model.SphereModel`, built once (``model``). A bounding sphere per link
(L = 11) is tested first: against the table, and against each box's world bounds axis by axis,
(L, O, B); the flagged (configuration, link) pairs go to the narrow phase in three `model.BUCKETS`
of links by sphere count (each link's spheres padded to its bucket's widest, placed in one batched
product per bucket). Self pairs go through the bounding spheres (the pairs `model.APART` always
keeps apart never), then the link's bounding sphere against the other link's box, then clusters of
at most `model.CLUSTER` spheres of the link (their bounding spheres against that box first), then
each sphere against the DOP's box and, where near, its 26 planes. A configuration with a contact
found is not tested further (``valid_batch``). Without square roots where only the sign of a
clearance matters, nor BLAS (numpy's OpenBLAS spreads a large product over a second thread): one
thread. tests/motion/test_sphere_check.py checks the verdicts against a check that tests every
sphere against everything.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence

import numpy as np

from motion.errors import MotionError
from motion.sphere_check.bounds import box_gap, box_sdf, dop_gap, near_box, obb_gap, turn
from motion.sphere_check.fk import FLOAT, PARTS, batch_first
from motion.sphere_check.model import APART_CLEARANCE, SphereModel
from robots.collision import HAND, HELD, TABLE, Box, Contact, PathCheck, densify
from robots.panda import PANDA, PandaSpec
from robots.panda_spheres import COVER_GAP

Ignore = Collection[tuple[str, str]]  # (part, other) pairs to skip, as in PandaCollision
CHUNK = 2048  # configurations per pass of valid_batch: ~2x faster than 100,000 at once


class SphereCollision:
    """The Panda's sphere model, its held box and a set of boxes; see the module docstring.

    ``margin``: a contact counts when a mesh would come closer than this to a box, the table or
    the held box (m); ``self_margin`` the same between two links (default 0, as the mesh
    model). Both may be changed between calls (the guard widens ``margin`` while it plans).
    """

    def __init__(self, margin: float = 0.01, spec: PandaSpec = PANDA, self_margin: float = 0.0):
        if not (math.isfinite(margin) and math.isfinite(self_margin)):
            raise MotionError(f"margins must be finite and >= 0, got {margin}, {self_margin}")
        if margin < 0 or self_margin < 0:
            raise MotionError(f"margins must be finite and >= 0, got {margin}, {self_margin}")
        self.margin, self.self_margin, self.spec = float(margin), float(self_margin), spec
        self.gap = COVER_GAP
        self.parts = (*PARTS, HELD)  # (P,) = L links + the held box, as PandaCollision.parts
        self.model = SphereModel(spec)  # the fixed geometry, built once
        index = {name: k for k, name in enumerate(self.parts)}
        self._index = index
        self._groups = {n: [k] for n, k in index.items()} | {
            "robot": list(range(len(PARTS))),
            "hand": [index[n] for n in HAND],
        }
        self._turns = np.zeros((0, 3, 3))  # (O, 3, 3) box frame -> world
        self._cos, self._sin = np.zeros(0, FLOAT), np.zeros(0, FLOAT)  # (O,) of the yaws
        self._world_half = np.zeros((3, 0), FLOAT)  # (3, O): see set_boxes
        self._names: list[str] = [TABLE]  # (O + 1,) the table, then the boxes
        self._box_c = np.zeros((0, 3))  # (O, 3)
        self._halves = np.ones((0, 3))  # (O, 3)
        self._yaws = np.zeros(0)  # (O,)
        self._held_half: np.ndarray | None = None  # (3,)
        self._held_pose = np.eye(4)  # in the TCP frame
        self._masks: dict[frozenset, tuple[np.ndarray, np.ndarray]] = {}

    # ---- the scene ---------------------------------------------------------------------------

    def set_boxes(self, boxes: Sequence[Box]) -> None:
        """Replace all boxes (blocks and obstacles). Names must be unique and not a part name."""
        seen, reserved = set(), {*self._groups, TABLE, ""}
        rows = []
        for box in boxes:
            name = getattr(box, "name", None)
            if not isinstance(name, str) or name in seen | reserved:
                raise MotionError(f"box name {name!r} is empty, repeated, 'table' or a robot part")
            try:
                row = np.array([*box.centre, *box.half, box.yaw], dtype=float)
            except (TypeError, ValueError):
                row = np.full(1, np.nan)
            if row.shape != (7,) or not np.isfinite(row).all() or (row[3:6] <= 0).any():
                raise MotionError(
                    f"box {name!r}: centre (3,), half (3,) > 0 and yaw must be finite"
                )
            seen.add(name)
            rows.append(row)
        table = np.array(rows, dtype=FLOAT).reshape(-1, 7)  # (O, 7)
        self._box_c, self._halves, self._yaws = table[:, :3], table[:, 3:6], table[:, 6]
        self._turns = turn(self._yaws).astype(FLOAT)
        self._cos, self._sin = np.cos(self._yaws), np.sin(self._yaws)  # (O,) each
        # (3, O) half extents of each box's world axis-aligned bounding box (turned about z)
        c, s_ = np.abs(self._cos), np.abs(self._sin)
        h = self._halves
        self._world_half = np.stack(
            [c * h[:, 0] + s_ * h[:, 1], s_ * h[:, 0] + c * h[:, 1], h[:, 2]]
        ).astype(FLOAT)
        self._names = [TABLE, *(b.name for b in boxes)]
        self._masks = {}

    def hold(self, size: float | None = None, half=None, pose=None) -> None:
        """Hold a box in the hand (as `PandaCollision.hold`); nothing when ``size`` and
        ``half`` are both None. ``pose``: (4, 4) the box's pose in the TCP frame; None: centred
        at the TCP, turned with the hand."""
        if size is not None and half is not None:
            raise MotionError(f"hold a cube edge or half extents, not both (size {size}, {half})")
        extents = None
        if size is not None or half is not None:
            extents = np.asarray((size / 2,) * 3 if size is not None else half, dtype=float)
            if extents.shape != (3,) or not np.isfinite(extents).all() or (extents <= 0).any():
                raise MotionError(f"held box must have a finite size or half extents > 0 m: {half}")
        relative = np.eye(4) if pose is None else np.asarray(pose, dtype=float)
        if relative.shape != (4, 4) or not np.isfinite(relative).all():
            raise MotionError(f"held pose must be a finite (4, 4) transform, got {relative.shape}")
        r = relative[:3, :3]
        if np.abs(r @ r.T - np.eye(3)).max() > 1e-6 or np.linalg.det(r) < 0:
            raise MotionError("held pose's rotation block is not a rotation (tolerance 1e-6)")
        self._held_half = None if extents is None else extents.astype(FLOAT)
        self._held_pose = relative.astype(FLOAT)

    def _mask(self, ignore: Ignore) -> tuple[np.ndarray, np.ndarray]:
        """Pairs to check, cached per ignore set: (P, O + 1) part vs table and boxes, (K,) link
        pairs, (L,) links vs the held box."""
        try:
            key = ignore if isinstance(ignore, frozenset) else frozenset(ignore)
        except TypeError:
            raise MotionError(f"ignore must hold (part, other) tuples, got {ignore!r}") from None
        if key in self._masks:
            return self._masks[key]
        scene = np.ones((len(self.parts), len(self._names)), dtype=bool)  # (P, O + 1)
        scene[self._index[self.spec.base_link], 0] = False  # link0 stands on the table
        own = np.ones(len(self.model.pairs), dtype=bool)  # (K,)
        held_arm = np.ones(len(PARTS), dtype=bool)  # (L,) held box vs link
        for pair in key:
            part, other = pair if isinstance(pair, tuple) and len(pair) == 2 else ("", "")
            rows, col = self._groups.get(part), self._index.get(other)
            if rows is None or (col is None and other not in self._names):
                raise MotionError(
                    f"ignore {pair!r} is not (link|held|hand|robot, box|table|link); boxes: "
                    f"{', '.join(self._names[1:]) or 'none'}"
                )
            if col is None:
                scene[rows, self._names.index(other)] = False
                continue
            for k, (a, b) in enumerate(self.model.pairs):
                own[k] &= not ((a in rows and b == col) or (b in rows and a == col))
            held = self._index[HELD]
            if held in rows and col < len(PARTS):
                held_arm[col] = False
            if part != HELD and other == HELD:
                held_arm[[r for r in rows if r < len(PARTS)]] = False
        self._masks[key] = (scene, own, held_arm)
        return self._masks[key]

    def _other(self, other, k: int) -> str:
        """The name of what a part hit: ``other`` itself (a name), or entry k of an index
        array into the table and boxes (>= 0) or into the links (~link < 0)."""
        if isinstance(other, str):
            return other
        return self._names[other[k]] if other[k] >= 0 else self.parts[~other[k]]

    # ---- queries -----------------------------------------------------------------------------

    def valid_batch(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()):
        """(B,) bool: True where configuration q (B, J) rad has no contact below the margins;
        checked `CHUNK` configurations at a time (the working arrays stay in cache)."""
        q = self._configs(q)
        out = np.empty(len(q), dtype=bool)
        for s in range(0, len(q), CHUNK):  # (CHUNK, J) each
            out[s : s + CHUNK] = self._clearance(q[s : s + CHUNK], fingers, ignore, False)
        return out

    def valid(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()) -> bool:
        """True when ``q`` (J,) has no contact below the margins."""
        return bool(self._clearance(self._configs(q, single=True), fingers, ignore, False)[0])

    def contacts(self, q, fingers: float = PANDA.finger_open, ignore: Ignore = ()) -> list[Contact]:
        """The contacts below the margins at ``q`` (J,), deepest first; a distance is the
        grown spheres' clearance (m, at most the meshes' distance)."""
        found = self._clearance(self._configs(q, single=True), fingers, ignore, detail=True)
        return sorted(found, key=lambda c: c.distance)

    def check_path(
        self, path, fingers=PANDA.finger_open, ignore: Ignore = (), max_step: float = 0.02
    ) -> PathCheck:
        """Check a joint path (S, J), densified so no joint moves more than ``max_step`` rad
        (as `PandaCollision.check_path`), one batch per finger opening."""
        path = np.asarray(path, dtype=float)
        n_j = len(self.spec.arm_joints)
        if path.ndim != 2 or path.shape[1] != n_j or not len(path) or not np.isfinite(path).all():
            raise MotionError(f"path must be finite (S, {n_j}) joint angles, got {path.shape}")
        if not (math.isfinite(max_step) and max_step > 0):
            raise MotionError(f"max_step must be a finite angle > 0 rad, got {max_step}")
        try:
            fs = np.broadcast_to(np.asarray(fingers, dtype=float), (len(path),))  # (S,)
        except ValueError:
            raise MotionError(f"fingers: one opening or {len(path)}, one per waypoint") from None
        seg, qs, f = densify(path, fs, max_step)
        ok = np.ones(len(qs), dtype=bool)
        for opening in np.unique(f):
            rows = f == opening
            ok[rows] = self.valid_batch(qs[rows], float(opening), ignore)
        if ok.all():
            return PathCheck(True, None, None, None, len(qs))
        k = int(np.argmin(ok))
        hits = self.contacts(qs[k], f[k], ignore)  # empty only when rounding tips the sign
        hit = hits[0] if hits else Contact("robot", "unknown", 0.0)
        why = f"{hit.part} hits {hit.other} (d = {hit.distance:+.4f} m)"
        why += f" on the way to waypoint {seg[k]}"
        return PathCheck(False, int(seg[k]), tuple(qs[k].tolist()), hit, k + 1, why)

    def _configs(self, q, single: bool = False) -> np.ndarray:
        """``q`` as float64 (B, J), from (J,) when ``single``, else from (B, J)."""
        n_j = len(self.spec.arm_joints)
        try:
            a = np.asarray(q, dtype=float)
        except (TypeError, ValueError):
            raise MotionError(f"q must be numeric joint angles, got {q!r}") from None
        if a.ndim != (1 if single else 2) or a.shape[-1] != n_j:
            want = f"({n_j},)" if single else f"(B, {n_j})"
            raise MotionError(f"q must have shape {want}, got {a.shape}")
        if not np.isfinite(a).all():
            raise MotionError("q contains NaN or inf")
        return (a[None] if single else a).astype(FLOAT)

    # ---- the checks --------------------------------------------------------------------------

    def _clearance(self, q: np.ndarray, fingers: float, ignore: Ignore, detail: bool):
        """(B,) bool validity, or (detail, B = 1) the list of contacts."""
        scene, own, held_arm = self._mask(ignore)
        model = self.model
        n, links = q.shape[0], len(PARTS)
        rot_t, pos_t = model.frames(q, float(fingers))  # (F, 3, 3, B), (F, 3, B)
        b = model.bounds[:, :, None]  # (L, 3, 1) the bounding spheres' centres, link frames
        mid_t = pos_t[:links] + rot_t[:links, :, 0] * b[:, None, 0]  # (L, 3, B)
        mid_t += rot_t[:links, :, 1] * b[:, None, 1]
        mid_t += rot_t[:links, :, 2] * b[:, None, 2]
        rot, pos = batch_first(rot_t, pos_t)  # (B, F, 3, 3), (B, F, 3)
        reach = model.reach + self.gap  # (L,)
        hit, found = np.zeros(n, dtype=bool), []  # found: [Contact]

        def record(b, part, other, clearance, limit: float) -> None:
            """Mark the rows b (M,) whose clearance (M,), or any of whose spheres' (M, S), is
            under ``limit``; ``part`` a name or link indices (M,), ``other`` a name or indices
            (see `_other`)."""
            if clearance.ndim == 2:
                clearance = clearance.min(1)  # (M,)
            bad = clearance < limit
            hit[b[bad]] = True
            if detail:
                for k in np.flatnonzero(bad):
                    name = part if isinstance(part, str) else self.parts[part[k]]
                    found.append(Contact(name, self._other(other, k), float(clearance[k])))

        def pending(*arrays):
            """The entries of ``arrays`` (first: configurations (M,)) whose configuration has
            no contact yet (all of them with ``detail``: every contact is listed)."""
            if detail:
                return arrays
            keep = ~hit[arrays[0]]
            return tuple(a[keep] for a in arrays)

        m = self.margin
        # the table: a plane at z = 0
        low = mid_t[:, 2] < (reach + m)[:, None]  # (L, B)
        near_l, near_b = np.nonzero(low & scene[:links, 0, None])
        for k, _, rows, link in model.by_bucket(near_b, near_l):
            x, grown = model.place(rot[rows, link], pos[rows, link], k, link, self.gap)  # (M, S, 3)
            record(rows, link, np.zeros_like(rows), x[..., 2] - grown, m)
        # the boxes, each in its own frame (turned about z only)
        if len(self._names) > 1:  # the bounding spheres against the boxes' world bounds
            near = np.empty((links, len(self._names) - 1, n), dtype=bool)  # (L, O, B)
            near[:] = scene[:links, 1:, None]
            d, inside = np.empty(near.shape, dtype=FLOAT), np.empty_like(near)
            for axis in range(3):  # batch-last, in place: every operation over rows of B
                room = self._world_half[axis] + (reach[:, None] + m)  # (L, O)
                np.subtract(mid_t[:, axis, None], self._box_c[:, axis, None], out=d)
                near &= np.less(np.abs(d, out=d), room[..., None], out=inside)
            near_l, near_o, near_b = np.nonzero(near)  # (M,) each
            near_b, near_l, near_o = pending(near_b, near_l, near_o)
            for k, group, rows, link in model.by_bucket(near_b, near_l):
                rot_k, pos_k = rot[rows, link], pos[rows, link]  # (M, 3, 3), (M, 3)
                x, grown = model.place(rot_k, pos_k, k, link, self.gap)  # (M, S, 3)
                box = near_o[group]  # (M,)
                gap = self._box_gap(x, box[:, None], grown + m, detail)  # (M, S)
                record(rows, link, box + 1, gap + m, m)
        # the links against each other: the distal link's spheres against the other's 26-DOP
        if self.self_margin < APART_CLEARANCE:  # the pairs APART keeps apart at any angle
            own = own & (model.apart_from > -math.inf)
        a, c = model.pairs[own, 1], model.pairs[own, 0]  # (K',) sphere side, DOP side
        apart = reach[a] + reach[c] + self.self_margin  # (K',)
        gap = mid_t[a]  # (K', 3, B)
        gap -= mid_t[c]
        gap *= gap
        close = gap.sum(1) < np.square(apart)[:, None]  # (K', B)
        if self.self_margin < APART_CLEARANCE:  # ... and those it keeps apart at these angles
            close &= q.T[model.apart_joint[own]] < model.apart_from[own, None]
        near_b, near_k = pending(*np.nonzero(close)[::-1])
        la, lc = a[near_k], c[near_k]
        if near_b.size:  # link a's bounding sphere against link c's box, in c's frame
            d = mid_t[la, :, near_b] - pos[near_b, lc]  # (M, 3)
            d = np.einsum("mji,mj->mi", rot[near_b, lc], d) - model.aabb_c[lc]  # from its middle
            keep = near_box(d, model.aabb_h[lc], reach[la] + self.self_margin)
            near_b, la, lc = near_b[keep], la[keep], lc[keep]
        if near_b.size:
            self._self_pairs(rot, pos, near_b, la, lc, record)
        if self._held_half is not None:
            self._check_held(rot, pos, mid_t.transpose(2, 0, 1), scene, held_arm, record)
        return found if detail else ~hit

    def _self_pairs(self, rot, pos, b, link, other, record) -> None:
        """The flagged link pairs (M,): configurations ``b``, sphere side ``link``, DOP side
        ``other``; each sphere-side cluster's bounding sphere against the other link's box,
        then its spheres against that box and, where near, against the 26-DOP."""
        model = self.model
        r_c = rot[b, other]  # (M, 3, 3)
        r_rel = np.swapaxes(r_c, 1, 2) @ rot[b, link]  # (M, 3, 3) link -> the other's frame
        t_rel = np.einsum("mji,mj->mi", r_c, pos[b, link] - pos[b, other])  # (M, 3)
        parts = model.n_clusters[link]  # (M,)
        pair = np.repeat(np.arange(b.size), parts)  # (N,) each pair's clusters
        cluster = model.first_cluster[link][pair] + np.arange(pair.size)
        cluster -= np.repeat(np.cumsum(parts) - parts, parts)  # (N,)
        frame = other[pair]  # (N,)
        box_c, box_h = model.aabb_c[frame], model.aabb_h[frame]  # (N, 3) each
        centre = np.einsum("nij,nj->ni", r_rel[pair], model.cluster_mid[cluster]) + t_rel[pair]
        reach = model.cluster_reach[cluster] + (self.gap + self.self_margin)  # (N,)
        keep = near_box(centre - box_c, box_h, reach)
        pair, cluster, frame = pair[keep], cluster[keep], frame[keep]
        box_c, box_h = box_c[keep, None], box_h[keep, None]  # (N', 1, 3) each
        local = model.cluster_local[cluster]  # (N', S, 3), padded with repeats of the first
        # (N', S, 3) in the other link's frame, from the centre of its DOP's box
        inner = np.matmul(local, np.swapaxes(r_rel[pair], 1, 2)) + (t_rel[pair, None] - box_c)
        grown = model.cluster_radii[cluster] + self.gap  # (N', S)
        # the DOP's axis-aligned box first (a lower bound too), the 26 planes where it is near
        near_n, near_s = np.nonzero(near_box(inner, box_h, grown + self.self_margin))
        gap = dop_gap(inner[near_n, near_s], model.directions, model.dop_c[:, frame[near_n]])
        gap -= grown[near_n, near_s]  # (K,) the 26-DOP's bound
        least = np.full(b.size, np.inf, dtype=gap.dtype)  # (M,) per pair, over its spheres
        np.minimum.at(least, pair[near_n], gap)
        record(b, link, ~other, least, self.self_margin)

    def _box_gap(self, points: np.ndarray, box, reach, exact: bool) -> np.ndarray:
        """`bounds.box_gap` of points (..., 3) to the boxes ``box`` (indices broadcasting
        with the points' leading axes, or a slice) less ``reach`` (...)."""
        d = points - self._box_c[box]  # (..., 3)
        return box_gap(d, self._cos[box], self._sin[box], self._halves[box], reach, exact)

    def _check_held(self, rot, pos, mid, scene, held_arm, record) -> None:
        """The held box at the TCP against the table, the boxes and the arm's links."""
        m, held, model = self.margin, self._index[HELD], self.model
        half = self._held_half  # (3,)
        r_tcp, t_tcp = rot[:, -1], pos[:, -1]  # (B, 3, 3), (B, 3)
        r_box = r_tcp @ self._held_pose[:3, :3]  # (B, 3, 3) held box -> world
        t_box = t_tcp + r_tcp @ self._held_pose[:3, 3]  # (B, 3)
        every = np.arange(len(t_box))
        if scene[held, 0]:
            low = t_box[:, 2] - np.abs(r_box[:, 2, :]) @ half  # (B,) lowest corner's z
            record(every, HELD, TABLE, low, m)
        columns = np.flatnonzero(scene[held, 1:])
        if columns.size:  # the held box's bounding sphere first, then the separating axes
            ball = float(np.linalg.norm(half)) + m
            gap = self._box_gap(t_box[:, None], columns, ball, exact=False)  # (B, O')
            near_b, near_o = np.nonzero(gap < 0.0)
            if near_b.size:
                box = columns[near_o]  # (M,)
                turns, centres, halves = self._turns[box], self._box_c[box], self._halves[box]
                sep = obb_gap(r_box[near_b], t_box[near_b], half + m, turns, centres, halves)
                record(near_b, HELD, box + 1, sep + m, m)
        links = model.arm_vs_held[held_arm[model.arm_vs_held]]
        if links.size:
            reach = model.reach + self.gap
            # (B, L', 3) link bounds in the held box's frame
            inner = np.einsum("bji,blj->bli", r_box, mid[:, links] - t_box[:, None])
            gap = box_sdf(inner, half) - reach[links]  # (B, L')
            near_b, near_l = np.nonzero(gap < m)
            for k, _, rows, link in model.by_bucket(near_b, links[near_l]):
                r_in = np.swapaxes(r_box[rows], 1, 2)  # (M, 3, 3) world -> held box
                r_rel = r_in @ rot[rows, link]  # (M, 3, 3) link -> held box
                t_rel = np.einsum("mij,mj->mi", r_in, pos[rows, link] - t_box[rows])  # (M, 3)
                # (M, S, 3) in its frame
                inner, grown = model.place(r_rel, t_rel, k, link, self.gap)
                record(rows, HELD, ~link, box_sdf(inner, half) - grown, m)
