"""Object poses of a scene file's world from RGB-D cameras: the camera sensor of geometric TAMP.

`ScenePoses` is a pose sensor (`tamp.geo.episode` ``observation="camera"``): each call renders
every camera of `scene_cameras` (RGB and z-depth, `Simulator.render_rgbd`) and estimates every
movable object's pose (x, y, z, yaw) from the pixels alone, using what the robot knows of its
objects: the scene file's kind, size and colour of each (the scene file is the model database)
and the fixed geometry (table, regions, obstacles, walls). Nothing here reads ground truth.

Per call:

1. Pixels: each object colour's pixels (`perception.segment.colour_labels` over the scene's
   object colours, eroded by one pixel so no pixel mixes two surfaces) become world points
   (`tamp.camera.geometry.backproject`) with surface normals (`tamp.camera.poses`); points on
   the fixed geometry (the table top, a region's surface, inside an obstacle grown by
   ``fixed_pad``) are dropped. All cameras' points are pooled.
2. Identity: an object whose colour no other object has owns its colour's points (the cluster
   nearest its previous estimate and whatever lies within its size of it). Objects that share
   a colour: the colour's points are split into clusters (connected within ``link``; a cluster
   taller than one object into layers of the model's height; a layer larger than one
   footprint into that many by k-means), and the clusters are assigned to the objects by the
   assignment that minimises the total distance to their previous estimates (Hungarian). The
   previous estimate is the pose in the scene the caller passes: the scene file's at the start.
3. Fit: each object's known model is fitted to its points (`tamp.camera.fit.fit_object`).
4. Support: bottom up, an object whose fitted height lies within ``snap`` of resting on the
   table, a region's surface, an obstacle's top or a lower object's top (or, with no top face
   seen, whose visible side band allows it) is set onto it.

An object no camera sees (too few points: hidden by the arm, a post or another object) keeps
its previous estimate; ``unseen`` counts those, per object, for the record.

Cameras (`scene_cameras`): the scene's own camera, its mirror image across the workspace's
middle (the other side of the posts and kerbs), and one straight down from above the
workspace, high enough to hold every object and region in view; all at the scene camera's
image size (a MuJoCo world renders one size).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from perception.segment import SegmentConfig, colour_labels
from tamp.camera.fit import FitConfig, Model, ObjectFit, fit_object, fold
from tamp.camera.geometry import backproject
from tamp.camera.poses import surface_normals
from tamp.scene import Pose
from tamp.sim.base import Camera, Lighting, Simulator
from tamp.world.schema import Scene

MARGIN = 0.06  # m the cameras' view reaches beyond the objects and regions
# the light the cameras look in: dimmer than the default, so that no lit face saturates (a
# saturated orange top face reads as yellow)
LIGHT = Lighting(direction=(-0.2, -0.1, -1.0), diffuse=0.5, ambient=0.3)


@dataclass(frozen=True)
class SceneCameraConfig:
    """Thresholds of `ScenePoses` (lengths in metres)."""

    agree: float = 0.985  # cosine: a normal is reliable where both neighbour pairs agree
    fixed_pad: float = 0.003  # points this near the table, a region or an obstacle are dropped
    link: float = 0.006  # points this near belong to one cluster
    snap: float = 0.006  # an object this near resting on something is set onto it
    light: Lighting = LIGHT
    fit: FitConfig = FitConfig()  # noqa: RUF009 (frozen)
    segment: SegmentConfig = SegmentConfig()


def scene_cameras(scene: Scene, base: Camera) -> tuple[Camera, ...]:
    """The cameras that look at ``scene`` (see the module docstring): ``base`` (the scene's
    camera), its mirror image across the workspace's middle in y, and an overhead camera."""
    lo, hi, top = _workspace(scene)
    cx, cy = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2
    mirror = replace(
        base,
        eye=(base.eye[0], 2 * cy - base.eye[1], base.eye[2]),
        target=(base.target[0], 2 * cy - base.target[1], base.target[2]),
    )
    # straight down, image up along +x: rows span x, columns y
    half_v = math.tan(math.radians(base.fovy) / 2)
    half_u = half_v * base.width / base.height
    height = max((hi[0] - lo[0]) / 2 / half_v, (hi[1] - lo[1]) / 2 / half_u)
    overhead = replace(base, eye=(cx, cy, top + height), target=(cx, cy, 0.0), up=(1.0, 0.0, 0.0))
    return (base, mirror, overhead)


