"""The image -> soft support model of the paper: CNN backbone, ROI pooling, bilinear head.

``SupportModel(images, boxes, entity_mask) -> F`` with ``F[b, x, y]`` the belief that entity x
rests on target y (targets: the N entities, then K fixed targets, K=1 the table). Every step is
soft (no argmax), so planning losses can flow back into the weights.

- Backbone: a small strided CNN, (B, C, H, W) -> (B, D, H', W').
- ROI pooling (Eq. ROI): bilinear sampling of a ``roi`` x ``roi`` grid inside each entity's box
  (written with ``grid_sample``; torchvision has no CPU build here), flattened and projected to
  ``r_x`` together with the box geometry (centre and size, normalised): relations such as "x is
  above y" are about where the boxes are.
- Fixed targets (the table) get a learned embedding.
- Head (Eq. bilinear): ``s(x, y) = r_x^T W r_y + b``; self-support, padded entities and padded
  targets are masked to -inf before the softmax over y; padded rows rest on the first fixed
  target.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import Tensor, nn
from torch.nn import functional as F

from perception.errors import PerceptionError


@dataclass(frozen=True)
class ModelConfig:
    """Sizes of the support model."""

    channels: tuple[int, ...] = (16, 32, 64)  # backbone widths; each layer halves H and W
    roi: int = 4  # ROI pooling grid, roi x roi samples per entity
    dim: int = 64  # D, entity embedding size
    fixed: int = 1  # K, fixed targets (the table)
    bands: int = 6  # Fourier bands of the box geometry (0: the raw geometry only)


def roi_pool(features: Tensor, boxes: Tensor, image_hw: tuple[int, int], size: int) -> Tensor:
    """Bilinear ROI pooling (B, D, H', W') x (B, R, 4) -> (B, R, D * size * size).

    ``boxes`` are (x0, y0, x1, y1) in pixels of the input image of size ``image_hw``.
    """
    b, d = features.shape[:2]
    r = boxes.shape[1]
    h, w = image_hw
    steps = (torch.arange(size, dtype=features.dtype, device=features.device) + 0.5) / size
    x0, y0, x1, y1 = boxes.unbind(-1)  # each (B, R)
    xs = x0[..., None] + (x1 - x0)[..., None] * steps  # (B, R, S) pixels
    ys = y0[..., None] + (y1 - y0)[..., None] * steps  # (B, R, S)
    gx = 2.0 * xs / w - 1.0  # (B, R, S) in [-1, 1], align_corners=False convention
    gy = 2.0 * ys / h - 1.0
    grid = torch.stack(torch.broadcast_tensors(gx[:, :, None, :], gy[:, :, :, None]), dim=-1)
    grid = grid.reshape(b, r * size, size, 2)  # (B, R*S, S, 2)
    pooled = F.grid_sample(features, grid, mode="bilinear", align_corners=False)  # (B,D,R*S,S)
    pooled = pooled.reshape(b, d, r, size, size).permute(0, 2, 1, 3, 4)  # (B, R, D, S, S)
    return pooled.reshape(b, r, d * size * size)


def fourier(g: Tensor, bands: int) -> Tensor:
    """g and its Fourier features sin/cos(2^j pi g), j < bands: (..., G) -> (..., G(1 + 2 bands)).

    With them the bilinear head can score *offsets* between two boxes (cos(a - b) is bilinear
    in the sin/cos of a and b), such as "y sits one block below x".
    """
    if bands == 0:
        return g
    freq = torch.pi * 2.0 ** torch.arange(bands, dtype=g.dtype, device=g.device)  # (F,)
    angles = (g[..., None] * freq).flatten(-2)  # (..., G * F)
    return torch.cat([g, angles.sin(), angles.cos()], dim=-1)


class SupportModel(nn.Module):
    """Images (B, 3, H, W) in [0, 1] + entity boxes (B, N, 4) -> soft supports (B, N, N+K)."""

    def __init__(self, config: ModelConfig = ModelConfig()) -> None:
        super().__init__()
        self.config = config
        layers, c_in = [], 3
        for c_out in config.channels:
            layers += [nn.Conv2d(c_in, c_out, 3, stride=2, padding=1), nn.ReLU()]
            c_in = c_out
        self.backbone = nn.Sequential(*layers)
        self.project = nn.Sequential(
            nn.Linear(c_in * config.roi * config.roi + 4 * (1 + 2 * config.bands), config.dim),
            nn.ReLU(),
            nn.Linear(config.dim, config.dim),
        )
        self.fixed = nn.Parameter(0.1 * torch.randn(config.fixed, config.dim))  # (K, D)
        self.W = nn.Parameter(torch.eye(config.dim) / config.dim**0.5)  # (D, D)
        self.b = nn.Parameter(torch.zeros(()))

    def forward(self, images: Tensor, boxes: Tensor, entity_mask: Tensor) -> Tensor:
        """Soft support matrix F (B, N, N+K); each row is a distribution over targets."""
        check_inputs(images, boxes, entity_mask)
        return self.head(self.backbone(images), boxes, entity_mask, images.shape[-2:])

    def head(
        self, features: Tensor, boxes: Tensor, entity_mask: Tensor, image_hw: tuple[int, int]
    ) -> Tensor:
        """Everything after the backbone: ROI pooling, embeddings, the bilinear head.

        features: (B, D', H', W') backbone output of images of size ``image_hw``.
        """
        b, n = entity_mask.shape
        k = self.config.fixed
        h, w = image_hw
        pooled = roi_pool(features, boxes, (h, w), self.config.roi)  # (B, N, D' S S)
        scale = boxes.new_tensor([w, h, w, h])
        x0, y0, x1, y1 = (boxes / scale).unbind(-1)  # each (B, N), normalised
        geometry = torch.stack([(x0 + x1) / 2, (y0 + y1) / 2, x1 - x0, y1 - y0], dim=-1)
        r = self.project(torch.cat([pooled, fourier(geometry, self.config.bands)], dim=-1))
        targets = torch.cat([r, self.fixed.expand(b, k, -1)], dim=1)  # (B, Y, D)
        scores = r @ self.W @ targets.transpose(1, 2) + self.b  # (B, N, Y), Eq. bilinear
        valid_target = torch.cat([entity_mask, entity_mask.new_ones(b, k)], dim=1)  # (B, Y)
        not_self = ~torch.eye(n, n + k, dtype=torch.bool, device=scores.device)  # (N, Y)
        allowed = valid_target[:, None, :] & not_self  # (B, N, Y)
        scores = scores.masked_fill(~allowed, float("-inf"))
        support = torch.softmax(scores, dim=-1)  # (B, N, Y)
        table = torch.zeros_like(support)
        table[..., n] = 1.0  # padded entities rest on the first fixed target
        return torch.where(entity_mask[..., None], support, table)

    def head_parameters(self) -> list[nn.Parameter]:
        """The weights after the backbone (projection, table embedding, W, b)."""
        return [*self.project.parameters(), self.fixed, self.W, self.b]


def check_inputs(images: Tensor, boxes: Tensor, entity_mask: Tensor) -> None:
    """One-line PerceptionError for inputs of the wrong shape or type."""
    if images.ndim != 4 or images.shape[1] != 3:
        raise PerceptionError(f"images must be (B, 3, H, W), got {tuple(images.shape)}")
    b = images.shape[0]
    if boxes.ndim != 3 or boxes.shape[0] != b or boxes.shape[2] != 4:
        raise PerceptionError(f"boxes must be (B={b}, N, 4), got {tuple(boxes.shape)}")
    if entity_mask.shape != boxes.shape[:2] or entity_mask.dtype != torch.bool:
        raise PerceptionError(
            f"entity_mask must be bool ({b}, {boxes.shape[1]}), got "
            f"{tuple(entity_mask.shape)} {entity_mask.dtype}"
        )
