"""One known object model fitted to its visible points: a box (cube or cuboid) or a cylinder.

The robot knows its object models (the scene file's kind, size and colour); what it measures
is where each one stands. Given the world points (M, 3) one object shows in the cameras, their
surface normals and where those are reliable (`tamp.camera.poses`'s normals: off creases and
edges), `fit_object` finds the centre (x, y, z) and, for a box, the yaw about z:

- yaw: the side faces' normals (their azimuths folded into the box's 90-degree symmetry),
  else the minimum-area rectangle of the top face; a box whose footprint is not square tries
  both ways its long side can lie and keeps the one its points fit better. A cylinder's yaw
  is not observable: it keeps the previous estimate's;
- x, y: a visible side face sits half the box's extent from the centre along its normal, else
  the middle of the points' extent along that axis (a cylinder: the middle of its top face,
  else of its points); then every parameter is refined by robust least squares on the model's
  signed distance (every visible point lies on the model's surface, `scipy.optimize`);
- z: the top face, half the height above the centre. Without a top face (an object on it, the
  hand over it), the lowest visible side point is taken for its bottom edge, and the visible
  side band bounds it: `ObjectFit.z_range` is every centre height the points allow, for
  `tamp.camera.scene_poses` to set the object onto what it rests on.

The yaw reported is the one of the model's symmetric equivalents (mod pi for a cuboid, mod pi/2
for a square footprint) nearest the previous estimate's, so it does not jump between them.
Numpy, OpenCV and SciPy only: nothing here renders or reads a simulator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import least_squares

from tamp.scene import Pose

QUARTER = math.pi / 2


@dataclass(frozen=True)
class Model:
    """An object's known shape: ``kind`` (cube, cuboid, cylinder) and half extents (x, y, z)
    in its own frame (a cylinder: radius, radius, half height)."""

    kind: str
    half: tuple[float, float, float]

    @property
    def symmetry(self) -> float:
        """The yaw period of the shape (rad): pi/2 for a square footprint, pi for a box, 0
        for a cylinder (every yaw alike)."""
        if self.kind == "cylinder":
            return 0.0
        return QUARTER if abs(self.half[0] - self.half[1]) < 5e-4 else math.pi


@dataclass(frozen=True)
class FitConfig:
    """Thresholds of the model fit (lengths in metres)."""

    min_points: int = 15  # visible points an object needs to be fitted
    min_face: int = 4  # reliable points a face needs to count as seen
    top_nz: float = 0.95  # a top-face normal has at least this z component
    side_nz: float = 0.2  # a side-face normal has at most this |z| component
    face_axis: float = 0.95  # a side normal belongs to the face whose axis it is this near
    tol: float = 0.004  # a face may put the centre this far outside what the extent allows
    scale: float = 0.002  # the robust loss's scale: points this far off the surface count less
    max_points: int = 1500  # points the least squares uses (an even subsample beyond)
    tie: float = 0.15  # fits whose residuals differ by less than this share are alike


@dataclass(frozen=True)
class ObjectFit:
    """One object's estimate: its pose, the points behind it (all, on the top face, on side
    faces) and ``z_range``, the centre heights its points allow (tight with a top face)."""

    pose: Pose
    points: int
    top_points: int
    side_points: int
    z_range: tuple[float, float]
    cost: float  # mean robust residual of the fit (m)


def fold(angle: float, period: float) -> float:
    """``angle`` folded into [-period / 2, period / 2)."""
    return (angle + period / 2) % period - period / 2


def nearest_equivalent(yaw: float, prior: float, period: float) -> float:
    """The yaw equivalent to ``yaw`` under the shape's ``period`` nearest ``prior``."""
    if period <= 0:
        return prior
    return prior + fold(yaw - prior, period)


