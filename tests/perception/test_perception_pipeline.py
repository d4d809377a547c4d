"""Segmentation, dataset files, training, checkpoints and soft beliefs for the planner.

Images here are drawn with OpenCV (coloured squares on grey), so no simulator is needed.
"""

from __future__ import annotations

import random

import cv2
import numpy as np
import pytest
import torch

from perception import data as pdata
from perception.errors import PerceptionError
from perception.model import ModelConfig, SupportModel
from perception.perceive import Perceiver, blur, kl_rows
from perception.segment import find_boxes
from perception.train import TrainConfig, evaluate, load_checkpoint, save_checkpoint, train

RGB = [(0.85, 0.1, 0.1), (0.1, 0.25, 0.9), (1.0, 0.55, 0.05)]  # red, blue, orange


def _image(squares) -> np.ndarray:
    """Grey (H=120, W=160) image with filled squares: [(rgb, x0, y0, size)]."""
    img = np.full((120, 160, 3), 110, np.uint8)
    for rgb, x, y, s in squares:
        colour = tuple(int(255 * c) for c in rgb)
        cv2.rectangle(img, (x, y), (x + s - 1, y + s - 1), colour, -1)
    return img


def _tower_image():
    # blue on red (stacked), orange alone on the table
    return _image([(RGB[0], 40, 70, 16), (RGB[1], 40, 54, 16), (RGB[2], 100, 70, 16)])


def test_colour_boxes_are_found_where_the_blocks_are():
    boxes = find_boxes(_tower_image(), RGB)  # within the 2x2 opening's one-pixel shift
    np.testing.assert_allclose(boxes[0], [40, 70, 56, 86], atol=1)
    np.testing.assert_allclose(boxes[1], [40, 54, 56, 70], atol=1)
    np.testing.assert_allclose(boxes[2], [100, 70, 116, 86], atol=1)


def test_a_missing_block_is_named_in_one_line():
    img = _image([(RGB[0], 40, 70, 16), (RGB[2], 100, 70, 16)])  # blue hidden
    with pytest.raises(PerceptionError, match=r"block\(s\) b not found") as err:
        find_boxes(img, RGB, names=["a", "b", "c"])
    assert "\n" not in str(err.value)


def test_a_grey_robot_and_table_are_never_blocks():
    img = _image([])
    cv2.rectangle(img, (10, 10), (60, 60), (235, 235, 235), -1)  # light grey, like the Panda
    with pytest.raises(PerceptionError):
        find_boxes(img, RGB[:1])


@pytest.mark.parametrize("bad", [np.zeros((10, 10)), np.zeros((10, 10, 3), np.float32)])
def test_bad_images_raise_one_line_errors(bad):
    with pytest.raises(PerceptionError, match="image must be"):
        find_boxes(bad, RGB)


def test_blur_keeps_shape_and_type_and_widens_boxes():
    img = _tower_image()
    soft = blur(img, 6)
    assert soft.shape == img.shape and soft.dtype == np.uint8
    assert blur(img, 0) is img
    wide, sharp = find_boxes(soft, RGB), find_boxes(img, RGB)
    assert (wide[:, 2:] - wide[:, :2] >= sharp[:, 2:] - sharp[:, :2]).all()


def _dataset(m: int = 8) -> pdata.SupportData:
    images = np.stack([_tower_image()] * m)
    colours = np.tile(np.array([[0, 1, 2, -1]], np.int8), (m, 1))
    # block 0 (red) on the table, block 1 (blue) on block 0, block 2 (orange) on the table
    supports = np.tile(np.array([[pdata.TABLE, 0, pdata.TABLE, pdata.PAD]], np.int8), (m, 1))
    return pdata.SupportData(images, colours, supports, np.asarray(RGB, np.float32), {"x": 1})


def test_dataset_round_trip_and_tensors(tmp_path):
    path = pdata.save(tmp_path / "d.npz", _dataset())
    back = pdata.load(path)
    assert back.meta == {"x": 1} and len(back) == 8 and back.slots == 4
    t = pdata.tensors(back)
    assert t["images"].shape == (8, 3, 120, 160) and t["images"].dtype == torch.uint8
    assert t["boxes"].shape == (8, 4, 4)
    assert t["mask"][0].tolist() == [True, True, True, False]
    assert t["target"][0].tolist() == [4, 0, 4, 4]  # the table is column S = 4


@pytest.mark.parametrize("kind", ["png", "npz of other arrays"])
def test_a_file_that_is_no_dataset_says_what_a_dataset_file_is(tmp_path, kind):
    """Never numpy's advice to unpickle the file: what was given is not a dataset file."""
    if kind == "png":
        path = tmp_path / "picture.png"
        cv2.imwrite(str(path), np.zeros((8, 8, 3), np.uint8))
    else:
        path = tmp_path / "other.npz"
        np.savez(path, x=np.zeros(3))
    with pytest.raises(PerceptionError) as caught:
        pdata.load(path)
    text = str(caught.value)
    assert "is not a support dataset" in text and "`tamp perception dataset` writes" in text
    assert "pickle" not in text and "\n" not in text


