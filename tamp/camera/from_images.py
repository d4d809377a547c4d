"""Planning from camera images: perception gives the planner its soft initial and goal states.

Three modes, for every planning entry point that takes a ``PerceptionMode``:

- ``state``: the ground-truth symbolic state (no images; the planner's own one-hot encoding);
- ``frozen``: every window starts from F0 = perception of the current image and aims at
  perception of the goal image, with the trained weights fixed;
- ``optimised``: as frozen, but the planning loss also updates a per-problem copy of the
  perception weights (Adam, lr 1e-4) with KL anchors to the initial predictions on both the
  initial and the goal image; the soft states are recomputed from the images at every gradient
  step (`task.optimize.with_beliefs`). Every window adapts a fresh copy of the trained
  weights (carried over, the adaptation drifts and the planner stalls). ``adapt="head"`` (the
  default) updates the weights after the CNN backbone (ROI projection, table embedding,
  bilinear W and b) and computes the backbone's features of the two images once per window;
  ``adapt="all"`` also updates the backbone and reruns it on both images at every step (see
  BENCHMARKS.md for what that costs).

Two crisp protocols (``crisp``). ``true``, the paper's: decoded moves are checked against the
true symbolic state. ``perceived``, a robot without an oracle: each window's moves are checked
against the most likely valid state read from the current image by the trained weights
(`perceived_state`), then applied to the world, where a move that is illegal ends the plan as
inexecutable (`task.beliefs`). The goal the planner stops at is the *perceived* goal scene
(the most likely valid state under the trained model's reading of the goal image, every block's
support), so a misread goal image gives a plan that fails validation against the PDDL goal; it
is never corrected from the PDDL.
"""

from __future__ import annotations

import copy
import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor

from perception.perceive import Perceiver, blur, kl_rows
from tamp.camera.render import block_colours
from tamp.camera.states import most_likely_state
from tamp.modes import Adapt, Crisp, Perception
from task.beliefs import WindowBeliefsBase
from task.domains.base import State
from task.errors import TampError, member
from task.problem import Problem

Observe = Callable[[int, State], np.ndarray]  # (problem index, true state) -> RGB image
Colours = Sequence[Sequence[float]]  # RGB in [0, 1] of each block, in entity order


@dataclass(frozen=True)
class PerceptionMode:
    """How the planner gets its states. ``lr`` and ``kl_weight`` matter in ``optimised`` only."""

    mode: Perception = Perception.FROZEN
    lr: float = 1e-4  # Adam learning rate of the perception weights (the paper's value)
    kl_weight: float = 10.0  # weight of each KL anchor (chosen on the 100-subset, BENCHMARKS.md)
    blur: int = 0  # Gaussian blur radius (pixels) applied to every image; 0 = clear
    adapt: Adapt = Adapt.HEAD  # which weights ``optimised`` updates: "head" or "all"
    crisp: Crisp = Crisp.TRUE  # decode against the true state (the paper's) or the perceived one

    def __post_init__(self) -> None:
        object.__setattr__(self, "mode", member(Perception, self.mode, "perception mode"))
        object.__setattr__(self, "adapt", member(Adapt, self.adapt, "adapt setting"))
        object.__setattr__(self, "crisp", member(Crisp, self.crisp, "crisp protocol"))
        if self.mode is Perception.STATE and self.crisp is not Crisp.TRUE:
            raise TampError("perception mode 'state' reads no image: it needs crisp 'true'")
        if self.lr <= 0 or self.kl_weight < 0 or self.blur < 0:
            raise TampError("PerceptionMode needs lr > 0, kl_weight >= 0 and blur >= 0")


class _Frozen(WindowBeliefsBase):
    """Soft inputs computed once, no parameters; ``crisp_states`` see `task.beliefs`."""

    lr = 0.0

    def __init__(self, F0: Tensor, goal: Tensor, crisp_states=None) -> None:
        self.F0, self.goal, self.crisp_states = F0, goal, crisp_states

    def compute(self):
        return self.F0, self.goal, self.F0.new_zeros(self.F0.shape[0])

    def parameters(self) -> list[Tensor]:
        return []


class _Adapted(WindowBeliefsBase):
    """Soft inputs recomputed from the images by per-problem models at every step.

    ``features[i]``: the frozen backbone's features of problem i's two images, or None to run
    the problem's own (adapted) backbone every step.
    """

    def __init__(
        self, models, inputs, features, anchors, mode: PerceptionMode, crisp_states=None
    ) -> None:
        self.models, self.inputs, self.features, self.anchors = models, inputs, features, anchors
        self.mode, self.crisp_states = mode, crisp_states
        self.lr, self.kl_weight = mode.lr, mode.kl_weight

    def compute(self):
        F0s, goals, penalties = [], [], []
        for model, (images, boxes, mask), feats, anchor in zip(
            self.models, self.inputs, self.features, self.anchors, strict=True
        ):
            if feats is None:
                F = model(images, boxes, mask)  # (2, N, Y): the current image, the goal image
            else:
                F = model.head(feats, boxes, mask, images.shape[-2:])  # (2, N, Y)
            kl = kl_rows(anchor, F, mask)  # (2,)
            F0s.append(F[0])
            goals.append(F[1])
            penalties.append(self.kl_weight * kl.sum())
        return torch.stack(F0s), torch.stack(goals), torch.stack(penalties)

    def fallback(self, rows: Sequence[int]) -> _Frozen:
        """The trained weights' reading (the anchors) for the problems at ``rows``: the
        frozen beliefs a window that decoded no move is retried with (`task.beliefs`)."""
        crisp = None if self.crisp_states is None else [self.crisp_states[r] for r in rows]
        F0 = torch.stack([self.anchors[r][0] for r in rows])
        return _Frozen(F0, torch.stack([self.anchors[r][1] for r in rows]), crisp)

    def parameters(self) -> list[Tensor]:
        if self.mode.adapt is Adapt.HEAD:
            return [p for m in self.models for p in m.head_parameters()]
        return [p for m in self.models for p in m.parameters()]


