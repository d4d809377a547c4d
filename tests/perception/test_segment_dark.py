"""The dark (black) block class and small images: shadows, dark floors, near-touching towers.

Images are drawn with numpy/OpenCV: shaded cylinder-ish rectangles (an elliptical top, light
falling off across the width) on a grey floor with soft cast shadows and sensor grain, at
150x100 and downscaled to 45x30 with ``cv2.INTER_AREA`` as LatPlan's small images are.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from perception.errors import PerceptionError
from perception.segment import SegmentConfig, colour_labels, find_boxes, scaled_min_area

RED, BLUE, GREEN, BLACK = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (0.0, 0.0, 0.0)
LATPLAN = [RED, BLUE, GREEN, BLACK]
W, H = 150, 100  # LatPlan's large images; its small ones are 45x30
SIDE = 17  # a block's width and visible height in pixels at 150x100


def _floor(grey: int, h: int = H, w: int = W) -> np.ndarray:
    """(H, W) float floor brightness: ``grey`` with a gentle top-to-bottom falloff."""
    return np.full((h, w), float(grey)) * np.linspace(0.9, 1.05, h)[:, None]


def _shadow(floor: np.ndarray, x0: int, y0: int, x1: int, y1: int, depth: float = 0.4):
    """Dims ``floor`` in place by ``depth`` at the core of a soft-edged box (a cast shadow;
    `SegmentConfig.dark_ratio` assumes shadows keep more than half the floor's light)."""
    mask = np.zeros(floor.shape, np.float32)
    cv2.rectangle(mask, (x0, y0), (x1 - 1, y1 - 1), 1.0, -1)
    mask = cv2.GaussianBlur(mask, (0, 0), 2.0)
    floor *= 1.0 - depth * mask


def _draw(floor: np.ndarray, blocks, seed: int = 0) -> np.ndarray:
    """RGB uint8 image: grey ``floor`` (H, W) with cylinder-ish blocks [(rgb, x0, y0)], each
    SIDE wide, SIDE tall and lit from the left, plus sensor grain."""
    img = np.repeat(floor[..., None], 3, axis=2)  # (H, W, 3)
    shade = np.linspace(1.0, 0.6, SIDE)  # (SIDE,) light falls off across the cylinder
    for rgb, x0, y0 in blocks:
        lit = 25.0 + 200.0 * np.asarray(rgb)  # black rubber still reflects a little
        img[y0 : y0 + SIDE, x0 : x0 + SIDE] = shade[None, :, None] * lit  # (SIDE, SIDE, 3)
        cx, cy = x0 + SIDE // 2, y0
        cv2.ellipse(img, (cx, cy), (SIDE // 2, 3), 0, 180, 360, tuple(1.1 * lit), -1)  # top
    img += np.random.default_rng(seed).normal(0.0, 3.0, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def _small(img: np.ndarray) -> np.ndarray:
    return cv2.resize(img, (45, 30), interpolation=cv2.INTER_AREA)


def _true_box(x0: int, y0: int) -> list[float]:
    return [x0, y0 - 3, x0 + SIDE, y0 + SIDE]  # the elliptical top rises 3 px above y0


@pytest.mark.parametrize("grey", [120, 70])  # mid-grey and dark-grey floors
def test_a_black_block_is_found_beside_its_soft_shadow(grey):
    floor = _floor(grey)
    _shadow(floor, 80, 52, 110, 78)  # cast to the right, touching the block
    img = _draw(floor, [(BLACK, 64, 60)])
    box = find_boxes(img, [BLACK])[0]
    np.testing.assert_allclose(box, _true_box(64, 60), atol=1.5)


@pytest.mark.parametrize("grey", [120, 70])
def test_a_shadow_alone_is_not_a_block(grey):
    floor = _floor(grey)
    _shadow(floor, 60, 50, 100, 80)
    img = _draw(floor, [(RED, 20, 60)])
    with pytest.raises(PerceptionError, match=r"block\(s\) black not found"):
        find_boxes(img, [RED, BLACK], names=["red", "black"])


@pytest.mark.parametrize("grey", [45, 25])  # floors as dark as the block's own colour
def test_a_uniformly_dark_floor_is_not_a_block(grey):
    img = _draw(_floor(grey), [])
    assert (colour_labels(img, [BLACK]) == -1).mean() > 0.99
    with pytest.raises(PerceptionError, match="not found"):
        find_boxes(img, [BLACK])


# towers 1 px apart: (rgb, x0, y0) of each block at 150x100
TOWERS = {
    "two towers": [(RED, 50, 70), (BLACK, 50, 53), (BLUE, 68, 70), (GREEN, 68, 53)],
    "four in a row": [(RED, 30, 70), (BLUE, 48, 70), (GREEN, 66, 70), (BLACK, 84, 70)],
    "black under": [(BLACK, 50, 70), (RED, 50, 53), (GREEN, 68, 70), (BLUE, 86, 70)],
    "tall tower": [(BLACK, 66, 76), (BLUE, 66, 59), (RED, 66, 42), (GREEN, 84, 76)],
}


@pytest.mark.parametrize("layout", sorted(TOWERS))
@pytest.mark.parametrize("grey", [120, 70])
def test_near_touching_towers_at_150x100_and_45x30(layout, grey):
    blocks = TOWERS[layout]
    floor = _floor(grey)
    for _, x0, y0 in blocks:  # each block casts a soft shadow down and to the right
        _shadow(floor, x0 + 4, y0 + 4, x0 + SIDE + 6, y0 + SIDE + 3)
    img = _draw(floor, blocks)
    colours = [rgb for rgb, _, _ in blocks]
    truth = np.asarray([_true_box(x0, y0) for _, x0, y0 in blocks], np.float32)  # (4, 4)
    # a block on top of another hides the lower one's elliptical top
    big = find_boxes(img, colours)
    np.testing.assert_allclose(big[:, [0, 2, 3]], truth[:, [0, 2, 3]], atol=1.5)
    small = find_boxes(_small(img), colours)
    scale = 45 / 150
    np.testing.assert_allclose(small[:, [0, 2, 3]], scale * truth[:, [0, 2, 3]], atol=1.2)


def test_columns_stay_apart_at_45x30():
    blocks = TOWERS["four in a row"]
    small = find_boxes(_small(_draw(_floor(110), blocks)), [rgb for rgb, _, _ in blocks])
    assert (small[:-1, 2] <= small[1:, 0] + 1).all()  # each box ends where the next begins


def test_adding_the_dark_class_keeps_vivid_boxes():
    blocks = [(RED, 50, 70), (BLUE, 50, 53), (GREEN, 90, 70)]
    img = _draw(_floor(110, 120, 160), blocks)
    colours = [rgb for rgb, _, _ in blocks]
    alone = find_boxes(img, colours)
    with pytest.raises(PerceptionError, match=r"block\(s\) #3 not found"):
        find_boxes(img, [*colours, BLACK])
    img = _draw(_floor(110, 120, 160), [*blocks, (BLACK, 110, 70)])
    np.testing.assert_array_equal(find_boxes(img, [*colours, BLACK])[:3], alone)


def test_min_area_scales_below_the_cube_resolution_only():
    assert scaled_min_area((120, 160)) == scaled_min_area((240, 320, 3)) == 12
    assert scaled_min_area((100, 150)) == 9
    assert scaled_min_area((30, 45)) == SegmentConfig().min_area_floor


@pytest.mark.parametrize(
    "colours, message",
    [
        ([RED, (0.6, 0.6, 0.6)], "neither vivid"),
        ([BLACK, (0.1, 0.1, 0.2)], "at most one dark block"),
    ],
)
def test_colours_that_cannot_be_segmented_are_named_in_one_line(colours, message):
    with pytest.raises(PerceptionError, match=message) as err:
        find_boxes(_draw(_floor(110), []), colours)
    assert "\n" not in str(err.value)
