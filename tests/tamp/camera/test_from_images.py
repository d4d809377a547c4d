"""Image beliefs for the planner: gradients reach perception only in optimised mode."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
import torch

from perception.model import ModelConfig, SupportModel
from perception.perceive import Perceiver
from tamp.camera.from_images import ImageBeliefs, PerceptionMode
from tamp.camera.render import block_colours
from task.config import PlannerConfig
from task.domains.blocksworld import DOMAIN
from task.errors import TampError
from task.planner import plan
from task.problem import TABLE, Problem

THREE = Problem("three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("c", "b"),))


def _image(boxes) -> np.ndarray:
    img = np.full((120, 160, 3), 110, np.uint8)
    for rgb, (x, y) in zip(block_colours(3), boxes, strict=True):
        cv2.rectangle(img, (x, y), (x + 15, y + 15), tuple(int(255 * c) for c in rgb), -1)
    return img


INIT = _image([(40, 70), (40, 54), (100, 70)])  # b on a, c alone
GOAL = _image([(40, 70), (40, 54), (40, 38)])  # c on b on a


def _beliefs(mode: str, adapt: str = "head"):
    torch.manual_seed(0)
    perceiver = Perceiver(SupportModel(ModelConfig(channels=(8, 16), dim=16, bands=2)))
    return perceiver, ImageBeliefs(
        [THREE], perceiver, lambda i, s: INIT, [GOAL], PerceptionMode(mode, adapt=adapt)
    )


def test_frozen_beliefs_carry_no_gradient_and_no_parameters():
    _, source = _beliefs("frozen")
    window = source([0], [THREE.init])
    F0, goal, penalty = window.compute()
    assert F0.shape == goal.shape == (1, 3, 4)
    assert not F0.requires_grad and not goal.requires_grad
    assert window.parameters() == [] and float(penalty.sum()) == 0.0
    torch.testing.assert_close(F0.sum(-1), torch.ones(1, 3))


@pytest.mark.parametrize("adapt", ["head", "all"])
def test_optimised_beliefs_send_planning_gradients_into_the_weights(adapt):
    perceiver, source = _beliefs("optimised", adapt)
    window = source([0], [THREE.init])
    F0, goal, penalty = window.compute()
    assert float(penalty.detach().sum()) == pytest.approx(0.0, abs=1e-6)  # at the anchors: KL = 0
    (F0[0, 2, 1].log() + goal[0, 2, 1].log()).backward()  # any planning-style loss
    params = window.parameters()
    assert params and all(p.grad is not None for p in params)
    assert all(p.grad is None for p in perceiver.model.parameters())  # the original is untouched
    conv = any(p.ndim == 4 for p in params)  # backbone convolution kernels
    assert conv == (adapt == "all")


@pytest.mark.parametrize("mode", ["frozen", "optimised"])
def test_planning_from_images_checks_moves_against_the_true_state(mode):
    _, source = _beliefs(mode)
    result = plan(THREE, PlannerConfig(iters=8, restarts=2, max_windows=3), beliefs=source)
    assert result.solved or result.stats["windows"] == 3  # every window was planned
    state = THREE.init
    for move in result.plan:  # an untrained model may not reach the goal, but never cheats
        assert DOMAIN.check_move(THREE, state, move) is None
        state = DOMAIN.apply_move(THREE, state, move)


def test_bad_perception_modes_are_refused():
    with pytest.raises(TampError, match="unknown perception mode"):
        PerceptionMode("blurry")
    with pytest.raises(TampError, match="unknown adapt"):
        PerceptionMode("optimised", adapt="backbone")
