"""The Panda's sphere model as the batched checker uses it: its fixed geometry, built once.

For `motion.sphere_check.collision.SphereCollision`: the URDF's chain (`motion.sphere_check.fk`),
the G spheres of `robots.panda_spheres` link by link, and the structures of the checks' phases
(`SphereModel`): the links in `BUCKETS` by sphere count, padded per bucket; each link's spheres
in clusters of at most `CLUSTER`; the links' bounding spheres; the link pairs checked for
self-collision with the `APART` rules that skip them; each link's 26-DOP and its axis-aligned
box (`motion.sphere_check.bounds`). Its methods place the spheres in world frames: `frames`,
`links`, `place`, and `by_bucket` to group (configuration, link) pairs by bucket.
"""

from __future__ import annotations

import math
from itertools import combinations

import numpy as np

from motion.errors import MotionError
from motion.sphere_check.bounds import bound, clusters, dops
from motion.sphere_check.fk import FLOAT, PARTS, batch_first, chain, frames, link_spheres, onehot
from robots.collision import DISABLED_PAIRS, HAND
from robots.panda import PandaSpec
from robots.panda_spheres import FINGERS

# Link pairs whose collision meshes stay at least APART_CLEARANCE apart while q[j] (0-based: 5
# is panda_joint6) is at least the given angle (rad; -inf: always), within the datasheet limits
# and for any finger opening: the least distance on a 0.02-0.03 rad grid of the two joints
# between the links (PyBullet's closest points), less the most a point can move between grid
# points (tests/motion/test_sphere_check.py re-derives them). They are skipped there while
# self_margin < APART_CLEARANCE. The wrist's links are closer to each other than the spheres'
# cover gap, so checking them with spheres would refuse most configurations.
APART = (
    ("panda_link0", "panda_link2", 0, -math.inf),  # >= 12 cm on a 0.03 rad grid of (q1, q2)
    ("panda_link1", "panda_link3", 0, -math.inf),  # >= 12 cm, grid of (q2, q3)
    ("panda_link2", "panda_link4", 0, -math.inf),  # >= 45 mm, grid of (q3, q4)
    ("panda_link3", "panda_link5", 0, -math.inf),  # >= 48 mm, grid of (q4, q5)
    ("panda_link5", "panda_link7", 5, 0.9),  # >= 9.8 mm for q6 >= 0.9, grid of (q6, q7)
    ("panda_link5", "panda_hand", 5, 0.9),  # >= 12 mm for q6 >= 0.9, grid of (q6, q7)
    ("panda_link6", "panda_hand", 0, -math.inf),  # >= 28 mm, grid of q7
    ("panda_link6", FINGERS[0], 0, -math.inf),  # >= 10 cm, grid of q7
    ("panda_link6", FINGERS[1], 0, -math.inf),
    ("panda_link7", FINGERS[0], 0, -math.inf),  # >= 57 mm, fingers at 0 and 0.04 m
    ("panda_link7", FINGERS[1], 0, -math.inf),
)
APART_CLEARANCE = 0.003  # m
# the narrow phases test the links in buckets by sphere count (at most 10, 30, more: link0's
# 46), each link's spheres padded to its bucket's widest: few groups, little padding
BUCKETS = (10, 30)
CLUSTER = 10  # spheres per cluster of a link in the self-collision narrow phase


