"""Entity regions from an image by colour: one bounding box per block, found with OpenCV.

Each block has its own saturated colour. A pixel belongs to a block when it is saturated and
bright enough (the grey table and the light-grey robot are not) and, among the colours looked
for, the block's hue is the nearest to the pixel's, within ``hue_tol`` (nearest, so that
neighbouring hues such as orange and yellow never share a pixel); the block's region is the
largest connected component of those pixels after a small morphological opening.
`colour_labels` gives the per-pixel labels behind the boxes (for fitting block poses to a depth
image). Nothing is read from a simulator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from perception.errors import PerceptionError


@dataclass(frozen=True)
class SegmentConfig:
    """Thresholds of the colour segmentation (OpenCV HSV: H in 0..179, S and V in 0..255)."""

    min_saturation: int = 90
    min_value: int = 35
    hue_tol: int = 9  # OpenCV hue units (2 degrees each)
    min_area: int = 12  # pixels a block must show to count as found


def hue_of(rgb: Sequence[float]) -> int:
    """OpenCV hue (0..179) of an RGB colour in [0, 1]."""
    pixel = np.clip(np.asarray(rgb, dtype=np.float32) * 255.0, 0, 255).astype(np.uint8)
    return int(cv2.cvtColor(pixel.reshape(1, 1, 3), cv2.COLOR_RGB2HSV)[0, 0, 0])


def check_image(image: np.ndarray) -> None:
    """One-line PerceptionError unless ``image`` is an RGB uint8 array (H, W, 3)."""
    if not isinstance(image, np.ndarray) or image.ndim != 3 or image.shape[2] != 3:
        shape = getattr(image, "shape", type(image).__name__)
        raise PerceptionError(f"an image must be an RGB array (H, W, 3), got shape {shape}")
    if image.dtype != np.uint8:
        raise PerceptionError(f"an image must be uint8 RGB, got dtype {image.dtype}")


def colour_labels(
    image: np.ndarray, colours: Sequence[Sequence[float]], config: SegmentConfig = SegmentConfig()
) -> np.ndarray:
    """Per-pixel labels (H, W) int16: the index in ``colours`` (RGB in [0, 1]) whose hue is the
    nearest to the pixel's, within ``hue_tol``, on saturated and bright pixels; -1 elsewhere."""
    check_image(image)
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    h = hsv[..., 0].astype(np.int16)
    vivid = (hsv[..., 1] >= config.min_saturation) & (hsv[..., 2] >= config.min_value)
    hues = np.asarray([hue_of(rgb) for rgb in colours], dtype=np.int16)  # (N,)
    d = np.abs(h[..., None] - hues)  # (H, W, N)
    d = np.minimum(d, 180 - d)  # hue is circular
    nearest = d.argmin(-1) if len(hues) else np.zeros(h.shape, int)  # (H, W)
    close = vivid & (d.min(-1, initial=255) <= config.hue_tol)
    return np.where(close, nearest, -1).astype(np.int16)


def find_boxes(
    image: np.ndarray,
    colours: Sequence[Sequence[float]],
    names: Sequence[str] | None = None,
    config: SegmentConfig = SegmentConfig(),
) -> np.ndarray:
    """Boxes (N, 4) as (x0, y0, x1, y1) pixels, one per colour in ``colours`` (RGB in [0, 1]).

    Raises PerceptionError naming every block (``names``, default the colour index) that shows
    fewer than ``min_area`` pixels: occluded, out of view, or absent.
    """
    check_image(image)
    names = [f"#{i}" for i in range(len(colours))] if names is None else list(names)
    if len(names) != len(colours):
        raise PerceptionError(f"{len(names)} block names for {len(colours)} colours")
    labels = colour_labels(image, colours, config)  # (H, W)
    kernel = np.ones((2, 2), np.uint8)
    boxes, missing = [], []
    for k, name in enumerate(names):
        mask = (labels == k).astype(np.uint8)
        mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, kernel)
        count, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        if count < 2:
            missing.append(name)
            boxes.append((0.0, 0.0, 1.0, 1.0))
            continue
        best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
        x, y, w, hh, area = (int(v) for v in stats[best])
        if area < config.min_area:
            missing.append(name)
        boxes.append((float(x), float(y), float(x + w), float(y + hh)))
    if missing:
        raise PerceptionError(
            f"block(s) {', '.join(missing)} not found in the image (occluded, out of view or "
            f"absent): fewer than {config.min_area} pixels of their colour"
        )
    return np.asarray(boxes, dtype=np.float32).reshape(len(colours), 4)
