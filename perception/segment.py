"""Entity regions from an image by colour: one bounding box per block, found with OpenCV.

Two kinds of block colour are looked for:

- vivid colours (saturated and bright, like every cube colour): a pixel belongs to such a block
  when it is saturated and bright enough (the grey table and the light-grey robot are not) and,
  among the vivid colours looked for, the block's hue is the nearest to the pixel's, within
  ``hue_tol`` (nearest, so that neighbouring hues such as orange and yellow never share a pixel);
- one dark colour (every RGB channel at most ``dark_colour_max``, e.g. black): hue means nothing
  there, so a pixel belongs to it when it is dark (``dark_value``), nearly grey (``dark_chroma``)
  and much darker than its local background: at most ``dark_ratio`` of the median brightness
  around it, and at least ``dark_contrast`` grey levels below it. The ratio is what keeps
  shadows and a dark floor out: it assumes that a soft shadow keeps more than half of the
  floor's brightness (fill light and bounces reach it) while a black surface under the same
  light reflects well under half. A shadow deeper than that, next to no black block, would be
  taken for one. The contrast is what keeps a black (or nearly black) image out: there a pixel
  of value 0 is "at most half" of a background of 0, and every pixel used to be the black block.

A block's region is the largest connected component of its pixels after a small morphological
opening; a region over ``max_area_share`` of the image is the background, not a block (a block
is a small part of any scene here, and an image of one colour shows none). The opening and
``min_area`` scale with the image: the 2x2 opening is skipped on images whose shorter side is
below ``open_min_side`` (at 45x30 a block is about 5 pixels wide), and ``min_area`` shrinks
with the image area below ``ref_area`` (never under ``min_area_floor``), so results at the cube
scenes' resolutions (160x120 and more) are unchanged. When no dark colour is looked for, labels
are exactly as they were before the dark class existed.

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
    min_area: int = 12  # pixels a block must show to count as found, on images of >= ref_area
    ref_area: int = 160 * 120  # below this image area, min_area shrinks in proportion ...
    min_area_floor: int = 3  # ... but never below this many pixels
    open_min_side: int = 60  # the 2x2 opening runs only when the shorter side has this many px
    max_area_share: float = 0.25  # a larger region of one colour is background, not a block
    dark_colour_max: float = 0.3  # a colour with every RGB channel <= this is looked for as dark
    dark_value: int = 70  # dark pixels: V (max channel) at most this ...
    dark_chroma: int = 32  # ... max - min channel below this (with a dark colour looked for,
    # vivid pixels need at least this spread, so a dark pixel is never given a hue) ...
    dark_ratio: float = 0.5  # ... and V at most this share of the local background's V,
    dark_contrast: int = 10  # ... and at least this many grey levels below it,
    background_window: float = 0.5  # the median V over a square of this share of the short side


def hue_of(rgb: Sequence[float]) -> int:
    """OpenCV hue (0..179) of an RGB colour in [0, 1]."""
    pixel = np.clip(np.asarray(rgb, dtype=np.float32) * 255.0, 0, 255).astype(np.uint8)
    return int(cv2.cvtColor(pixel.reshape(1, 1, 3), cv2.COLOR_RGB2HSV)[0, 0, 0])


def is_dark(rgb: Sequence[float], config: SegmentConfig = SegmentConfig()) -> bool:
    """Whether the colour (RGB in [0, 1]) is looked for as the dark class, not by hue."""
    return float(np.max(np.asarray(rgb, dtype=np.float64))) <= config.dark_colour_max


def check_image(image: np.ndarray) -> None:
    """One-line PerceptionError unless ``image`` is an RGB uint8 array (H, W, 3)."""
    if not isinstance(image, np.ndarray) or image.ndim != 3 or image.shape[2] != 3:
        shape = getattr(image, "shape", type(image).__name__)
        raise PerceptionError(f"an image must be an RGB array (H, W, 3), got shape {shape}")
    if image.dtype != np.uint8:
        raise PerceptionError(f"an image must be uint8 RGB, got dtype {image.dtype}")


def _split_colours(colours: Sequence[Sequence[float]], config: SegmentConfig) -> int | None:
    """Index of the one dark colour (None if none); one-line errors for pale or 2 dark ones."""
    dark = []
    for k, rgb in enumerate(colours):
        if is_dark(rgb, config):
            dark.append(k)
            continue
        pixel = np.clip(np.asarray(rgb, dtype=np.float32) * 255.0, 0, 255).astype(np.uint8)
        _, s, v = cv2.cvtColor(pixel.reshape(1, 1, 3), cv2.COLOR_RGB2HSV)[0, 0]
        if s < config.min_saturation or v < config.min_value:
            raise PerceptionError(
                f"colour #{k} {tuple(float(c) for c in rgb)} is neither vivid (saturation >= "
                f"{config.min_saturation}/255) nor dark (every channel <= "
                f"{config.dark_colour_max}): it cannot be segmented by colour"
            )
    if len(dark) > 1:
        raise PerceptionError(
            f"colours {', '.join(f'#{k}' for k in dark)} are all dark: segmentation tells at most "
            "one dark block apart"
        )
    return dark[0] if dark else None


def _dark_pixels(image: np.ndarray, value: np.ndarray, config: SegmentConfig) -> np.ndarray:
    """(H, W) bool: dark, nearly grey, and much darker than the median V around them (by
    ``dark_ratio`` and by ``dark_contrast`` grey levels)."""
    rgb = image.astype(np.int16)  # (H, W, 3)
    chroma = rgb.max(-1) - rgb.min(-1)  # (H, W)
    side = round(config.background_window * min(value.shape))
    k = max(3, side | 1)  # odd window
    background = cv2.medianBlur(value, k).astype(np.float32)  # (H, W) uint8 median, any k
    return (
        (value <= config.dark_value)
        & (chroma < config.dark_chroma)
        & (value <= config.dark_ratio * background)
        & (value <= background - config.dark_contrast)
    )


def colour_labels(
    image: np.ndarray, colours: Sequence[Sequence[float]], config: SegmentConfig = SegmentConfig()
) -> np.ndarray:
    """Per-pixel labels (H, W) int16: the index in ``colours`` (RGB in [0, 1]) of the block the
    pixel belongs to (nearest hue within ``hue_tol`` on saturated, bright pixels; the dark
    colour on dark, grey pixels darker than their surroundings); -1 elsewhere."""
    check_image(image)
    dark = _split_colours(colours, config)
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    h = hsv[..., 0].astype(np.int16)
    vivid = (hsv[..., 1] >= config.min_saturation) & (hsv[..., 2] >= config.min_value)
    if dark is not None:  # a hue only where the channels really differ
        rgb = image.astype(np.int16)  # (H, W, 3)
        vivid &= rgb.max(-1) - rgb.min(-1) >= config.dark_chroma
    bright = [k for k in range(len(colours)) if k != dark]
    hues = np.asarray([hue_of(colours[k]) for k in bright], dtype=np.int16)  # (M,)
    d = np.abs(h[..., None] - hues)  # (H, W, M)
    d = np.minimum(d, 180 - d)  # hue is circular
    nearest = d.argmin(-1) if len(hues) else np.zeros(h.shape, int)  # (H, W)
    close = vivid & (d.min(-1, initial=255) <= config.hue_tol)
    index = np.asarray([*bright, -1], dtype=np.int16)  # M -> -1 when no vivid colour
    labels = np.where(close, index[nearest], -1).astype(np.int16)  # (H, W)
    if dark is not None:
        labels[~close & _dark_pixels(image, hsv[..., 2], config)] = dark
    return labels


def scaled_min_area(shape: Sequence[int], config: SegmentConfig = SegmentConfig()) -> int:
    """Pixels a block must show in an image of ``shape`` (H, W, ...): ``min_area`` at
    ``ref_area`` pixels or more, in proportion to the area below it, at least ``min_area_floor``."""
    area = int(shape[0]) * int(shape[1])
    share = min(1.0, area / config.ref_area)
    return max(config.min_area_floor, round(config.min_area * share))


def _largest_regions(image, colours, config: SegmentConfig) -> list[tuple[tuple, int]]:
    """Per colour, the box (x0, y0, x1, y1) and pixel area of its largest connected region
    after the small opening (area 0 and a dummy box when the colour shows nowhere, or only as
    a region over ``max_area_share`` of the image: a background)."""
    labels = colour_labels(image, colours, config)  # (H, W)
    opening = min(image.shape[:2]) >= config.open_min_side
    kernel = np.ones((2, 2), np.uint8)
    out = []
    for k in range(len(colours)):
        mask = (labels == k).astype(np.uint8)
        if opening:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, kernel)
        count, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        if count < 2:
            out.append(((0.0, 0.0, 1.0, 1.0), 0))
            continue
        best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
        x, y, w, hh, area = (int(v) for v in stats[best])
        if area > config.max_area_share * mask.size:
            out.append(((0.0, 0.0, 1.0, 1.0), 0))
            continue
        out.append(((float(x), float(y), float(x + w), float(y + hh)), area))
    return out


def present(
    image: np.ndarray, colours: Sequence[Sequence[float]], config: SegmentConfig = SegmentConfig()
) -> list[bool]:
    """Whether each colour shows a region big enough to be a block (as `find_boxes` counts)."""
    check_image(image)
    min_area = scaled_min_area(image.shape, config)
    return [area >= min_area for _, area in _largest_regions(image, colours, config)]


def find_boxes(
    image: np.ndarray,
    colours: Sequence[Sequence[float]],
    names: Sequence[str] | None = None,
    config: SegmentConfig = SegmentConfig(),
) -> np.ndarray:
    """Boxes (N, 4) as (x0, y0, x1, y1) pixels, one per colour in ``colours`` (RGB in [0, 1]).

    Raises PerceptionError naming every block (``names``, default the colour index) that shows
    fewer than `scaled_min_area` pixels: occluded, out of view, or absent.
    """
    check_image(image)
    names = [f"#{i}" for i in range(len(colours))] if names is None else list(names)
    if len(names) != len(colours):
        raise PerceptionError(f"{len(names)} block names for {len(colours)} colours")
    min_area = scaled_min_area(image.shape, config)
    regions = _largest_regions(image, colours, config)
    missing = [name for name, (_, area) in zip(names, regions, strict=True) if area < min_area]
    if missing:
        raise PerceptionError(
            f"block(s) {', '.join(missing)} not found in the image (occluded, out of view or "
            f"absent): fewer than {min_area} pixels of their colour"
        )
    return np.asarray([box for box, _ in regions], dtype=np.float32).reshape(len(colours), 4)
