"""Perception checkpoints: a file that is not one is a single `PerceptionError` line naming the
file and what is wrong (torch's own messages span several lines), and a checkpoint knows the
image scene it was trained on, so a reader of another scene's images refuses it."""

from __future__ import annotations

import pickle

import pytest
import torch

from perception import CHECKPOINT
from perception.errors import PerceptionError
from perception.model import ModelConfig, SupportModel
from perception.perceive import Perceiver
from perception.train import checkpoint_scene, load_checkpoint, save_checkpoint

LATPLAN = CHECKPOINT.with_name("support-latplan.pt")
SMALL = ModelConfig(channels=(4,), dim=8, bands=0)


class _Thing:
    """Not tensors and plain data: what a weights-only load refuses."""


def _good(path, meta=None):
    return save_checkpoint(path, SupportModel(SMALL), meta or {})


def _blob(path):
    return torch.load(_good(path), weights_only=True)


def _write(path, kind: str) -> None:
    if kind == "empty":
        path.write_bytes(b"")
    elif kind == "text":
        path.write_text("(define (problem p))\n")
    elif kind == "random":
        path.write_bytes(bytes(range(256)) * 8)
    elif kind == "pickle":
        path.write_bytes(pickle.dumps(_Thing()))
    elif kind == "tensor":
        torch.save(torch.zeros(3), path)
    elif kind == "keys":
        torch.save({"weights": {}}, path)
    elif kind == "config":
        blob = _blob(path)
        torch.save({**blob, "config": {**blob["config"], "width": 3}}, path)
    elif kind == "missing":
        blob = _blob(path)
        torch.save({**blob, "state": dict(list(blob["state"].items())[1:])}, path)
    elif kind == "shape":
        blob = _blob(path)
        name = next(iter(blob["state"]))
        torch.save({**blob, "state": {**blob["state"], name: torch.zeros(2, 2)}}, path)


@pytest.mark.parametrize(
    ("kind", "says"),
    [
        ("empty", "not a perception checkpoint (the file is empty)"),
        ("text", "not a perception checkpoint: not a file torch.save wrote"),
        ("random", "not a perception checkpoint: not a file torch.save wrote"),
        ("pickle", "tensors and plain data only (torch: Unsupported"),
        ("tensor", "it holds a Tensor, not a dict with keys config, state, meta"),
        ("keys", "no config or state key (its keys: weights; expected config, state, meta)"),
        ("config", "model config has fields this code does not know: width (valid: channels"),
        ("missing", "weights do not fit the model its config describes (missing weights: "),
        ("shape", "weights do not fit the model its config describes (wrong shapes: "),
    ],
)
def test_a_bad_checkpoint_is_one_line_naming_the_file_and_the_fault(tmp_path, kind, says):
    path = tmp_path / "model.pt"
    _write(path, kind)
    with pytest.raises(PerceptionError) as excinfo:
        load_checkpoint(path)
    message = str(excinfo.value)
    assert "\n" not in message and message.startswith(str(path)) and says in message
    assert "weights_only" not in message


def test_a_good_small_checkpoint_loads(tmp_path):
    model, meta = load_checkpoint(_good(tmp_path / "model.pt", {"seed": 3}))
    assert model.config == SMALL and meta == {"seed": 3} and checkpoint_scene(meta) is None


def test_the_shipped_checkpoints_know_their_scenes():
    assert checkpoint_scene(load_checkpoint(CHECKPOINT)[1]) == "cubes"
    assert checkpoint_scene(load_checkpoint(LATPLAN)[1]) == "latplan"


@pytest.mark.parametrize(
    ("meta", "scene"),
    [
        ({"dataset": {"scene": "latplan"}}, "latplan"),
        ({"train": {"made_by": "tamp perception dataset --n 9 --seed 0"}}, "cubes"),
        ({"train": {"made_by": "tamp perception dataset --scene latplan --n 9"}}, "latplan"),
        ({"train": {"made_by": "tamp perception dataset --image-scene latplan"}}, "latplan"),
        ({"train": {"made_by": "somebody's script"}}, None),
        ({}, None),
    ],
)
def test_checkpoint_scene_reads_the_record_or_the_dataset_command(meta, scene):
    assert checkpoint_scene(meta) == scene


@pytest.mark.parametrize(
    ("path", "images", "trained"), [(CHECKPOINT, "latplan", "cubes"), (LATPLAN, "cubes", "latplan")]
)
def test_a_checkpoint_of_another_scene_is_refused_in_one_line(path, images, trained):
    for load in (lambda: load_checkpoint(path, images), lambda: Perceiver.load(path, images)):
        with pytest.raises(PerceptionError) as excinfo:
            load()
        message = str(excinfo.value)
        assert "\n" not in message and str(path) in message
        assert f"trained on the {trained} scene, not {images}" in message
    assert Perceiver.load(path, trained).model is not None


def test_a_checkpoint_of_unknown_scene_is_read_for_any_scene(tmp_path):
    path = _good(tmp_path / "model.pt")
    assert load_checkpoint(path, "latplan")[0].config == SMALL