class ImageBeliefs:
    """A `task.beliefs.BeliefSource` that reads every window's states from images.

    ``observe(i, state)`` returns the current camera image of problem i (whose true state is
    ``state``); ``goal_images[i]`` is its goal image. Images are blurred per ``mode.blur``.
    ``colours[i]``: the RGB colour of each block of problem i (default: the first ``n`` palette
    colours, `block_colours`).
    With ``mode.crisp == "perceived"`` each window also gives the planner the most likely valid
    state of the current image under the trained weights (``crisp_states``).
    """

    def __init__(
        self,
        problems: Sequence[Problem],
        perceiver: Perceiver,
        observe: Observe,
        goal_images: Sequence[np.ndarray],
        mode: PerceptionMode,
        colours: Sequence[Colours] | None = None,
    ) -> None:
        if mode.mode is Perception.STATE:
            raise TampError("ImageBeliefs needs mode 'frozen' or 'optimised'")
        self.problems, self.perceiver, self.observe, self.mode = problems, perceiver, observe, mode
        self.colours = [block_colours(p.n) for p in problems] if colours is None else list(colours)
        self.goal_images = [blur(im, mode.blur) for im in goal_images]
        self.perception_s = 0.0  # time spent reading images (segmentation and the model)

    def _inputs(self, i: int, image: np.ndarray):
        p, colours = self.problems[i], self.colours[i]
        return self.perceiver.inputs(
            [blur(image, self.mode.blur), self.goal_images[i]],
            [colours, colours],
            [p.entities, p.entities],
        )

    def __call__(self, indices: Sequence[int], states: Sequence[State]):
        t0 = time.perf_counter()
        inputs = [self._inputs(i, self.observe(i, s)) for i, s in zip(indices, states, strict=True)]
        model = self.perceiver.model
        with torch.no_grad():  # one backbone pass per image pair: the anchors and the features
            features = [model.backbone(images) for images, _, _ in inputs]
            anchors = [  # (2, N, Y) each
                model.head(f, boxes, mask, images.shape[-2:])
                for f, (images, boxes, mask) in zip(features, inputs, strict=True)
            ]
        crisp = None
        if self.mode.crisp is Crisp.PERCEIVED:  # (N, Y) reading of the current image per problem
            crisp = [
                most_likely_state(self.problems[i], a[0])
                for i, a in zip(indices, anchors, strict=True)
            ]
        self.perception_s += time.perf_counter() - t0
        if self.mode.mode is Perception.FROZEN:
            return _Frozen(
                torch.stack([a[0] for a in anchors]), torch.stack([a[1] for a in anchors]), crisp
            )
        models = []
        for _ in indices:  # a fresh copy of the trained weights for every problem and window
            model = copy.deepcopy(self.perceiver.model)
            trained = (
                model.head_parameters() if self.mode.adapt is Adapt.HEAD else model.parameters()
            )
            for param in trained:
                param.requires_grad_(True)
            models.append(model)
        if self.mode.adapt is Adapt.ALL:
            features = [None] * len(inputs)  # each step reruns the adapted backbone
        return _Adapted(models, inputs, features, anchors, self.mode, crisp)


def perceived_goal(
    problem: Problem,
    perceiver: Perceiver,
    goal_image: np.ndarray,
    radius: int = 0,
    colours: Colours | None = None,
) -> Problem:
    """``problem`` whose goal is the perceived goal scene: every block's most likely support
    under the trained model's reading of ``goal_image`` (a valid state by construction)."""
    state, _ = perceived_state(problem, perceiver, goal_image, radius, colours)
    return dataclasses.replace(problem, goal=tuple(zip(problem.entities, state, strict=True)))


def perceived_state(
    problem: Problem,
    perceiver: Perceiver,
    image: np.ndarray,
    radius: int = 0,
    colours: Colours | None = None,
) -> tuple[State, Tensor]:
    """The most likely valid state of ``image`` and the soft supports F (N, Y) behind it.

    ``colours``: the RGB colour (in [0, 1]) of each block, in entity order (default: the first
    ``n`` palette colours, `block_colours`)."""
    colours = block_colours(problem.n) if colours is None else list(colours)
    x = perceiver.inputs([blur(image, radius)], [colours], [problem.entities])
    with torch.no_grad():
        F = perceiver.support(x)[0]  # (N, Y)
    return most_likely_state(problem, F), F
