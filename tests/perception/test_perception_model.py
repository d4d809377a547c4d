"""The support model: shapes, masks, row distributions, ROI pooling, gradients, bad input."""

from __future__ import annotations

import pytest
import torch

from perception.errors import PerceptionError
from perception.model import ModelConfig, SupportModel, roi_pool


def _batch(b: int = 2, n: int = 4, h: int = 64, w: int = 80):
    gen = torch.Generator().manual_seed(0)
    images = torch.rand(b, 3, h, w, generator=gen)
    x0 = torch.rand(b, n, generator=gen) * (w - 16)
    y0 = torch.rand(b, n, generator=gen) * (h - 16)
    boxes = torch.stack([x0, y0, x0 + 12, y0 + 12], dim=-1)  # (B, N, 4)
    mask = torch.ones(b, n, dtype=torch.bool)
    mask[1, 3] = False  # the second image has 3 entities, padded to 4
    return images, boxes, mask


@pytest.fixture
def model() -> SupportModel:
    torch.manual_seed(0)
    return SupportModel(ModelConfig())


def test_support_rows_are_distributions_over_the_allowed_targets(model):
    images, boxes, mask = _batch()
    F = model(images, boxes, mask)  # (B, N, N+K)
    assert F.shape == (2, 4, 5)
    torch.testing.assert_close(F.sum(-1), torch.ones(2, 4))
    assert (F.diagonal(dim1=1, dim2=2) == 0).all()  # nothing rests on itself
    assert (F[1, :, 3] == 0).all()  # nothing rests on a padded entity
    torch.testing.assert_close(F[1, 3], torch.tensor([0.0, 0, 0, 0, 1]))  # padding: on the table
    assert ((F > 0) & (F < 1))[0].any()  # soft, no argmax


def test_gradients_reach_every_weight(model):
    images, boxes, mask = _batch()
    F = model(images, boxes, mask)
    torch.log(F[0, 0, 4]).backward()
    for name, p in model.named_parameters():
        assert p.grad is not None and p.grad.abs().sum() > 0, name


def test_roi_pool_reads_the_features_inside_the_box():
    feats = torch.zeros(1, 1, 8, 8)
    feats[0, 0, 2:4, 4:6] = 1.0  # a bright patch; the image is 32 x 32, features stride 4
    inside = torch.tensor([[[16.0, 8.0, 24.0, 16.0]]])  # covers the patch
    outside = torch.tensor([[[0.0, 20.0, 8.0, 28.0]]])
    assert roi_pool(feats, inside, (32, 32), 2).min() == 1.0
    assert roi_pool(feats, outside, (32, 32), 2).max() == 0.0


@pytest.mark.parametrize(
    ("images", "boxes", "mask"),
    [
        (torch.rand(1, 1, 32, 32), torch.zeros(1, 2, 4), torch.ones(1, 2, dtype=torch.bool)),
        (torch.rand(1, 3, 32, 32), torch.zeros(1, 2, 3), torch.ones(1, 2, dtype=torch.bool)),
        (torch.rand(1, 3, 32, 32), torch.zeros(1, 2, 4), torch.ones(1, 2)),
    ],
)
def test_bad_shapes_are_one_line_errors(model, images, boxes, mask):
    with pytest.raises(PerceptionError):
        model(images, boxes, mask)