class SphereModel:
    """The fixed geometry of the Panda's sphere model for ``spec``; see the module docstring.

    Arrays are float32 (`FLOAT`) where the checks compute with them; L links (`PARTS`), G
    spheres, K self-collision pairs, C clusters.
    """

    def __init__(self, spec: PandaSpec):
        self.rot, self.off, self.hand, self.tcp = chain(spec)
        self._quarter_turns()
        spheres = link_spheres()
        # the G spheres, link by link: centres (G, 3) in their link's frame, radii (G,)
        self.local = np.concatenate([spheres[link][0] for link in PARTS])
        self.radii = np.concatenate([spheres[link][1] for link in PARTS])
        self.count = np.array([len(spheres[link][1]) for link in PARTS])  # (L,)
        self.start = np.cumsum(self.count) - self.count  # (L,) first sphere of each link
        self._buckets(spheres)
        self._clusters(spheres)
        bounds = [bound(*spheres[link]) for link in PARTS]
        self.bounds = np.array([c for c, _ in bounds])  # (L, 3) bounding-sphere centres
        self.reach = np.array([r for _, r in bounds])  # (L,) bounding-sphere radii
        self._pair_rules()
        self.directions, self.dop = dops()  # (26, 3), (L, 26)
        self.arm_vs_held = np.array([k for k, n in enumerate(PARTS) if n not in HAND])
        for name in ("rot", "off", "hand", "tcp", "local", "radii", "bounds", "reach"):
            setattr(self, name, getattr(self, name).astype(FLOAT))
        self.directions, self.dop = self.directions.astype(FLOAT), self.dop.astype(FLOAT)
        self._dop_boxes()

    def _quarter_turns(self) -> None:
        """Each joint origin's rotation as (source axis, sign) per axis (``swaps``); the
        URDF's are all quarter turns (MotionError otherwise)."""
        self.swaps = []
        for origin in self.rot:
            k = np.abs(origin).argmax(0)  # (3,) the parent axis each new axis is
            if not np.allclose(np.abs(origin), onehot(k), atol=1e-9):
                raise MotionError(f"joint origin rotations must be quarter turns, got {origin}")
            self.swaps.append([(int(k[a]), float(np.sign(origin[k[a], a]))) for a in range(3)])

    def _buckets(self, spheres) -> None:
        """The links by sphere count into BUCKETS; per bucket, every link's spheres padded to
        the bucket's largest count by repeating its first (a repeat changes no minimum):
        centres (L, S_k, 3) in the link's frame, radii (L, S_k); a link outside the bucket is
        zeros."""
        self.bucket = np.searchsorted(BUCKETS, self.count)  # (L,)
        self.pad_local, self.pad_radii = [], []
        for k in range(len(BUCKETS) + 1):
            width = int(self.count[self.bucket == k].max(initial=1))
            local, radii = np.zeros((len(PARTS), width, 3)), np.zeros((len(PARTS), width))
            for link, name in enumerate(PARTS):
                if self.bucket[link] == k:
                    rows = np.arange(width)
                    rows = np.where(rows < self.count[link], rows, 0)
                    local[link], radii[link] = spheres[name][0][rows], spheres[name][1][rows]
            self.pad_local.append(local.astype(FLOAT))
            self.pad_radii.append(radii.astype(FLOAT))

    def _pair_rules(self) -> None:
        """The link pairs checked for self-collision (K, 2), and per pair the joint whose
        angle, when at least its bound, keeps the pair apart (see APART)."""
        pairs = [
            (a, b)
            for a, b in combinations(range(len(PARTS)), 2)
            if frozenset((PARTS[a], PARTS[b])) not in DISABLED_PAIRS
        ]
        self.pairs = np.array(pairs)  # (K, 2) link pairs checked for self-collision
        # (K,) the joint whose angle, when at least (K,), keeps the pair apart (see APART)
        apart = {frozenset((a, b)): (j, lowest) for a, b, j, lowest in APART}
        rule = [apart.get(frozenset((PARTS[a], PARTS[b])), (0, math.inf)) for a, b in pairs]
        self.apart_joint = np.array([j for j, _ in rule])
        self.apart_from = np.array([lowest for _, lowest in rule])

    def _dop_boxes(self) -> None:
        """The 26-DOP's first test: its axis-aligned box, centre (L, 3) and half extents
        (L, 3), and the supports from the box's centre (26, L)."""
        axes = [np.flatnonzero((self.directions == e).all(1))[0] for e in np.eye(3, dtype=FLOAT)]
        minus = [np.flatnonzero((self.directions == -e).all(1))[0] for e in np.eye(3)]
        high, low = self.dop[:, axes], -self.dop[:, minus]  # (L, 3) each
        self.aabb_c, self.aabb_h = (high + low) / 2, (high - low) / 2
        # (26, L) the supports from the box's centre: d . (p - c) - (s - d . c) = d . p - s
        self.dop_c = np.ascontiguousarray((self.dop - self.aabb_c @ self.directions.T).T)

    def _clusters(self, spheres) -> None:
        """The self-collision narrow phase's clusters (`bounds.clusters`), as float32."""
        link_of, local, radii, count, mids, reach, first, parts = clusters(spheres, CLUSTER)
        self.cluster_link, self.cluster_count = link_of, count  # (C,) each
        self.cluster_local = local.astype(FLOAT)  # (C, CLUSTER, 3)
        self.cluster_radii = radii.astype(FLOAT)  # (C, CLUSTER)
        self.cluster_mid, self.cluster_reach = mids.astype(FLOAT), reach.astype(FLOAT)
        self.first_cluster, self.n_clusters = first, parts  # (L,) each

    # ---- kinematics --------------------------------------------------------------------------

    def links(self, q: np.ndarray, fingers: float) -> tuple[np.ndarray, np.ndarray]:
        """World rotations (B, L + 1, 3, 3) and origins (B, L + 1, 3): see `fk.links`."""
        return batch_first(*self.frames(q, fingers))

    def frames(self, q: np.ndarray, fingers: float) -> tuple[np.ndarray, np.ndarray]:
        """The same batch-last, (L + 1, 3, 3, B) and (L + 1, 3, B): see `fk.frames`."""
        return frames(q, fingers, self.off, self.swaps, self.hand, self.tcp)

    def place(self, rot: np.ndarray, pos: np.ndarray, bucket: int, link: np.ndarray, gap):
        """World centres (M, S, 3) and radii grown by ``gap`` (M, S) of the spheres of links
        ``link`` (M,), all in bucket ``bucket`` (padded to its S), in M frames: rotations
        (M, 3, 3) and origins (M, 3) of those links (or of each relative to another link)."""
        local = self.pad_local[bucket][link]  # (M, S, 3)
        x = np.matmul(local, np.swapaxes(rot, 1, 2))  # (M, S, 3): R a for every sphere a
        return x + pos[:, None], self.pad_radii[bucket][link] + gap

    def by_bucket(self, b: np.ndarray, link: np.ndarray):
        """The (configuration, link) pairs ``b``, ``link`` (M,) grouped by the links' bucket:
        yields the bucket, the positions (M_k,) of its pairs, their configurations and links."""
        if not link.size:
            return
        bucket = self.bucket[link]  # (M,)
        for k in range(len(BUCKETS) + 1):
            group = np.flatnonzero(bucket == k)
            if group.size:
                yield k, group, b[group], link[group]
