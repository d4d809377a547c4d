"""Planning from a pair of photographs (initial, goal) that nobody rendered for us.

There is no ground truth and no camera in the loop: the blocks are the scene's colours found in
both images (`blocks_in`, named by colour), the trained model reads the most likely valid state
of each image (`tamp.camera.from_images.perceived_state`), and those two perceived states make
the problem (the goal: every block's support in the goal image). `plan_from_images` plans it
under the perceived protocol with the chosen perception mode (`ImageBeliefs`); the world it
plans in is the perceived initial state. Only the initial state was photographed: windows that
start elsewhere start from the one-hot state the plan's moves reach (`Unseen`) and keep reading
the goal image. ``tamp plan-images`` and ``tamp bench latplan`` both plan through here.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np
import torch

from perception.perceive import Perceiver
from perception.segment import present
from tamp.camera.from_images import ImageBeliefs, PerceptionMode, perceived_goal, perceived_state
from tamp.modes import Crisp, ImageScene
from tamp.scene import CAMERA_COLOURS, PALETTE
from task.beliefs import WindowBeliefsBase
from task.config import PlannerConfig
from task.domains import blocksworld, get_domain
from task.errors import TampError
from task.planner import plan
from task.problem import TABLE, Action, PlanResult, Problem

RGB = tuple[float, float, float]


def scene_colours(scene: str) -> tuple[tuple[str, RGB], ...]:
    """The block colours a scene's images may show, (name, RGB in [0, 1]) in palette order."""
    if scene == ImageScene.LATPLAN:
        from tamp.camera.latplan import COLOURS

        return COLOURS
    return PALETTE[:CAMERA_COLOURS]


def input_size(scene: str) -> tuple[int, int]:
    """(H, W): the size of the images the scene's perception model reads (its renders: the
    camera's 320x240 for ``cubes``, LatPlan's 150x100 for ``latplan``)."""
    if scene == ImageScene.LATPLAN:
        from tamp.camera.latplan import SIZES

        return SIZES[0][1], SIZES[0][0]
    from tamp.sim.base import Camera

    return Camera().height, Camera().width


def fit_image(image: np.ndarray, scene: str) -> np.ndarray:
    """``image`` (H, W, 3) shrunk, aspect kept (pixel-area averaging), to fit the scene's
    `input_size`; unchanged when it fits already (never enlarged). A photograph of thousands
    of pixels a side is read at the size the model reads, not segmented at full size."""
    h, w = input_size(scene)
    scale = min(h / image.shape[0], w / image.shape[1])
    if scale >= 1.0:
        return image
    size = (max(1, round(image.shape[1] * scale)), max(1, round(image.shape[0] * scale)))
    return cv2.resize(image, size, interpolation=cv2.INTER_AREA)  # (h', w', 3)


def read_image(path: str | Path, scene: str | None = None) -> np.ndarray:
    """An RGB uint8 image (H, W, 3) from a PNG or JPG file (RGBA: alpha dropped), shrunk to
    fit ``scene``'s `input_size` when a scene is given (`fit_image`); one-line TampError
    otherwise."""
    path = str(path)
    if not Path(path).is_file():
        raise TampError(f"no image file at {path}")
    raw = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if raw is None:
        raise TampError(f"cannot read {path} as an image (expected PNG or JPG)")
    if raw.dtype == np.uint16:
        raw = (raw >> 8).astype(np.uint8)
    if raw.dtype != np.uint8:
        raise TampError(f"{path}: unsupported pixel type {raw.dtype} (expected 8- or 16-bit)")
    if raw.ndim == 2 or raw.shape[2] not in (3, 4):
        raise TampError(f"{path} is not a colour image: blocks are told apart by colour")
    code = cv2.COLOR_BGRA2RGB if raw.shape[2] == 4 else cv2.COLOR_BGR2RGB
    image = np.ascontiguousarray(cv2.cvtColor(raw, code))
    return image if scene is None else fit_image(image, scene)


def check_sizes(images: Sequence[np.ndarray], paths: Sequence[str], model) -> None:
    """One-line errors for images of different sizes or a size the model cannot read."""
    (h0, w0), (h1, w1) = images[0].shape[:2], images[1].shape[:2]
    if (h0, w0) != (h1, w1):
        raise TampError(f"{paths[0]} is {w0}x{h0} but {paths[1]} is {w1}x{h1}: sizes must match")
    layers = len(model.config.channels)
    if min(h0, w0) < 2**layers:
        raise TampError(
            f"images of {w0}x{h0} are too small for the perception model: each of its {layers} "
            f"backbone layers halves the image, so it reads at least {2**layers}x{2**layers} pixels"
        )


