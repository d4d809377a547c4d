"""Block poses from an RGB-D image: segment each cube by colour, back-project it, fit the cube.

A block resting on the table or on another block shows at most its top face and two side faces.
Its pixels (`perception.segment.colour_labels`, eroded by one pixel so that no edge pixel mixes
two surfaces; where its colour shows up in two places more than a block apart, the place whose
hue is nearest) become world points (`tamp.camera.geometry.backproject`), and each point gets a
surface normal from its neighbours in the image, kept where the neighbours on both sides agree
(off creases and edges). The fit:

- yaw: the side faces' normals (their azimuths, folded into the cube's 90-degree symmetry);
  without side faces, the minimum-area rectangle of the top face in xy (`cv2.minAreaRect`);
- xy, each block axis on its own: a visible side face sits half a block from the centre along
  its normal; without one, the centre is the middle of the other side face's width (or of all
  the points' extent along that axis);
- z: the top face, half a block above the centre. A block whose top face is covered by the
  block on it takes its height from that block (one block lower), else from the middle of its
  side faces' height.

Side faces are what make a covered block (the lower blocks of a tower) measurable at all; its
xy is as good as its visible side faces. A block that shows too few pixels raises
`PerceptionError` naming it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np

from perception.errors import PerceptionError
from perception.segment import SegmentConfig, colour_labels, hue_of
from tamp.camera.geometry import backproject
from tamp.scene import Pose
from tamp.sim.base import Camera

QUARTER = math.pi / 2


@dataclass(frozen=True)
class PoseConfig:
    """Thresholds of the cube fit (lengths in metres)."""

    min_points: int = 12  # visible points (after erosion) a block needs
    min_face: int = 4  # reliable points a face needs to count as seen
    agree: float = 0.985  # cosine: a normal is reliable where both neighbour pairs agree (10 deg)
    top_nz: float = 0.95  # a top-face normal has at least this z component
    side_nz: float = 0.2  # a side-face normal has at most this |z| component
    face_axis: float = 0.95  # a side normal belongs to the face whose axis it is this near
    tol: float = 0.004  # a face may put the centre this far outside what the extent allows
    band: float = 0.6  # side faces showing this share of the block's height place it in z
    segment: SegmentConfig = SegmentConfig()


@dataclass(frozen=True)
class BlockFit:
    """One block's estimate and the evidence behind it: points, top-face and side-face points."""

    pose: Pose
    points: int
    top_points: int
    side_points: int
    covered: bool  # no top face seen: z came from the block on it or from the side faces
    seen_z: tuple[float, float]  # the lowest and highest visible side points (m)