def _workspace(scene: Scene) -> tuple[tuple[float, float], tuple[float, float], float]:
    """The (x, y) corners of the rectangle holding every object and region, grown by
    `MARGIN`, and the height of the tallest object's top."""
    xs, ys, top = [], [], 0.0
    for o in scene.objects:
        r = math.hypot(o.half[0], o.half[1])
        xs += [o.pose.xyz[0] - r, o.pose.xyz[0] + r]
        ys += [o.pose.xyz[1] - r, o.pose.xyz[1] + r]
        top = max(top, o.top)
    for region in scene.regions:
        xs += [region.lo[0], region.hi[0]]
        ys += [region.lo[1], region.hi[1]]
    return (min(xs) - MARGIN, min(ys) - MARGIN), (max(xs) + MARGIN, max(ys) + MARGIN), top


@dataclass
class _Cloud:
    """Points of one colour pooled over the cameras: world points (M, 3), normals (M, 3),
    reliable (M,)."""

    points: np.ndarray
    normals: np.ndarray
    reliable: np.ndarray

    def take(self, keep: np.ndarray) -> _Cloud:
        return _Cloud(self.points[keep], self.normals[keep], self.reliable[keep])


class ScenePoses:
    """The camera pose sensor of a scene's world in ``sim`` (see the module docstring).

    ``cameras``: the views (default `scene_cameras` of ``scene`` and ``sim``'s camera).
    Call it with the scene as last estimated (its poses are the previous estimates): every
    object's pose. ``unseen`` counts per object the calls that kept its previous estimate;
    ``looks`` counts the calls."""

    def __init__(
        self,
        sim: Simulator,
        scene: Scene,
        cameras: Sequence[Camera] | None = None,
        config: SceneCameraConfig = SceneCameraConfig(),
    ) -> None:
        self.sim, self.config = sim, config
        self.cameras = tuple(cameras) if cameras is not None else scene_cameras(scene, sim.camera)
        self.models = {o.name: Model(o.kind, o.half) for o in scene.objects}
        self.colours: list[tuple[float, float, float]] = []
        self.colour_of: dict[str, int] = {}
        for o in scene.objects:
            if o.rgb not in self.colours:
                self.colours.append(o.rgb)
            self.colour_of[o.name] = self.colours.index(o.rgb)
        self.fixed = scene
        self.unseen: Counter[str] = Counter()
        self.looks = 0
        # per look, its estimates' errors as the episode scores them (never read here)
        self.errors: list[dict] = []
        self.last: dict[str, Pose] = {}
        self._frames: tuple[float, list] | None = None

    def frames(self) -> list[tuple[Camera, np.ndarray, np.ndarray]]:
        """(camera, RGB (H, W, 3) uint8, z-depth (H, W) m) of every camera, rendered once per
        simulated instant; the simulator's own view is put back afterwards."""
        if self._frames is not None and self._frames[0] == self.sim.time:
            return self._frames[1]
        own, light = self.sim.camera, self.sim.lighting
        out = []
        try:
            for camera in self.cameras:
                self.sim.set_view(camera, self.config.light)
                out.append((camera, *self.sim.render_rgbd()))
        finally:
            self.sim.set_view(own, light)
        self._frames = (self.sim.time, out)
        return out

    def __call__(self, scene: Scene) -> dict[str, Pose]:
        """Every object's pose estimated from the cameras now; ``scene``'s poses are the
        previous estimates (identity among objects of one colour, yaw among a shape's
        equivalents, the pose kept for an object no camera sees)."""
        prior = {o.name: o.pose for o in scene.objects}
        clouds = self._clouds()
        fits: dict[str, ObjectFit] = {}
        for k, cloud in enumerate(clouds):
            names = [n for n, c in self.colour_of.items() if c == k]
            for name, part in self._identify(names, cloud, prior).items():
                found = fit_object(
                    part.points,
                    part.normals,
                    part.reliable,
                    self.models[name],
                    prior[name],
                    self.config.fit,
                )
                if found is not None:
                    fits[name] = found
        poses = self._settle(fits, prior)
        self.looks += 1
        for name in prior:
            if name not in fits:
                self.unseen[name] += 1
        self.last = poses
        return poses

    # ---- 1. pixels ------------------------------------------------------------------------
    def _clouds(self) -> list[_Cloud]:
        """Each object colour's points, pooled over the cameras."""
        parts: list[list[_Cloud]] = [[] for _ in self.colours]
        cross = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8)
        for camera, rgb, depth in self.frames():
            labels = colour_labels(rgb, self.colours, self.config.segment)  # (H, W)
            points = backproject(depth, camera)  # (H, W, 3)
            normals, reliable = surface_normals(points, self.config.agree)
            for k in range(len(self.colours)):
                mask = cv2.erode((labels == k).astype(np.uint8), cross).astype(bool)
                if not mask.any():
                    continue
                cloud = _Cloud(points[mask], normals[mask], reliable[mask])
                parts[k].append(cloud.take(~self._on_fixed(cloud.points)))
        out = []
        for chunks in parts:
            if chunks:
                out.append(
                    _Cloud(
                        np.concatenate([c.points for c in chunks]),
                        np.concatenate([c.normals for c in chunks]),
                        np.concatenate([c.reliable for c in chunks]),
                    )
                )
            else:
                out.append(_Cloud(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, bool)))
        return out

    def _on_fixed(self, points: np.ndarray) -> np.ndarray:
        """Which points (M, 3) lie on the fixed geometry: the table top, a region's surface,
        inside an obstacle (walls and base slabs too) grown by ``fixed_pad``. (M,) bool."""
        pad = self.config.fixed_pad
        out = points[:, 2] <= pad
        for r in self.fixed.regions:
            inside = np.all((points[:, :2] >= r.lo) & (points[:, :2] <= r.hi), axis=1)
            out |= inside & (points[:, 2] <= r.surface + pad)
            for box in (*r.walls(), r.slab()):
                if box is not None:
                    out |= _in_box(points, box, pad)
        for box in self.fixed.obstacles:
            out |= _in_box(points, box, pad)
        return out

    # ---- 2. identity ----------------------------------------------------------------------
    def _identify(
        self, names: list[str], cloud: _Cloud, prior: dict[str, Pose]
    ) -> dict[str, _Cloud]:
        """Which of ``cloud``'s points each object of one colour owns (see the module
        docstring); an object with no cluster is left out."""
        if len(cloud.points) < self.config.fit.min_points:
            return {}
        labels = _clusters(cloud.points, self.config.link)  # (M,)
        if len(names) == 1:
            name = names[0]
            size = 2 * max(self.models[name].half)
            centre = np.asarray(prior[name].xyz)
            groups = [labels == c for c in np.unique(labels)]
            groups = [g for g in groups if g.sum() >= self.config.fit.min_points] or groups
            middles = [np.median(cloud.points[g], axis=0) for g in groups]
            # the largest cluster, unless one nearer the previous estimate is as large as half
            main = max(range(len(groups)), key=lambda i: groups[i].sum())
            near = min(range(len(groups)), key=lambda i: np.linalg.norm(middles[i] - centre))
            if groups[near].sum() >= groups[main].sum() / 2:
                main = near
            keep = np.linalg.norm(cloud.points - middles[main], axis=1) <= size
            return {name: cloud.take(keep)}
        height = float(np.median([2 * self.models[n].half[2] for n in names]))
        area = float(
            np.median([4 * self.models[n].half[0] * self.models[n].half[1] for n in names])
        )
        parts = []
        for c in np.unique(labels):
            for layer in _layers(cloud.points, labels == c, height):
                parts += _split_xy(cloud.points, layer, area, len(names))
        parts = [p for p in parts if p.sum() >= self.config.fit.min_points]
        if not parts:
            return {}
        middles = np.array([np.median(cloud.points[p], axis=0) for p in parts])  # (P, 3)
        centres = np.array([prior[n].xyz for n in names])  # (N, 3)
        cost = np.linalg.norm(middles[:, None] - centres[None], axis=2)  # (P, N)
        rows, cols = linear_sum_assignment(cost)
        return {names[j]: cloud.take(parts[i]) for i, j in zip(rows, cols, strict=True)}

    # ---- 4. support -----------------------------------------------------------------------
    def _settle(self, fits: dict[str, ObjectFit], prior: dict[str, Pose]) -> dict[str, Pose]:
        """Every object's pose: fitted ones bottom up set onto what they rest on, the rest at
        their previous estimates."""
        poses = dict(prior)
        done: list[str] = []
        for name in sorted(fits, key=lambda n: fits[n].pose.xyz[2] - self.models[n].half[2]):
            fit, half = fits[name], self.models[name].half
            x, y, z = fit.pose.xyz
            surfaces = [0.0, *self._fixed_tops(x, y)]
            for other in done:
                o, oh = poses[other], self.models[other].half
                if math.dist(o.xyz[:2], (x, y)) <= max(oh[0], oh[1]):
                    surfaces.append(o.xyz[2] + oh[2])
            lo, hi = fit.z_range
            pad = self.config.snap
            fitting = [s + half[2] for s in surfaces if lo - pad <= s + half[2] <= hi + pad]
            if fitting:
                z = min(fitting, key=lambda h: abs(h - z))
            poses[name] = Pose((x, y, z), fit.pose.yaw)
            done.append(name)
        return poses

    def _fixed_tops(self, x: float, y: float) -> list[float]:
        """Heights of the fixed surfaces under (x, y): region surfaces and obstacle tops."""
        tops = [
            r.surface
            for r in self.fixed.regions
            if r.lo[0] <= x <= r.hi[0] and r.lo[1] <= y <= r.hi[1]
        ]
        for box in self.fixed.obstacles:
            local = _box_local(np.array([[x, y, box.centre[2]]]), box)[0]
            if abs(local[0]) <= box.half[0] and abs(local[1]) <= box.half[1]:
                tops.append(box.centre[2] + box.half[2])
        return tops


