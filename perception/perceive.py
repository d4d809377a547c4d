"""From RGB images to soft support matrices: segmentation, model inputs, KL anchors, blur.

`Perceiver` wraps a trained `SupportModel`: ``inputs`` finds each block's box by its colour
and stacks the images; ``support`` runs the model, on the perceiver's ``device`` (the CPU unless
told, e.g. "cuda"). Everything after segmentation is a torch
function of the images and the weights, so planning losses can reach the weights.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np
import torch
from torch import Tensor

from perception.data import resize_image
from perception.errors import PerceptionError
from perception.model import SupportModel
from perception.segment import SegmentConfig, check_image, find_boxes
from perception.train import as_float, load_checkpoint, torch_device


def blur(images: np.ndarray, radius: int) -> np.ndarray:
    """Gaussian blur with a ``radius``-pixel kernel radius (kernel 2r+1, OpenCV's sigma for
    that size) of one image (H, W, 3) or a stack (M, H, W, 3); uint8 in and out."""
    if radius < 1:
        return images
    k = 2 * int(radius) + 1
    if images.ndim == 3:
        return cv2.GaussianBlur(images, (k, k), 0)
    return np.stack([cv2.GaussianBlur(im, (k, k), 0) for im in images])


def kl_rows(anchor: Tensor, F: Tensor, mask: Tensor) -> Tensor:
    """KL(anchor || F) summed over real rows: (B, N, Y) x (B, N, Y) x (B, N) -> (B,)."""
    tiny = torch.finfo(F.dtype).tiny
    kl = anchor * (anchor.clamp_min(tiny).log() - F.clamp_min(tiny).log())  # (B, N, Y)
    return (kl.sum(-1) * mask).sum(-1)


class Perceiver:
    """A trained support model plus the colour segmentation that gives it entity boxes."""

    def __init__(
        self,
        model: SupportModel,
        segment: SegmentConfig = SegmentConfig(),
        input_hw: Sequence[int] | None = None,
        device: str = "cpu",
    ) -> None:
        self.device = torch_device(device)  # one-line TampError where this machine lacks it
        self.model = model.to(self.device).eval()
        self.segment = segment
        self.input_hw = None if input_hw is None else tuple(int(v) for v in input_hw)
        for p in self.model.parameters():
            p.requires_grad_(False)

    @classmethod
    def load(cls, path: str | Path, scene: str | None = None, device: str = "cpu") -> Perceiver:
        """The checkpoint at ``path``; one trained at one input size for several resolutions
        (its meta's ``input_hw``) resizes every image to that size first. With ``scene`` (the
        image scene it is to read), one trained on another scene is refused (`load_checkpoint`).
        ``device``: where the model runs (a torch device name such as "cuda")."""
        model, meta = load_checkpoint(path, scene)
        return cls(model, input_hw=meta.get("input_hw"), device=device)

    def inputs(
        self,
        images: Sequence[np.ndarray],
        colours: Sequence[Sequence[Sequence[float]]],
        names: Sequence[Sequence[str]] | None = None,
    ) -> tuple[Tensor, Tensor, Tensor]:
        """Model inputs of B images: (B, 3, H, W) float, boxes (B, N, 4), mask (B, N), on
        the perceiver's device.

        ``colours[b]`` lists the RGB colour (in [0, 1]) of each block of image b, in the
        problem's entity order; N is the most blocks of any image (padding is masked).
        """
        if len(images) != len(colours) or not images:
            raise PerceptionError(f"got {len(images)} images but {len(colours)} colour lists")
        for im in images:
            check_image(im)
        if self.input_hw is not None:
            images = [resize_image(im, self.input_hw) for im in images]
        if len({im.shape for im in images}) > 1:
            raise PerceptionError(f"images differ in size: {sorted({im.shape for im in images})}")
        n = max(len(c) for c in colours)
        boxes = np.zeros((len(images), n, 4), dtype=np.float32)
        boxes[..., 2:] = 1.0
        mask = np.zeros((len(images), n), dtype=bool)
        for b, (im, cols) in enumerate(zip(images, colours, strict=True)):
            who = None if names is None else names[b]
            boxes[b, : len(cols)] = find_boxes(im, cols, who, self.segment)
            mask[b, : len(cols)] = True
        stack = torch.from_numpy(np.stack(images)).permute(0, 3, 1, 2)  # (B, 3, H, W) uint8
        images_, boxes_ = as_float(stack.to(self.device)), torch.from_numpy(boxes).to(self.device)
        return images_, boxes_, torch.from_numpy(mask).to(self.device)

    def support(self, inputs: tuple[Tensor, Tensor, Tensor]) -> Tensor:
        """Soft supports F (B, N, N+K) of `inputs` (see `inputs`) by this perceiver's model."""
        return self.model(*inputs)
