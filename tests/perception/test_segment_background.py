"""An image of one colour shows no block: the dark class needs contrast with the background (a
black image used to be one big black block, as every pixel of value 0 is "at most half" of a
background of 0), and no region covering most of the image counts as a block."""

from __future__ import annotations

import numpy as np
import pytest

from perception.errors import PerceptionError
from perception.segment import colour_labels, find_boxes, present

RED, BLUE, GREEN, BLACK = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (0.0, 0.0, 0.0)
LATPLAN = [RED, BLUE, GREEN, BLACK]


def _uniform(rgb, noise: float = 0.0, shape=(100, 150)) -> np.ndarray:
    img = np.broadcast_to(np.asarray(rgb, float), (*shape, 3))
    img = img + np.random.default_rng(0).normal(0.0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("shape", [(100, 150), (30, 45)])
@pytest.mark.parametrize(("level", "noise"), [(0, 0.0), (0, 3.0), (6, 3.0), (15, 3.0)])
def test_a_black_or_nearly_black_image_has_no_black_block(shape, level, noise):
    img = _uniform((level, level, level), noise, shape)
    assert not (colour_labels(img, LATPLAN) >= 0).any()
    assert present(img, LATPLAN) == [False] * 4
    with pytest.raises(PerceptionError, match=r"block\(s\) red, blue, green, black not found"):
        find_boxes(img, LATPLAN, ["red", "blue", "green", "black"])


@pytest.mark.parametrize("rgb", [(220, 20, 20), (20, 200, 30)])
def test_an_image_of_one_vivid_colour_has_no_block_of_it(rgb):
    assert present(_uniform(rgb, 2.0), LATPLAN) == [False] * 4


def test_a_black_block_on_a_grey_floor_is_still_found():
    img = _uniform((110, 110, 110), 3.0)
    img[50:70, 60:78] = 20  # a black block, 18 x 20 px
    img[50:70, 90:108] = (200, 20, 20)  # and a red one
    boxes = find_boxes(img, [RED, BLACK])
    np.testing.assert_allclose(boxes, [[90, 50, 108, 70], [60, 50, 78, 70]], atol=1)
