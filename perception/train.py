"""Training and evaluation of the support model, and its checkpoints.

Supervised on rendered scenes: cross-entropy of each real block's row of F against the true
support. Relation accuracy counts blocks whose most likely support (an argmax used only to
score, never inside the model) is the true one; scene accuracy counts images with every
relation right.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from pickle import UnpicklingError

import torch
from torch import Tensor

from perception.errors import PerceptionError
from perception.model import ModelConfig, SupportModel


@dataclass(frozen=True)
class TrainConfig:
    """Supervised training of the support model (Adam, cosine-decayed learning rate)."""

    epochs: int = 20
    batch: int = 32
    lr: float = 2e-3
    weight_decay: float = 1e-5
    seed: int = 0


def as_float(images: Tensor) -> Tensor:
    """uint8 images (B, 3, H, W) -> float in [0, 1]; float images pass through."""
    return images.float() / 255.0 if images.dtype == torch.uint8 else images


def nll(F: Tensor, target: Tensor, mask: Tensor) -> Tensor:
    """Mean negative log-likelihood of the true supports over real blocks.

    F: (B, N, Y) soft supports; target: (B, N) column indices; mask: (B, N) real blocks.
    """
    tiny = torch.finfo(F.dtype).tiny
    picked = F.gather(-1, target.unsqueeze(-1)).squeeze(-1)  # (B, N)
    return -(picked.clamp_min(tiny).log() * mask).sum() / mask.sum().clamp_min(1)


@torch.no_grad()
def evaluate(model: SupportModel, data: dict[str, Tensor], batch: int = 64) -> dict[str, float]:
    """Relation and scene accuracy, and the mean NLL, of ``model`` on ``data`` (`tensors`)."""
    model.eval()
    right = blocks = scenes = 0
    loss = 0.0
    m = len(data["images"])
    for start in range(0, m, batch):
        sl = slice(start, start + batch)
        F = model(as_float(data["images"][sl]), data["boxes"][sl], data["mask"][sl])
        mask, target = data["mask"][sl], data["target"][sl]
        ok = (F.argmax(-1) == target) | ~mask  # (B, N)
        right += int((ok & mask).sum())
        blocks += int(mask.sum())
        scenes += int(ok.all(-1).sum())
        loss += float(nll(F, target, mask)) * len(mask)
    return {
        "relation_accuracy": right / max(blocks, 1),
        "scene_accuracy": scenes / max(m, 1),
        "nll": loss / max(m, 1),
        "blocks": blocks,
        "scenes": m,
        "unreadable": int(data.get("dropped", 0)),  # scenes segmentation could not read
    }


def train(
    data: dict[str, Tensor],
    config: TrainConfig = TrainConfig(),
    model_config: ModelConfig = ModelConfig(),
    on_epoch: Callable[[int, float], None] | None = None,
) -> SupportModel:
    """Train a fresh model on ``data`` (`perception.data.tensors`); ``on_epoch(k, loss)``."""
    gen = torch.Generator().manual_seed(config.seed)
    with torch.random.fork_rng():  # seeded initialisation without touching the global RNG
        torch.manual_seed(config.seed)
        model = SupportModel(model_config)
    opt = torch.optim.AdamW(model.parameters(), lr=config.lr, weight_decay=config.weight_decay)
    m = len(data["images"])
    steps = config.epochs * ((m + config.batch - 1) // config.batch)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, max(steps, 1))
    for epoch in range(config.epochs):
        model.train()
        order = torch.randperm(m, generator=gen)
        total = 0.0
        for start in range(0, m, config.batch):
            idx = order[start : start + config.batch]
            F = model(as_float(data["images"][idx]), data["boxes"][idx], data["mask"][idx])
            loss = nll(F, data["target"][idx], data["mask"][idx])
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            sched.step()
            total += float(loss.detach()) * len(idx)
        if on_epoch is not None:
            on_epoch(epoch, total / m)
    model.eval()
    return model


def save_checkpoint(path: str | Path, model: SupportModel, meta: dict) -> Path:
    """Write the weights, the model config and ``meta`` (how they were made) to ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    state = {k: v.detach().clone() for k, v in model.state_dict().items()}
    torch.save({"config": dataclasses.asdict(model.config), "state": state, "meta": meta}, path)
    return path


def load_checkpoint(path: str | Path) -> tuple[SupportModel, dict]:
    """The model stored at ``path`` (eval mode) and its meta; one-line error if unusable."""
    path = Path(path)
    if not path.is_file():
        raise PerceptionError(f"no perception checkpoint at {path}")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
        config = ModelConfig(
            **{k: tuple(v) if isinstance(v, list) else v for k, v in blob["config"].items()}
        )
        model = SupportModel(config)
        model.load_state_dict(blob["state"])
    except (KeyError, TypeError, RuntimeError, EOFError, ValueError, UnpicklingError) as err:
        raise PerceptionError(f"{path} is not a support-model checkpoint: {err}") from None
    model.eval()
    return model, dict(blob.get("meta", {}))
