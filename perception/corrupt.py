"""Image degradations for the perception stress ladder: dim light, an occluding pole, blur and
sensor noise, applied to rendered RGB images before perception reads them.

`Corruption` is deterministic: the same image and ``key`` give the same result, so every
window of a plan sees the same degradation of the same scene, and reruns are exact. Dimming
scales light in linear intensity (sRGB gamma 2.2), as a weaker lamp would; noise is additive
Gaussian sensor grain in grey levels, after the dimming (so dim images are also noisier
relative to their signal); the pole is a matte grey vertical bar in front of the scene, over
half of one block's width when the block boxes are given.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from perception.errors import PerceptionError
from perception.perceive import blur as gaussian_blur

GAMMA = 2.2
POLE_GREY = 150  # grey level of the occluding pole: unsaturated, never a block's colour


@dataclass(frozen=True)
class Corruption:
    """One rung of the stress ladder. Defaults leave the image unchanged."""

    blur: int = 0  # Gaussian blur radius, pixels
    noise: float = 0.0  # standard deviation of Gaussian sensor noise, grey levels (0..255)
    dim: float = 1.0  # light level, a factor on linear intensity (1 = as rendered)
    occlude: bool = False  # a grey pole in front of one block, covering half its width

    def __post_init__(self) -> None:
        if self.blur < 0 or self.noise < 0 or not 0.0 < self.dim <= 1.0:
            raise PerceptionError(
                f"corruption needs blur >= 0, noise >= 0 and 0 < dim <= 1, got {self}"
            )

    @property
    def name(self) -> str:
        """Short label, e.g. ``blur 6`` or ``dim 0.35 + noise 8`` (``clear`` when none)."""
        parts = [f"blur {self.blur}"] if self.blur else []
        parts += [f"noise {self.noise:g}"] if self.noise else []
        parts += [f"dim {self.dim:g}"] if self.dim < 1.0 else []
        parts += ["occluder"] if self.occlude else []
        return " + ".join(parts) or "clear"

    def __call__(
        self, image: np.ndarray, key: int = 0, boxes: Sequence[Sequence[float]] = ()
    ) -> np.ndarray:
        """The degraded copy of ``image`` (H, W, 3) uint8. ``key`` seeds the noise and which
        block the pole stands in front of; ``boxes`` (x0, y0, x1, y1) are the blocks' boxes in
        the clear image (without them the pole stands at a seeded position)."""
        out = image
        rng = np.random.default_rng(key & 0xFFFFFFFF)
        if self.dim < 1.0:
            linear = (out.astype(np.float32) / 255.0) ** GAMMA * self.dim
            out = np.clip(255.0 * linear ** (1.0 / GAMMA) + 0.5, 0, 255).astype(np.uint8)
        if self.occlude:
            out = _pole(out, rng, boxes)
        out = gaussian_blur(out, self.blur)
        if self.noise > 0:
            grain = rng.normal(0.0, self.noise, out.shape)
            out = np.clip(out.astype(np.float32) + grain + 0.5, 0, 255).astype(np.uint8)
        return out


def _pole(image: np.ndarray, rng: np.random.Generator, boxes) -> np.ndarray:
    """A vertical grey bar over the full image height: over the left or right half of one of
    ``boxes`` (picked by ``rng``), else one twentieth of the width at a random position."""
    w = image.shape[1]
    if len(boxes):
        x0, _, x1, _ = (float(v) for v in boxes[int(rng.integers(len(boxes)))])
        mid = 0.5 * (x0 + x1)
        left, right = (x0, mid) if rng.random() < 0.5 else (mid, x1)
    else:
        width = max(1.0, w / 20)
        left = float(rng.uniform(0, w - width))
        right = left + width
    out = image.copy()
    a = round(left)
    out[:, a : max(round(right), a + 1)] = POLE_GREY
    return out