def _box_local(points: np.ndarray, box) -> np.ndarray:
    """Points (M, 3) in the frame of an obstacle box (its centre, turned by its yaw)."""
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    d = points - np.asarray(box.centre)
    return np.stack([d[:, 0] * c + d[:, 1] * s, -d[:, 0] * s + d[:, 1] * c, d[:, 2]], 1)


def _in_box(points: np.ndarray, box, pad: float) -> np.ndarray:
    """Which points (M, 3) lie inside ``box`` grown by ``pad``. (M,) bool."""
    return np.all(np.abs(_box_local(points, box)) <= np.asarray(box.half) + pad, axis=1)


def _clusters(points: np.ndarray, link: float) -> np.ndarray:
    """Cluster labels (M,): points linked by chains of neighbours within ``link``."""
    pairs = cKDTree(points).query_pairs(link, output_type="ndarray")  # (E, 2)
    m = len(points)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    return connected_components(graph, directed=False)[1]


def _layers(points: np.ndarray, member: np.ndarray, height: float) -> list[np.ndarray]:
    """A cluster (``member``, (M,) bool) split into layers of ``height`` from its top when
    it spans more than one object's height (objects of one colour stacked)."""
    z = points[member, 2]
    top, bottom = float(z.max()), float(z.min())
    count = max(1, round((top - bottom) / height))
    if count == 1:
        return [member]
    out = []
    for k in range(count):
        band = (points[:, 2] <= top - k * height + 1e-9) & (points[:, 2] > top - (k + 1) * height)
        if k == count - 1:
            band = points[:, 2] <= top - k * height + 1e-9
        out.append(member & band)
    return [m for m in out if m.any()]