def check_scene(images: Sequence[np.ndarray], paths: Sequence[str], scene: str) -> None:
    """One-line TampError when an image shows blocks of a colour ``scene`` cannot name but
    another image scene can (cube renders read as ``latplan`` would lose the orange cube, a
    LatPlan pair read as ``cubes`` the black cylinder), naming the colours found and the scene
    that reads them. The images are segmented for every image scene's colours at once (the
    chosen scene's own colours first, so a name both share is looked for as this scene's)."""
    looked = dict(scene_colours(scene))
    for other in ImageScene:
        for name, rgb in scene_colours(other):
            looked.setdefault(name, rgb)
    names, rgbs = list(looked), list(looked.values())
    looked_for = [name for name, _ in scene_colours(scene)]
    mine = set(looked_for)
    for path, image in zip(paths, images, strict=True):
        seen = [name for name, found in zip(names, present(image, rgbs), strict=True) if found]
        foreign = [name for name in seen if name not in mine]
        if not foreign:
            continue
        readers = [
            s for s in ImageScene if s != scene and set(seen) <= dict(scene_colours(s)).keys()
        ]
        fix = (
            f"read them with --image-scene {readers[0]}"
            if readers
            else "no image scene names all of them"
        )
        raise TampError(
            f"{path} shows {', '.join(seen)}: the {scene} scene has no {', '.join(foreign)} "
            f"block (its colours: {', '.join(looked_for)}); {fix}"
        )


def blocks_in(
    images: Sequence[np.ndarray], paths: Sequence[str], scene: str
) -> tuple[tuple[str, ...], list[RGB]]:
    """Names and colours of the scene's blocks found in both images; one-line errors for a
    block found in one image only and for images with no block."""
    check_scene(images, paths, scene)
    palette = scene_colours(scene)
    rgbs = [rgb for _, rgb in palette]
    seen = [present(im, rgbs) for im in images]
    odd = [
        f"{name} is in {paths[0 if a else 1]} but not in {paths[1 if a else 0]}"
        for (name, _), a, b in zip(palette, *seen, strict=True)
        if a != b
    ]
    if odd:
        raise TampError("the images show different blocks: " + "; ".join(odd))
    names = tuple(name for (name, _), a in zip(palette, seen[0], strict=True) if a)
    if not names:
        valid = ", ".join(name for name, _ in palette)
        raise TampError(f"no blocks found in {paths[0]} or {paths[1]} (looked for {valid})")
    return names, [rgb for (name, rgb) in palette if name in names]


class Unseen(WindowBeliefsBase):
    """Window beliefs for states no camera saw: the rows of problems whose state is not the
    photographed initial state start from that state one-hot (and are decoded against it);
    the goal (read from the goal image, adapted in ``optimised``) and the penalty are kept."""

    def __init__(self, inner, problem: Problem, states) -> None:
        self.inner, self.lr, self.problem, self.states = inner, inner.lr, problem, list(states)
        self.unseen = torch.tensor([s != problem.init for s in states])[:, None, None]
        domain = get_domain(problem.domain)
        self.onehot = domain.encode([problem] * len(states), states, torch.float32).F0
        read = zip(states, inner.crisp_states, strict=True)
        self.crisp_states = [s if s != problem.init else r for s, r in read]

    def fallback(self, rows):
        """Optimised beliefs: a stuck window is retried with the frozen ones (the inner
        beliefs' `fallback`, None for frozen beliefs), here for the same states."""
        frozen = self.inner.fallback(rows)
        if frozen is None:
            return None
        return Unseen(frozen, self.problem, [self.states[r] for r in rows])

    def compute(self):
        F0, goal, penalty = self.inner.compute()  # (P, N, Y), (P, N, Y), (P,)
        unseen, onehot = self.unseen.to(F0.device), self.onehot.to(F0.device)  # F0's device
        return torch.where(unseen, onehot, F0), goal, penalty

    def parameters(self):
        return self.inner.parameters()


@dataclass(frozen=True)
class ImagePlan:
    """A plan from an image pair: the perceived ``problem`` (blocks named by colour), the
    planner's ``result``, its 4-op ``actions``, and seconds spent reading the two states
    (``read_s``) and perceiving inside the planning windows (``perception_s``)."""

    problem: Problem
    result: PlanResult
    actions: tuple[Action, ...]
    read_s: float
    perception_s: float


def plan_from_images(
    init_image: np.ndarray,
    goal_image: np.ndarray,
    colours: Sequence[RGB],
    names: Sequence[str],
    perceiver: Perceiver,
    mode: str,
    config: PlannerConfig,
    seed: int = 0,
) -> ImagePlan:
    """Plan from an initial and a goal image (H, W, 3) uint8 whose blocks are ``names`` with
    RGB ``colours`` (`blocks_in`); ``mode`` is ``frozen`` or ``optimised`` perception."""
    t0 = time.perf_counter()
    n = len(names)
    blank = Problem("plan-images", blocksworld.NAME, tuple(names), (TABLE,) * n, ())
    init, _ = perceived_state(blank, perceiver, init_image, colours=colours)
    problem = perceived_goal(replace(blank, init=init), perceiver, goal_image, colours=colours)
    read_s = time.perf_counter() - t0
    perception = PerceptionMode(mode, crisp=Crisp.PERCEIVED)
    beliefs = ImageBeliefs(
        [problem], perceiver, lambda i, s: init_image, [goal_image], perception, [colours]
    )

    def source(indices, states):
        return Unseen(beliefs(indices, states), problem, states)

    result = plan(problem, config, seed, beliefs=source)
    actions = blocksworld.moves_to_actions(problem, result.plan.moves, strict=False)
    return ImagePlan(problem, result, actions, read_s, beliefs.perception_s)
