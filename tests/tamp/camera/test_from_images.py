"""Image beliefs for the planner: gradients reach perception only in optimised mode, and the
shipped checkpoint's beliefs lead the planner to the goal with a plan the PDDL validator accepts.

Images are drawn with OpenCV (coloured squares on grey), so no simulator is needed.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest
import torch

from perception import CHECKPOINT
from perception.model import ModelConfig, SupportModel
from perception.perceive import Perceiver
from tamp.camera.from_images import ImageBeliefs, PerceptionMode
from tamp.camera.render import block_colours
from task.config import PlannerConfig
from task.errors import TampError
from task.planner import plan
from task.problem import TABLE, Problem
from tests.pddl_check import assert_valid

THREE = Problem("three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("c", "b"),))


def _draw(state) -> np.ndarray:
    """THREE in ``state``: one column per tower, bases in entity order, 16-pixel squares."""
    img = np.full((120, 160, 3), 110, np.uint8)
    colours = dict(zip(THREE.entities, block_colours(3), strict=True))
    supports = dict(zip(THREE.entities, state, strict=True))
    bases = [x for x in THREE.entities if supports[x] == TABLE]
    for column, base in enumerate(bases):
        block, level = base, 0
        while block is not None:
            x, y = 40 + 60 * column, 70 - 16 * level
            colour = tuple(int(255 * c) for c in colours[block])
            cv2.rectangle(img, (x, y), (x + 15, y + 15), colour, -1)
            block = next((z for z in THREE.entities if supports[z] == block), None)
            level += 1
    return img


INIT = _draw(THREE.init)  # b on a, c alone
GOAL = _draw((TABLE, "a", "b"))  # c on b on a


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


@pytest.fixture(scope="module")
def shipped() -> Perceiver:
    return Perceiver.load(CHECKPOINT)


@pytest.mark.parametrize("mode", ["frozen", "optimised"])
def test_planning_from_images_reaches_the_goal_with_a_valid_plan(mode, shipped):
    def observe(i, state):  # the camera sees the true state
        return _draw(state)

    source = ImageBeliefs([THREE], shipped, observe, [GOAL], PerceptionMode(mode))
    result = plan(THREE, PlannerConfig(iters=8, restarts=2, max_windows=3), beliefs=source)
    assert result.solved and result.stats["misread_windows"] == 0, result.stats
    assert_valid(THREE, result.plan)  # legal and goal-reaching for the PDDL validator
    # the optimum is one move (c -> b), found with seeds 0 and 2; seed 1 detours to 3 moves
    assert 1 <= len(result.plan) <= 3


def test_bad_perception_modes_are_refused():
    with pytest.raises(TampError, match="unknown perception mode"):
        PerceptionMode("blurry")
    with pytest.raises(TampError, match="unknown adapt"):
        PerceptionMode("optimised", adapt="backbone")