def test_a_missing_dataset_or_checkpoint_is_a_one_line_error(tmp_path):
    with pytest.raises(PerceptionError, match="no dataset at"):
        pdata.load(tmp_path / "none.npz")
    with pytest.raises(PerceptionError, match="no perception checkpoint"):
        load_checkpoint(tmp_path / "none.pt")
    (tmp_path / "junk.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(PerceptionError, match=r"junk\.pt: not a perception checkpoint"):
        load_checkpoint(tmp_path / "junk.pt")


def _scene(rng: random.Random) -> tuple[np.ndarray, np.ndarray]:
    """A random 3-block scene: towers in 4 jittered columns. Returns (image, supports (4,))."""
    order = [0, 1, 2]
    rng.shuffle(order)
    towers: list[list[int]] = []
    for b in order:  # each block starts a tower or goes on top of one
        k = rng.randrange(len(towers) + 1)
        towers.append([b]) if k == len(towers) else towers[k].append(b)
    supports = np.full(4, pdata.PAD, np.int8)
    squares = []
    for tower, column in zip(towers, rng.sample(range(4), len(towers)), strict=False):
        x = 8 + 38 * column + rng.randrange(12)
        for level, b in enumerate(tower):
            squares.append((RGB[b], x, 70 - 16 * level, 16))
            supports[b] = pdata.TABLE if level == 0 else tower[level - 1]
    return _image(squares), supports


def _scenes(m: int, seed: int) -> pdata.SupportData:
    rng = random.Random(seed)
    images, supports = zip(*(_scene(rng) for _ in range(m)), strict=True)
    colours = np.tile(np.array([[0, 1, 2, -1]], np.int8), (m, 1))
    palette = np.asarray(RGB, np.float32)
    return pdata.SupportData(np.stack(images), colours, np.stack(supports), palette, {})


SMALL = ModelConfig(channels=(8, 8), dim=16, bands=2)


@pytest.fixture(scope="module")
def trained():
    """A small model trained on 32 random scenes (seed 1); its data and per-epoch losses."""
    t = pdata.tensors(_scenes(32, seed=1))
    losses: list[float] = []
    model = train(t, TrainConfig(epochs=30, batch=8, lr=1e-2), SMALL, lambda k, x: losses.append(x))
    return model, t, losses


def test_training_lowers_the_loss_and_reads_held_out_scenes(trained):
    model, t, losses = trained
    assert len(losses) == 30 and losses[-1] < 0.3 * losses[0]  # from ~ln 3 = 1.1 to ~0.07
    held_out = pdata.tensors(_scenes(64, seed=999))  # other layouts than the training scenes
    assert held_out["dropped"] == 0 and held_out["mask"].sum() == 192
    train_images = {img.numpy().tobytes() for img in t["images"]}
    assert not any(img.numpy().tobytes() in train_images for img in held_out["images"])
    table = held_out["target"] == 4
    baseline = float((table & held_out["mask"]).sum()) / 192  # "every block on the table"
    assert baseline == pytest.approx(0.625)
    scores = evaluate(model, held_out)
    assert scores["blocks"] == 192 and scores["scenes"] == 64
    # Measured: 0.81-0.97 over training seeds 0-3 and training sets 1-2 (0.92 for this one);
    # chance is about 1/3 (two other blocks or the table), "all on the table" scores 0.625.
    assert scores["relation_accuracy"] >= 0.75


def test_the_checkpoint_round_trips(tmp_path, trained):
    model, t, _ = trained
    path = save_checkpoint(tmp_path / "m.pt", model, {"seed": 0})
    again, meta = load_checkpoint(path)
    assert meta == {"seed": 0} and again.config == SMALL
    x = (t["images"].float() / 255, t["boxes"], t["mask"])
    torch.testing.assert_close(again(*x), model(*x))


def test_kl_anchor_is_zero_at_the_anchor_and_positive_elsewhere():
    F = torch.softmax(torch.randn(2, 3, 4), -1)
    mask = torch.ones(2, 3, dtype=torch.bool)
    torch.testing.assert_close(kl_rows(F, F, mask), torch.zeros(2))
    G = torch.softmax(torch.randn(2, 3, 4), -1)
    assert (kl_rows(F, G, mask) > 0).all()


def test_perceiver_inputs_pad_to_the_largest_scene():
    torch.manual_seed(0)
    perceiver = Perceiver(SupportModel(ModelConfig(channels=(8,), dim=8)))
    images, boxes, mask = perceiver.inputs([_tower_image()] * 2, [RGB, RGB[:2]])
    assert images.shape == (2, 3, 120, 160) and boxes.shape == (2, 3, 4)
    assert mask.tolist() == [[True, True, True], [True, True, False]]
    F = perceiver.support((images, boxes, mask))
    assert F.shape == (2, 3, 4)
    with pytest.raises(PerceptionError, match="images differ in size"):
        perceiver.inputs([_tower_image(), _tower_image()[:100]], [RGB, RGB])


def test_datasets_of_two_resolutions_load_as_one_at_the_first_size(tmp_path):
    big = _dataset(4)
    small = pdata.SupportData(
        np.stack([cv2.resize(im, (48, 36), interpolation=cv2.INTER_AREA) for im in big.images]),
        big.colours,
        big.supports,
        big.palette,
        {"y": 2},
    )
    a, b = pdata.save(tmp_path / "a.npz", big), pdata.save(tmp_path / "b.npz", small)
    both = pdata.load_many(f"{a},{b}")
    assert both.images.shape == (8, 120, 160, 3) and len(both.meta["parts"]) == 2
    assert (both.supports[4:] == big.supports).all()
    assert pdata.load_many([b]).images.shape[1:3] == (36, 48)  # one file: as it is
    other = pdata.SupportData(big.images, big.colours, big.supports, big.palette[::-1], {})
    with pytest.raises(PerceptionError, match="palette differs"):
        pdata.load_many([a, pdata.save(tmp_path / "c.npz", other)])
    # a perceiver trained at one input size reads a small image at that size
    perceiver = Perceiver(SupportModel(ModelConfig()), input_hw=(120, 160))
    images, boxes, _ = perceiver.inputs([small.images[0]], [RGB])
    assert images.shape[-2:] == (120, 160)
    assert boxes.shape == (1, 3, 4) and float(boxes[..., 2].max()) > 48