def _split_xy(points: np.ndarray, member: np.ndarray, area: float, most: int) -> list[np.ndarray]:
    """A layer (``member``, (M,) bool) split by k-means in xy into as many parts as its
    footprint holds objects of ``area`` (m^2), at most ``most``."""
    xy = points[member, :2].astype(np.float32)  # (K, 2)
    cells = np.unique(np.floor(xy / 0.005).astype(np.int64), axis=0)
    count = min(most, max(1, round(len(cells) * 0.005**2 / area)), len(xy))
    if count == 1:
        return [member]
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-5)
    _, assigned, _ = cv2.kmeans(xy, count, None, criteria, 3, cv2.KMEANS_PP_CENTERS)
    index = np.flatnonzero(member)
    out = []
    for k in range(count):
        part = np.zeros_like(member)
        part[index[assigned.ravel() == k]] = True
        out.append(part)
    return out


def pose_errors(
    estimated: dict[str, Pose], truth: dict[str, Pose], scene: Scene
) -> dict[str, tuple[float, float | None]]:
    """Per object: (position error in mm, yaw error in degrees folded by the shape's symmetry,
    None for a cylinder) of ``estimated`` against ``truth``. For scoring only."""
    out = {}
    for o in scene.objects:
        est, true = estimated[o.name], truth[o.name]
        mm = 1000.0 * math.dist(est.xyz, true.xyz)
        period = Model(o.kind, o.half).symmetry
        yaw = None if period == 0 else abs(math.degrees(fold(est.yaw - true.yaw, period)))
        out[o.name] = (mm, yaw)
    return out