def surface_normals(points: np.ndarray, agree: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (H, W, 3) of an organised point cloud (H, W, 3), facing the camera, and
    where they are reliable (H, W): the normals from the pixel's right-and-below and its
    left-and-above neighbours agree within ``agree`` (cosine), so no crease or edge is near."""
    ahead = np.cross(  # (H - 2, W - 2, 3) from the pixels right of and below each pixel
        points[1:-1, 2:] - points[1:-1, 1:-1], points[2:, 1:-1] - points[1:-1, 1:-1]
    )
    behind = np.cross(  # from the pixels left of and above
        points[1:-1, 1:-1] - points[1:-1, :-2], points[1:-1, 1:-1] - points[:-2, 1:-1]
    )
    ahead /= np.maximum(np.linalg.norm(ahead, axis=-1, keepdims=True), 1e-12)
    behind /= np.maximum(np.linalg.norm(behind, axis=-1, keepdims=True), 1e-12)
    both = ahead + behind  # image x right, y down: pointing away from the camera
    normals = np.zeros_like(points)
    normals[1:-1, 1:-1] = -both / np.maximum(np.linalg.norm(both, axis=-1, keepdims=True), 1e-12)
    reliable = np.zeros(points.shape[:2], dtype=bool)
    reliable[1:-1, 1:-1] = (ahead * behind).sum(-1) >= agree
    return normals, reliable


def _fold(angle: float) -> float:
    """An angle folded into the cube's symmetry, [-pi/4, pi/4)."""
    return (angle + QUARTER / 2) % QUARTER - QUARTER / 2


def _yaw(normals_xy: np.ndarray, top_xy: np.ndarray) -> float | None:
    """Yaw from side normals (K, 2) (mean of 4 x azimuth), else the top face's rectangle."""
    if len(normals_xy):
        four = 4.0 * np.arctan2(normals_xy[:, 1], normals_xy[:, 0])
        return _fold(math.atan2(np.sin(four).sum(), np.cos(four).sum()) / 4.0)
    if len(top_xy) >= 3:
        (_, _), (_, _), angle = cv2.minAreaRect(top_xy.astype(np.float32))
        return _fold(math.radians(angle))
    return None


def fit_block(
    points: np.ndarray,
    normals: np.ndarray,
    reliable: np.ndarray,
    size: float,
    config: PoseConfig = PoseConfig(),
) -> BlockFit | None:
    """A cube of edge ``size`` fitted to its visible points (M, 3), their normals (M, 3) and
    where those are reliable (M,); None when nothing fixes its yaw. A covered block's z comes
    from its side faces here; `estimate_fits` then takes it from the block on it, if any."""
    top = reliable & (normals[:, 2] >= config.top_nz)  # (M,)
    side = reliable & (np.abs(normals[:, 2]) <= config.side_nz)
    yaw = _yaw(normals[side, :2], points[top, :2])
    if yaw is None:
        return None
    c, s = math.cos(yaw), math.sin(yaw)
    axes = np.array([[c, s], [-s, c]])  # rows: the block's x and y axes in the world
    local = points[:, :2] @ axes.T  # (M, 2) coordinates along the block axes
    local_n = normals[:, :2] @ axes.T  # (M, 2)
    faces = [side & (np.abs(local_n[:, j]) >= config.face_axis) for j in range(2)]  # (M,) each
    seen = local[top | side] if (top | side).any() else local  # points off any crease
    centre = np.empty(2)
    for j in range(2):
        lo, hi = seen[:, j].max() - size / 2, seen[:, j].min() + size / 2  # they lie inside
        if faces[j].sum() >= config.min_face:
            sign = np.sign(np.median(local_n[faces[j], j]))
            centre[j] = np.median(local[faces[j], j]) - sign * size / 2
            if lo - config.tol <= centre[j] <= hi + config.tol:
                continue
        # no face along j: the middle of the other face's width (eroded alike on both edges)
        other = faces[1 - j] if faces[1 - j].sum() >= config.min_face else np.ones_like(top)
        centre[j] = (local[other, j].min() + local[other, j].max()) / 2
    x, y = centre @ axes  # back to the world
    covered = int(top.sum()) < config.min_face
    low, high = (float(v) for v in np.percentile(points[side if side.any() else ~top, 2], [1, 99]))
    if covered:  # the side faces: their middle when they show most of their height
        z = (low + high) / 2 if high - low >= config.band * size else high - size / 2
    else:
        z = float(np.median(points[top, 2])) - size / 2
    pose = Pose((float(x), float(y), z), yaw)
    return BlockFit(pose, len(points), int(top.sum()), int(side.sum()), covered, (low, high))


def _block_pixels(
    mask: np.ndarray, off: np.ndarray, points: np.ndarray, size: float, config: PoseConfig
) -> np.ndarray:
    """A block's pixels (H, W): its label ``mask`` eroded by one pixel (no edge pixel mixes two
    surfaces). Where the colour shows up in places more than a block apart (a lit face of a
    neighbouring hue), the region whose hue is nearest (``off``, (H, W)) wins, with whatever
    lies within a block of it."""
    cross = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8)
    mask = cv2.erode(mask.astype(np.uint8), cross)
    count, regions, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    big = [r for r in range(1, count) if stats[r, cv2.CC_STAT_AREA] >= config.min_points]
    if len(big) < 2:
        return mask.astype(bool)
    middles = {r: np.median(points[regions == r], axis=0) for r in big}  # (3,) each
    best = min(big, key=lambda r: np.median(off[regions == r]))
    keep = [r for r in big if np.linalg.norm(middles[r] - middles[best]) <= size]
    return np.isin(regions, keep)


