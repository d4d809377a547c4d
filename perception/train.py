"""Training and evaluation of the support model, and its checkpoints.

Supervised on rendered scenes: cross-entropy of each real block's row of F against the true
support. Relation accuracy counts blocks whose most likely support (an argmax used only to
score, never inside the model) is the true one; scene accuracy counts images with every
relation right.
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

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
    device: str = "cpu"  # torch device of the model and its batches ("cuda": a GPU); the
    # initialisation and the batch order are drawn on the CPU, the same on every device


def torch_device(name: str) -> torch.device:
    """The torch device ``name`` ("cpu", "cuda" or "cuda:N") the model runs on; PerceptionError
    (one line) for another name or one this machine lacks: never a silent CPU. (The planner's
    own check is `task.config.torch_device`; perception does not import the planner.)"""
    try:
        device = torch.device(name)
    except (RuntimeError, TypeError):
        device = None
    if device is None or device.type not in ("cpu", "cuda"):
        raise PerceptionError(f"unknown device {name!r} (valid: cpu, cuda, cuda:N)")
    if device.type == "cpu":
        return device
    if not torch.backends.cuda.is_built():
        raise PerceptionError(
            f"device {name!r}: this torch build has no CUDA (torch {torch.__version__})"
        )
    count = torch.cuda.device_count()
    if (device.index or 0) >= count:
        raise PerceptionError(f"device {name!r}: {count} CUDA device(s) visible here")
    return device


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
    """Relation and scene accuracy, and the mean NLL, of ``model`` on ``data`` (`tensors`),
    each batch read on the model's device."""
    model.eval()
    device = next(model.parameters()).device
    right = blocks = scenes = 0
    loss = 0.0
    m = len(data["images"])
    for start in range(0, m, batch):
        sl = slice(start, start + batch)
        images, boxes = data["images"][sl].to(device), data["boxes"][sl].to(device)
        mask, target = data["mask"][sl].to(device), data["target"][sl].to(device)
        F = model(as_float(images), boxes, mask)
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
    device = torch_device(config.device)  # one-line TampError where this machine lacks it
    model = model.to(device)
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
            batch = {k: data[k][idx].to(device) for k in ("images", "boxes", "mask", "target")}
            F = model(as_float(batch["images"]), batch["boxes"], batch["mask"])
            loss = nll(F, batch["target"], batch["mask"])
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
    state = {k: v.detach().cpu().clone() for k, v in model.state_dict().items()}  # on any device
    torch.save({"config": dataclasses.asdict(model.config), "state": state, "meta": meta}, path)
    return path


CHECKPOINT_KEYS = ("config", "state", "meta")  # what `save_checkpoint` writes
DEFAULT_SCENE = "cubes"  # the scene ``tamp perception dataset`` renders without ``--scene``
_SCENE_FLAG = re.compile(r"--(?:image-)?scene[ =](\S+)")


def checkpoint_scene(meta: dict) -> str | None:
    """The image scene a checkpoint was trained on, from its ``meta``: the training set's own
    record (``meta["dataset"]["scene"]``), else the dataset command that made the training set
    (``--scene X``, or `DEFAULT_SCENE` without it: the shipped ``support.pt`` predates the
    record); None when the meta says neither."""
    dataset = meta.get("dataset")
    if isinstance(dataset, dict) and dataset.get("scene"):
        return str(dataset["scene"])
    train = meta.get("train")
    made_by = train.get("made_by") if isinstance(train, dict) else None
    if not isinstance(made_by, str) or "perception dataset" not in made_by:
        return None
    match = _SCENE_FLAG.search(made_by)
    return match.group(1) if match else DEFAULT_SCENE


def _torch_detail(err: BaseException) -> str:
    """The one informative line of a weights-only `torch.load` failure, e.g. ``" (torch:
    Unsupported operand 44)"``; "" for other failures, whose messages (a pickle key, a zip
    assertion) say nothing to a user. Torch's full message spans several lines and suggests
    ``weights_only=False``, which this loader never uses."""
    text = str(err)
    if "WeightsUnpickler error:" not in text:
        return ""
    rest = [ln.strip() for ln in text.split("WeightsUnpickler error:", 1)[1].splitlines()]
    detail = next((ln for ln in rest if ln), "")
    return f" (torch: {detail[:80]})" if detail else ""


