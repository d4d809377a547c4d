"""Rendered support datasets on disk, and the tensors the model trains on.

One compressed ``.npz`` file holds M samples:

- ``images`` (M, H, W, 3) uint8 RGB;
- ``colours`` (M, S) int8: palette index of each block of the sample, -1 after its last block;
- ``supports`` (M, S) int8: what each block rests on, as the block's position in the sample
  (0..n-1), ``TABLE`` (-1) for the table, ``PAD`` (-2) after the last block;
- ``palette`` (P, 3) float32 RGB in [0, 1], the colours the blocks may have;
- ``meta``: a JSON string saying how the file was made (command, seed, simulators).

Entity boxes are not stored: they come from `perception.segment` at load time, exactly as at
test time.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np
import torch
from torch import Tensor

from perception.errors import PerceptionError
from perception.segment import find_boxes

TABLE = -1
PAD = -2


@dataclass(frozen=True)
class SupportData:
    """A loaded dataset (see the module docstring for the arrays)."""

    images: np.ndarray
    colours: np.ndarray
    supports: np.ndarray
    palette: np.ndarray
    meta: dict

    def __len__(self) -> int:
        return len(self.images)

    @property
    def slots(self) -> int:
        """S, the most blocks a sample may have."""
        return self.colours.shape[1]


def save(path: str | Path, data: SupportData) -> Path:
    """Write ``data`` to ``path`` (``.npz``, compressed); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        path,
        images=data.images,
        colours=data.colours,
        supports=data.supports,
        palette=data.palette,
        meta=np.asarray(json.dumps(data.meta)),
    )
    return path


def load(path: str | Path) -> SupportData:
    """Read a dataset written by `save`; one-line PerceptionError if missing or malformed."""
    path = Path(path)
    if not path.is_file():
        raise PerceptionError(f"no dataset at {path} (make one with `tamp perception dataset`)")
    expected = (
        "expected a .npz archive of images, colours, supports, palette and meta, as "
        "`tamp perception dataset` writes"
    )
    if not zipfile.is_zipfile(path):  # an image, a checkpoint, text: np.load would unpickle
        raise PerceptionError(f"{path} is not a support dataset file ({expected})")
    try:
        with np.load(path, allow_pickle=False) as z:
            data = SupportData(
                z["images"], z["colours"], z["supports"], z["palette"], json.loads(str(z["meta"]))
            )
    except KeyError as err:
        raise PerceptionError(
            f"{path} is not a support dataset: {err.args[0]} ({expected})"
        ) from None
    except (ValueError, OSError, zipfile.BadZipFile) as err:
        raise PerceptionError(f"{path} is not a support dataset: {err} ({expected})") from None
    if data.images.ndim != 4 or data.colours.shape != data.supports.shape:
        raise PerceptionError(f"{path}: arrays of inconsistent shapes")
    return data


def resize_image(image: np.ndarray, hw: Sequence[int]) -> np.ndarray:
    """``image`` (H, W, 3) resized to ``hw`` = (H', W'): bilinear when enlarging, pixel-area
    averaging when shrinking; unchanged when already that size."""
    h, w = int(hw[0]), int(hw[1])
    if image.shape[:2] == (h, w):
        return image
    shrink = h * w < image.shape[0] * image.shape[1]
    return cv2.resize(image, (w, h), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)


def resize_data(data: SupportData, hw: Sequence[int]) -> SupportData:
    """``data`` with every image resized to ``hw`` = (H', W') (`resize_image`); the labels are
    unchanged (boxes are found on the images later, at their new size)."""
    return replace(data, images=np.stack([resize_image(im, hw) for im in data.images]))


def load_many(paths: str | Sequence[str | Path]) -> SupportData:
    """Datasets ``paths`` (a list, or one string of comma-separated files) as one, every image
    resized to the first file's size (`resize_image`): a model for several resolutions trains
    on all of them at one input size. Palettes and block counts must agree."""
    if isinstance(paths, str):
        paths = [p for p in paths.split(",") if p]
    parts = [load(p) for p in paths]
    if not parts:
        raise PerceptionError("no dataset files given")
    first = parts[0]
    for path, part in zip(paths[1:], parts[1:], strict=True):
        if part.palette.shape != first.palette.shape or not np.allclose(
            part.palette, first.palette
        ):
            raise PerceptionError(f"{path}: its palette differs from {paths[0]}'s")
        if part.slots != first.slots:
            raise PerceptionError(
                f"{path}: {part.slots} blocks per sample, {paths[0]} has {first.slots}"
            )
    if len(parts) == 1:
        return first
    hw = first.images.shape[1:3]
    images = np.concatenate([np.stack([resize_image(im, hw) for im in d.images]) for d in parts])
    meta = {
        **first.meta,
        "parts": [{"file": str(p), **d.meta} for p, d in zip(paths, parts, strict=True)],
    }
    return SupportData(
        images,
        np.concatenate([d.colours for d in parts]),
        np.concatenate([d.supports for d in parts]),
        first.palette,
        meta,
    )


def label_matrix(supports: np.ndarray, slots: int) -> np.ndarray:
    """Target column per block, (M, S) int64 in 0..S (S = the table column); padding -> S."""
    out = supports.astype(np.int64)
    return np.where(out < 0, slots, out)


def tensors(data: SupportData, indices: np.ndarray | None = None) -> dict[str, Tensor]:
    """Model inputs and labels of the chosen samples (all by default).

    images (M, 3, H, W) uint8; boxes (M, S, 4); mask (M, S) bool; target (M, S) long with the
    table at column S. A sample in which segmentation cannot find every block is left out
    (``dropped`` counts them). Boxes of padded slots are a
    dummy 1-pixel box.
    """
    idx = np.arange(len(data)) if indices is None else np.asarray(indices)
    s = data.slots
    kept, boxes = [], []
    for i in idx:
        n = int((data.colours[i] >= 0).sum())
        row = np.zeros((s, 4), dtype=np.float32)
        row[:, 2:] = 1.0
        try:
            row[:n] = find_boxes(data.images[i], data.palette[data.colours[i, :n]])
        except PerceptionError:
            continue
        kept.append(i)
        boxes.append(row)
    kept = np.asarray(kept, dtype=np.int64)
    images = torch.from_numpy(data.images[kept]).permute(0, 3, 1, 2)  # (M, 3, H, W) uint8
    return {
        "images": images,
        "boxes": torch.from_numpy(np.asarray(boxes, dtype=np.float32).reshape(len(kept), s, 4)),
        "mask": torch.from_numpy(data.colours[kept] >= 0),
        "target": torch.from_numpy(label_matrix(data.supports[kept], s)),
        "dropped": len(idx) - len(kept),
    }