def estimate_fits(
    rgb: np.ndarray,
    depth: np.ndarray,
    camera: Camera,
    entities: Sequence[str],
    colours: Sequence[Sequence[float]],
    block_size: float,
    config: PoseConfig = PoseConfig(),
) -> dict[str, BlockFit | str]:
    """Every entity's `BlockFit`, or a one-line reason why it has none (too few pixels)."""
    if len(entities) != len(colours):
        raise PerceptionError(f"{len(entities)} block names for {len(colours)} colours")
    labels = colour_labels(rgb, colours, config.segment)  # (H, W)
    hue = cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV)[..., 0].astype(np.int16)  # (H, W)
    points = backproject(depth, camera)  # (H, W, 3)
    normals, reliable = surface_normals(points, config.agree)  # (H, W, 3), (H, W)
    fits: dict[str, BlockFit | str] = {}
    for k, name in enumerate(entities):
        off = np.abs(hue - hue_of(colours[k]))
        mask = _block_pixels(labels == k, np.minimum(off, 180 - off), points, block_size, config)
        if mask.sum() < config.min_points:
            fits[name] = f"block {name} shows {int(mask.sum())} pixels, needs {config.min_points}"
            continue
        pts, nrm, ok = points[mask], normals[mask], reliable[mask]  # (M, 3), (M, 3), (M,)
        near = np.linalg.norm(pts - np.median(pts, axis=0), axis=1) <= block_size  # stray pixels
        fit = fit_block(pts[near], nrm[near], ok[near], block_size, config)
        fits[name] = fit if fit is not None else f"block {name} shows no face to fit"
    _settle_heights(fits, block_size, config)
    return fits


def _settle_heights(fits: dict[str, BlockFit | str], size: float, config: PoseConfig) -> None:
    """Heights of the blocks whose top face was not seen. Top down: a block with blocks over it
    sits one block below the lowest of them (so a tower's covered blocks chain from its top).
    Then bottom up: a block showing too little of its side faces to place it (behind another
    tower) rests on the table or on a block under it, whichever its visible band fits in."""
    names = [n for n, f in fits.items() if isinstance(f, BlockFit)]

    def z(n: str) -> float:
        return fits[n].pose.xyz[2]

    def near(a: str, b: str) -> bool:
        return math.dist(fits[a].pose.xyz[:2], fits[b].pose.xyz[:2]) <= size / 2

    def put(n: str, height: float) -> None:
        fits[n] = replace(fits[n], pose=Pose((*fits[n].pose.xyz[:2], height), fits[n].pose.yaw))

    loose = []
    for n in sorted(names, key=lambda n: -z(n)):
        low, high = fits[n].seen_z
        if not fits[n].covered:
            continue
        over = [z(o) for o in names if o != n and near(o, n) and z(o) > high + size / 4]
        if over:
            put(n, min(over) - size)
        elif high - low < config.band * size:
            loose.append(n)
    for n in sorted(loose, key=lambda n: fits[n].seen_z[0]):
        low, high = fits[n].seen_z
        bottoms = [0.0] + [z(o) + size / 2 for o in names if o != n and near(o, n)]
        fitting = [b for b in bottoms if b - config.tol <= low and high <= b + size + config.tol]
        if fitting:
            put(n, max(fitting) + size / 2)


def estimate_poses(
    rgb: np.ndarray,
    depth: np.ndarray,
    camera: Camera,
    entities: Sequence[str],
    colours: Sequence[Sequence[float]],
    block_size: float,
) -> dict[str, Pose]:
    """Block poses (centre, yaw in [-pi/4, pi/4)) from an RGB image (H, W, 3) uint8 and its
    z-depth (H, W) in metres seen by ``camera``; ``colours[i]`` (RGB in [0, 1]) is the colour of
    ``entities[i]``. Raises PerceptionError naming the first block not visible enough."""
    fits = estimate_fits(rgb, depth, camera, entities, colours, block_size)
    for fit in fits.values():
        if isinstance(fit, str):
            raise PerceptionError(f"{fit} (occluded, out of view or absent)")
    return {name: fit.pose for name, fit in fits.items()}