def _read(path: Path) -> dict:
    """The dict a checkpoint file holds; PerceptionError when torch cannot read it as one."""
    if path.stat().st_size == 0:
        raise PerceptionError(f"{path}: not a perception checkpoint (the file is empty)")
    try:
        with warnings.catch_warnings():  # torch warns about pickle protocols on stderr
            warnings.simplefilter("ignore")
            blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as err:  # torch raises many kinds, most with several lines
        raise PerceptionError(
            f"{path}: not a perception checkpoint: not a file torch.save wrote with tensors "
            f"and plain data only{_torch_detail(err)}"
        ) from None
    if not isinstance(blob, dict):
        raise PerceptionError(
            f"{path}: not a perception checkpoint: it holds a {type(blob).__name__}, not a dict "
            f"with keys {', '.join(CHECKPOINT_KEYS)} (what tamp perception train writes)"
        )
    missing = [k for k in CHECKPOINT_KEYS[:2] if k not in blob]
    if missing:
        keys = ", ".join(sorted(map(str, blob))) or "none"
        raise PerceptionError(
            f"{path}: not a perception checkpoint: no {' or '.join(missing)} key (its keys: "
            f"{keys}; expected {', '.join(CHECKPOINT_KEYS)})"
        )
    for key, kind in (("config", dict), ("state", dict), ("meta", dict)):
        if key in blob and not isinstance(blob[key], kind):
            raise PerceptionError(
                f"{path}: its {key!r} is a {type(blob[key]).__name__}, not a dict"
            )
    return blob


def _config(path: Path, raw: dict) -> ModelConfig:
    fields = [f.name for f in dataclasses.fields(ModelConfig)]
    unknown = sorted(str(k) for k in raw if k not in fields)
    if unknown:
        raise PerceptionError(
            f"{path}: model config has fields this code does not know: {', '.join(unknown)} "
            f"(valid: {', '.join(fields)})"
        )
    try:
        return ModelConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in raw.items()})
    except (TypeError, ValueError) as err:
        raise PerceptionError(f"{path}: bad model config: {str(err).splitlines()[0]}") from None


def _weights(path: Path, model: SupportModel, state: dict) -> None:
    """Load ``state`` into ``model``; PerceptionError naming the missing, unexpected or
    misshapen weights (torch's own message spans several lines)."""
    expected = model.state_dict()
    missing = [k for k in expected if k not in state]
    unexpected = [str(k) for k in state if k not in expected]
    shapes = [
        f"{k} {tuple(state[k].shape)} (model: {tuple(v.shape)})"
        if isinstance(state[k], Tensor)
        else f"{k} (not a tensor)"
        for k, v in expected.items()
        if k in state and not (isinstance(state[k], Tensor) and state[k].shape == v.shape)
    ]
    problems = [
        f"{label}: {', '.join(names[:3])}{', ...' if len(names) > 3 else ''}"
        for label, names in (
            ("missing weights", missing),
            ("unexpected weights", unexpected),
            ("wrong shapes", shapes),
        )
        if names
    ]
    if problems:
        raise PerceptionError(
            f"{path}: weights do not fit the model its config describes ({'; '.join(problems)})"
        )
    model.load_state_dict(state)


def load_checkpoint(path: str | Path, scene: str | None = None) -> tuple[SupportModel, dict]:
    """The model stored at ``path`` (eval mode) and its meta. One PerceptionError line naming
    the file and what is wrong when it is not a checkpoint (missing, empty, not a torch file,
    wrong keys, a config or weights that do not fit this code). With ``scene`` (the image scene
    to be read, e.g. ``"latplan"``), a checkpoint whose meta says it was trained on another
    scene is refused too (`checkpoint_scene`): its readings would be confidently wrong."""
    path = Path(path)
    if not path.is_file():
        raise PerceptionError(f"no perception checkpoint at {path}")
    blob = _read(path)
    model = SupportModel(_config(path, blob["config"]))
    _weights(path, model, blob["state"])
    model.eval()
    meta = dict(blob.get("meta", {}))
    trained = checkpoint_scene(meta)
    if scene is not None and trained is not None and trained != scene:
        raise PerceptionError(
            f"{path} was trained on the {trained} scene, not {scene}: its readings of {scene} "
            f"images would be wrong; pass a checkpoint trained on {scene} images"
        )
    return model, meta
