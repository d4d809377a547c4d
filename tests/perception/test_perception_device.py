"""The perception model's torch device: refused in one line where this machine lacks it, and
on a machine with CUDA the model and its inputs live there (skipped without one)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from perception.errors import PerceptionError
from perception.model import SupportModel
from perception.perceive import Perceiver
from perception.train import torch_device

CUDA = torch.cuda.is_available()


@pytest.mark.skipif(CUDA, reason="this machine has CUDA")
@pytest.mark.parametrize("name", ["cuda", "cuda:1"])
def test_cuda_where_there_is_none_is_refused_in_one_line(name):
    with pytest.raises(PerceptionError, match=rf"device '{name}': .*CUDA") as err:
        Perceiver(SupportModel(), device=name)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("name", ["tpu", "gpu", "cuda:x"])
def test_an_unknown_device_is_refused_listing_the_valid_ones(name):
    with pytest.raises(PerceptionError, match=r"\(valid: cpu, cuda, cuda:N\)"):
        torch_device(name)


ON_CUDA = pytest.mark.skipif(not CUDA, reason="needs a CUDA device")


@pytest.mark.parametrize("name", ["cpu", pytest.param("cuda", marks=ON_CUDA)])
def test_the_model_and_its_inputs_live_on_the_device(name):
    perceiver = Perceiver(SupportModel(), device=name)
    image = np.zeros((64, 96, 3), np.uint8)
    image[10:30, 10:30] = (255, 0, 0)  # one red block
    inputs = perceiver.inputs([image], [[(1.0, 0.0, 0.0)]])
    assert all(t.device.type == name for t in inputs)
    assert perceiver.support(inputs).device.type == name
    assert all(p.device.type == name for p in perceiver.model.parameters())
