"""The stress ladder's image degradations: deterministic, bounded, and each does what it says."""

from __future__ import annotations

import numpy as np
import pytest

from perception.corrupt import POLE_GREY, Corruption
from perception.errors import PerceptionError
from perception.segment import find_boxes

RED, BLUE = (0.85, 0.1, 0.1), (0.1, 0.25, 0.9)


def _scene() -> np.ndarray:
    img = np.full((60, 80, 3), 110, np.uint8)
    img[30:46, 10:26] = (217, 25, 25)  # red block
    img[30:46, 50:66] = (25, 64, 230)  # blue block
    return img


def test_clear_is_the_identity_and_names_read_well():
    img = _scene()
    assert Corruption()(img, 3) is img
    assert Corruption().name == "clear"
    assert Corruption(blur=6, noise=8).name == "blur 6 + noise 8"
    assert Corruption(dim=0.35, occlude=True).name == "dim 0.35 + occluder"


def test_same_key_same_image_other_key_other_noise():
    img, c = _scene(), Corruption(noise=10)
    assert np.array_equal(c(img, 1), c(img, 1))
    assert not np.array_equal(c(img, 1), c(img, 2))
    assert abs(float(c(img, 1).astype(float).mean()) - float(img.mean())) < 2.0


def test_dimming_darkens_every_pixel_and_keeps_black_black():
    img = _scene()
    img[0, 0] = 0
    dim = Corruption(dim=0.35)(img)
    assert (dim <= img).all() and dim[0, 0].tolist() == [0, 0, 0]
    assert dim[5, 5, 0] < 0.7 * img[5, 5, 0]


def test_the_pole_covers_half_of_one_block_and_leaves_it_findable():
    img = _scene()
    boxes = find_boxes(img, [RED, BLUE])
    out = Corruption(occlude=True)(img, 7, boxes)
    covered = (out == POLE_GREY).all(axis=2).all(axis=0)  # (W,) whole columns of pole grey
    assert 6 <= covered.sum() <= 10  # half of a 16-pixel block
    found = find_boxes(out, [RED, BLUE])  # the other half still shows
    assert found.shape == (2, 4)


def test_bad_settings_are_one_line_errors():
    with pytest.raises(PerceptionError, match="0 < dim <= 1"):
        Corruption(dim=0.0)
    with pytest.raises(PerceptionError, match="noise >= 0"):
        Corruption(noise=-1)