def box_distance(local: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Signed distance (M,) of points (M, 3) in a box's frame to the box of half extents (3,)."""
    q = np.abs(local) - half  # (M, 3)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    return outside + np.minimum(q.max(axis=1), 0.0)


def cylinder_distance(local: np.ndarray, radius: float, half_h: float) -> np.ndarray:
    """Signed distance (M,) of points (M, 3) in a cylinder's frame to the upright cylinder."""
    d = np.stack([np.linalg.norm(local[:, :2], axis=1) - radius, np.abs(local[:, 2]) - half_h], 1)
    return np.linalg.norm(np.maximum(d, 0.0), axis=1) + np.minimum(d.max(axis=1), 0.0)


def _residuals(params: np.ndarray, points: np.ndarray, model: Model, yaw: float) -> np.ndarray:
    """Distances (M,) of ``points`` to ``model`` at ``params``: (x, y, z, yaw) for a box,
    (x, y, z) for a cylinder (``yaw`` unused)."""
    local = points - params[:3]  # (M, 3)
    if model.kind == "cylinder":
        return cylinder_distance(local, model.half[0], model.half[2])
    c, s = math.cos(params[3]), math.sin(params[3])
    x = local[:, 0] * c + local[:, 1] * s  # into the box's frame
    y = -local[:, 0] * s + local[:, 1] * c
    return box_distance(np.stack([x, y, local[:, 2]], 1), np.asarray(model.half))


def _yaw_guess(normals_xy: np.ndarray, top_xy: np.ndarray) -> float | None:
    """Yaw mod pi/2 from side normals (K, 2) (mean of 4 x azimuth), else the top face's
    rectangle (K, 2) of points; None when neither shows."""
    if len(normals_xy):
        four = 4.0 * np.arctan2(normals_xy[:, 1], normals_xy[:, 0])
        return fold(math.atan2(np.sin(four).sum(), np.cos(four).sum()) / 4.0, QUARTER)
    if len(top_xy) >= 3:
        (_, _), (_, _), angle = cv2.minAreaRect(top_xy.astype(np.float32))
        return fold(math.radians(angle), QUARTER)
    return None


def _box_centre(
    points: np.ndarray,
    normals: np.ndarray,
    side: np.ndarray,
    seen: np.ndarray,
    yaw: float,
    half: tuple[float, ...],
    config: FitConfig,
) -> np.ndarray:
    """The xy centre (2,) of a box at ``yaw`` from its side faces, else its points' extent."""
    c, s = math.cos(yaw), math.sin(yaw)
    axes = np.array([[c, s], [-s, c]])  # rows: the box's x and y axes in the world
    local = points[:, :2] @ axes.T  # (M, 2)
    local_n = normals[:, :2] @ axes.T  # (M, 2)
    faces = [side & (np.abs(local_n[:, j]) >= config.face_axis) for j in range(2)]
    ref = local[seen] if seen.any() else local
    centre = np.empty(2)
    for j in range(2):
        lo, hi = ref[:, j].max() - half[j], ref[:, j].min() + half[j]  # the points lie inside
        if faces[j].sum() >= config.min_face:
            sign = np.sign(np.median(local_n[faces[j], j]))
            centre[j] = np.median(local[faces[j], j]) - sign * half[j]
            if lo - config.tol <= centre[j] <= hi + config.tol:
                continue
        centre[j] = (ref[:, j].min() + ref[:, j].max()) / 2
    return centre @ axes


def _better(cost: float, off: float, best_cost: float, best_off: float, tie: float) -> bool:
    """Whether a fit of mean residual ``cost`` at ``off`` rad from the previous yaw beats
    the best so far: a clearly lower residual, else (within ``tie``, a footprint whose sides
    the points cannot tell apart) the yaw nearer the previous estimate's."""
    if abs(cost - best_cost) > tie * max(cost, best_cost):
        return cost < best_cost
    return off < best_off


def fit_object(
    points: np.ndarray,
    normals: np.ndarray,
    reliable: np.ndarray,
    model: Model,
    prior: Pose,
    config: FitConfig = FitConfig(),
) -> ObjectFit | None:
    """``model`` fitted to the points (M, 3) one object shows, their normals (M, 3) and where
    those are reliable (M,) (see the module docstring); None with fewer than
    ``config.min_points`` points. ``prior``: the previous estimate (its yaw picks among the
    symmetric equivalents, and is a cylinder's yaw)."""
    if len(points) < config.min_points:
        return None
    half = model.half
    top = reliable & (normals[:, 2] >= config.top_nz)  # (M,)
    side = reliable & (np.abs(normals[:, 2]) <= config.side_nz)
    seen = top | side
    if top.sum() >= config.min_face:
        z0 = float(np.median(points[top, 2])) - half[2]
        z_range = (z0 - config.tol / 2, z0 + config.tol / 2)
    else:
        high = float(np.percentile(points[:, 2], 99))
        low = float(np.percentile(points[:, 2], 1))
        z0 = low + half[2]  # the lowest visible edge: a held object's top is in the hand
        z_range = (high - half[2], max(low + half[2], high - half[2]))
    step = max(1, len(points) // config.max_points)
    sample = points[::step]  # (<= max_points, 3)
    if model.kind == "cylinder":
        ref = points[top] if top.sum() >= config.min_face else points
        x0 = np.array([*np.median(ref[:, :2], axis=0), z0])
        # the middle of the points is inside the disc, not its centre: start from the centre
        # of the points' extent, and let the distances to the surface pull it
        x0[:2] = (ref[:, :2].min(axis=0) + ref[:, :2].max(axis=0)) / 2
        found = least_squares(
            _residuals, x0, loss="soft_l1", f_scale=config.scale, args=(sample, model, 0.0)
        )
        x, y, z = found.x
        cost = float(np.mean(np.abs(found.fun)))
        return ObjectFit(
            Pose((float(x), float(y), float(z)), prior.yaw),
            len(points),
            int(top.sum()),
            int(side.sum()),
            z_range,
            cost,
        )
    guess = _yaw_guess(normals[side, :2], points[top, :2])
    if guess is None:
        guess = prior.yaw
    best = None
    turns = (0.0,) if model.symmetry == QUARTER else (0.0, QUARTER)
    for turn in turns:
        yaw = guess + turn
        xy = _box_centre(points, normals, side, seen, yaw, half, config)
        x0 = np.array([*xy, z0, yaw])
        found = least_squares(
            _residuals,
            x0,
            loss="soft_l1",
            f_scale=config.scale,
            x_scale=np.array([0.01, 0.01, 0.01, 0.1]),
            args=(sample, model, yaw),
        )
        cost = float(np.mean(np.abs(found.fun)))
        off = abs(fold(found.x[3] - prior.yaw, math.pi))  # from the previous estimate
        if best is None or _better(cost, off, best[1], best[2], config.tie):
            best = (found.x, cost, off)
    (x, y, z, yaw), cost, _ = best
    yaw = nearest_equivalent(float(yaw), prior.yaw, model.symmetry)
    return ObjectFit(
        Pose((float(x), float(y), float(z)), yaw),
        len(points),
        int(top.sum()),
        int(side.sum()),
        z_range,
        cost,
    )
