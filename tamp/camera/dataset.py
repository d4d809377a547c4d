"""The rendered support dataset: random Blocksworld states seen by the simulators' cameras.

Each sample draws 3 to 6 blocks with distinct camera colours, a random tower configuration,
random tower slots and placement jitter, a random light and a slightly moved camera, and renders
it in one simulator (samples alternate between the simulators asked for). A sample in which
colour segmentation cannot find every block (a block hidden behind a tower) is redrawn, and the
number redrawn is recorded in the file's meta.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from perception import data as pdata
from perception.errors import PerceptionError
from perception.segment import find_boxes
from tamp.camera.render import (
    StateRenderer,
    View,
    ViewJitter,
    block_colours,
    jitter_camera,
    random_lighting,
)
from tamp.scene import CAMERA_COLOURS, SceneConfig
from tamp.sim.base import SIMULATORS
from task.errors import TampError, one_of
from task.problem import TABLE
from task.symbolic.generate import block_names, random_towers


def sample_scene(rng: np.random.Generator, min_blocks: int, max_blocks: int):
    """(entities, colours, state) of one random scene."""
    n = int(rng.integers(min_blocks, max_blocks + 1))
    names = block_names(n)
    colours = [int(c) for c in rng.permutation(CAMERA_COLOURS)[:n]]
    state = random_towers(names, random.Random(int(rng.integers(2**31))))
    return names, colours, state


def check_settings(sims: Sequence[str], min_blocks: int, max_blocks: int, most: int) -> None:
    """One-line TampError for an unknown simulator or a block range outside 1..``most``."""
    for sim in sims:
        if sim not in SIMULATORS:
            raise TampError(f"unknown simulator {one_of(sim, SIMULATORS)}")
    if not 1 <= min_blocks <= max_blocks <= most:
        raise TampError(f"need 1 <= min_blocks <= max_blocks <= {most}")


def label_row(names, colours, state, width: int) -> tuple[np.ndarray, np.ndarray]:
    """One sample's ``colours`` and ``supports`` rows (`perception.data`), padded to ``width``."""
    row_c = np.full(width, -1, dtype=np.int8)
    row_s = np.full(width, pdata.PAD, dtype=np.int8)
    row_c[: len(names)] = colours
    row_s[: len(names)] = [pdata.TABLE if s == TABLE else names.index(s) for s in state]
    return row_c, row_s


def generate(
    n: int,
    seed: int = 0,
    sims: Sequence[str] = SIMULATORS,
    min_blocks: int = 3,
    max_blocks: int = 6,
    jitter: ViewJitter = ViewJitter(),
    progress: Callable[[int], None] | None = None,
    meta: dict | None = None,
) -> pdata.SupportData:
    """``n`` rendered samples, seeded; ``progress(k)`` reports k more samples done."""
    check_settings(sims, min_blocks, max_blocks, CAMERA_COLOURS)
    scene = replace(SceneConfig(), jitter_xy=jitter.place_xy, jitter_yaw=jitter.place_yaw)
    palette = np.asarray(block_colours(CAMERA_COLOURS), dtype=np.float32)
    images, colours_out, supports_out = [], [], []
    redrawn = 0
    renderers = {sim: StateRenderer(sim) for sim in sims}
    try:
        for i in range(n):
            rng = np.random.default_rng([seed, i])
            sim = sims[i % len(sims)]
            renderer = renderers[sim]
            while True:
                names, colours, state = sample_scene(rng, min_blocks, max_blocks)
                camera = jitter_camera(renderer.camera, jitter, rng)
                draw = int(rng.integers(2**31))  # drawn before the light, as always
                view = View(camera, random_lighting(rng), scene)
                image = renderer.render(names, state, draw, colours, view)
                try:
                    find_boxes(image, palette[colours])
                    break
                except PerceptionError:
                    redrawn += 1
            row_c, row_s = label_row(names, colours, state, max_blocks)
            images.append(image)
            colours_out.append(row_c)
            supports_out.append(row_s)
            if progress is not None:
                progress(1)
    finally:
        for r in renderers.values():
            r.close()
    info = dict(meta or {})
    info.update(
        scene="cubes",  # the image scene (training copies it into the checkpoint's meta)
        seed=seed,
        sims=list(sims),
        n=n,
        blocks=[min_blocks, max_blocks],
        redrawn=redrawn,
        camera=renderers[sims[0]].camera.__dict__,
        jitter=jitter.__dict__,
    )
    return pdata.SupportData(
        np.stack(images), np.stack(colours_out), np.stack(supports_out), palette, info
    )
