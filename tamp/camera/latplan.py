"""LatPlan's rendered Blocksworld setting in our simulators, and a randomised dataset of it.

LatPlan's images (IBM/photorealistic-blocksworld, tag ``jair``) show 4 rubber "SmoothCylinder"
objects of size 0.7 (CLEVR units: radius 0.7, height 1.4; centres at z = 0.7, 2.1, 3.5), red,
blue, green and black, on one row of 5 table slots at x in {-3.5, -1.75, 0, 1.75, 3.5}, rendered
at 150x100 (and downscaled to 45x30). Here one CLEVR unit is ``block_size / 1.4`` metres, the
row runs along the world x axis through (``ROW_X``, 0), and LatPlan's +y (away from the camera)
is the world's +y.

The camera is the generator's published one, read from ``data/base_scene.blend`` of that tag
(see `CAMERA_SOURCE`): eye (0, -16, 6), a Track-To constraint on an Empty at (0, 0, 3), a 35 mm
lens on a 32 mm sensor fitted to the image width, so 49.13 degrees across and 33.90 degrees
vertically at 150x100. Nothing was fitted to the evaluation scenes.

`generate` renders random layouts (which block on what, which slot) in both simulators with
wide randomisation and writes `perception.data.SupportData`; layouts of the 80 evaluation
states (`evaluation_layouts`, read from the ``scene_tr`` JSON when present) are never drawn.
"""

from __future__ import annotations

import json
import math
import random
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from perception import data as pdata
from tamp.camera.dataset import check_settings, label_row
from tamp.camera.render import StateRenderer, View, ViewJitter, jitter_camera
from tamp.scene import SceneConfig, towers
from tamp.sim.base import SIMULATORS, Camera, Lighting
from task.symbolic.generate import block_names, random_towers

COLOURS = (
    ("red", (1.0, 0.0, 0.0)),
    ("blue", (0.0, 0.0, 1.0)),
    ("green", (0.0, 1.0, 0.0)),
    ("black", (0.0, 0.0, 0.0)),
)
SLOTS_CLEVR = (-3.5, -1.75, 0.0, 1.75, 3.5)  # table slots, CLEVR units
SIZE_CLEVR = 1.4  # cylinder height and diameter, CLEVR units
ROW_X = 0.5  # m, world x of the middle slot (in front of the robot)
SIZES = ((150, 100), (45, 30))  # (W, H): the render and LatPlan's planner input
EVALUATION = Path(__file__).resolve().parents[3] / "shared/data/latplan/prob-cylinders-4"
CAMERA_SOURCE = {
    "how": "published generator camera, read from the .blend file (not fitted to any scene)",
    "repository": "IBM/photorealistic-blocksworld, tag jair (db7dda16), data/base_scene.blend",
    "eye_clevr": [0.0, -16.0, 6.0],
    "target_clevr": [0.0, 0.0, 3.0],  # the Empty its Track-To constraint aims at
    "lens_mm": 35.0,
    "sensor_width_mm": 32.0,  # sensor fit AUTO: the wider image side
    "fitted_from_evaluation_scenes": False,
    # a check, not a fit: with this camera the 320 object locations of the 80 evaluation
    # scene_tr JSON files project onto their recorded pixel_coords within 0.5 px
    "checked": "reproduces the evaluation scenes' pixel_coords within 0.5 px (no jitter)",
}

Layout = tuple[tuple[str, ...], ...]  # per slot, bottom-to-top colour names


def unit(block_size: float = 0.05) -> float:
    """Metres per CLEVR unit when a cylinder is ``block_size`` tall."""
    return block_size / SIZE_CLEVR


def latplan_scene(block_size: float = 0.05) -> SceneConfig:
    """Cylinders of LatPlan's colours on one row of 5 slots, a floor and a backdrop wall."""
    k = unit(block_size)
    return SceneConfig(
        block_size=block_size,
        slot_xs=tuple(ROW_X + k * x for x in SLOTS_CLEVR),
        slot_ys=(0.0,),
        jitter_xy=0.0,
        jitter_yaw=math.pi,
        shape="cylinder",
        palette=COLOURS,
        floor_grey=0.45,
        backdrop_y=30.0 * k,
        backdrop_grey=0.55,
    )


def latplan_camera(block_size: float = 0.05, width: int = 150, height: int = 100) -> Camera:
    """The generator's camera (`CAMERA_SOURCE`) in this world, at ``width`` x ``height``."""
    k = unit(block_size)
    half_w = CAMERA_SOURCE["sensor_width_mm"] / 2 / CAMERA_SOURCE["lens_mm"]
    half_h = half_w * height / width if width >= height else half_w
    eye, target = CAMERA_SOURCE["eye_clevr"], CAMERA_SOURCE["target_clevr"]
    return Camera(
        eye=(ROW_X + k * eye[0], k * eye[1], k * eye[2]),
        target=(ROW_X + k * target[0], k * target[1], k * target[2]),
        fovy=math.degrees(2 * math.atan(half_h)),
        width=width,
        height=height,
    )


def scene_layout(path: str | Path) -> Layout:
    """The symbolic layout of one LatPlan ``scene_tr`` JSON: per slot, colours bottom to top."""
    objects = json.loads(Path(path).read_text())["objects"]
    slots: list[list[tuple[float, str]]] = [[] for _ in SLOTS_CLEVR]
    for obj in objects:
        rgb = np.asarray(obj["color"][:3], float)
        name = min(COLOURS, key=lambda c: float(np.abs(rgb - c[1]).sum()))[0]
        x, z = obj["location"][0], obj["location"][2]
        slots[min(range(len(SLOTS_CLEVR)), key=lambda i: abs(SLOTS_CLEVR[i] - x))].append((z, name))
    return tuple(tuple(name for _, name in sorted(s)) for s in slots)


def evaluation_layouts(root: str | Path = EVALUATION) -> frozenset[Layout] | None:
    """Layouts of every ``*/scene_tr/*.json`` under ``root`` (None when there are none)."""
    found = sorted(Path(root).glob("*/scene_tr/*.json")) if Path(root).is_dir() else []
    return frozenset(scene_layout(p) for p in found) if found else None


def layout_of(names: Sequence[str], colours: Sequence[int], state, slots: Sequence[int]) -> Layout:
    """The symbolic layout of a sampled scene (tower i, in `towers` order, on slot slots[i])."""
    colour_of = {x: COLOURS[c][0] for x, c in zip(names, colours, strict=True)}
    out: list[tuple[str, ...]] = [() for _ in SLOTS_CLEVR]
    for tower, k in zip(towers(names, state), slots, strict=True):
        out[k] = tuple(colour_of[x] for x in tower)
    return tuple(out)


@dataclass(frozen=True)
class Randomisation:
    """Ranges of the domain randomisation (uniform unless said otherwise). Camera ranges are in
    CLEVR units (converted to metres with the scene's unit)."""

    eye_clevr: float = 1.0  # +- on each eye coordinate
    target_clevr: float = 0.5  # +- on each target coordinate
    fovy_deg: float = 2.0  # +- on the field of view
    place_clevr: float = 0.1  # +- block placement (neighbouring towers stay 0.15 apart)
    grey: tuple[float, float] = (0.2, 0.65)  # floor and backdrop levels, drawn independently
    light_azimuth_deg: tuple[float, float] = (-30.0, 30.0)  # where the light comes from, from +x
    light_elevation_deg: tuple[float, float] = (35.0, 60.0)
    diffuse: tuple[float, float] = (0.5, 0.9)
    ambient: tuple[float, float] = (0.25, 0.6)
    shade_gain: tuple[float, float] = (0.55, 1.0)  # block colour = nominal * gain + offset
    shade_offset: float = 0.2  # offset per channel in [0, this]
    grain: tuple[float, float] = (0.0, 8.0)  # Gaussian sensor noise sigma, 0..255 levels
    blur: tuple[float, float] = (0.0, 1.2)  # Gaussian blur sigma at 150x100, pixels


def random_light(rng: np.random.Generator, rand: Randomisation) -> Lighting:
    """A light from the right-hand side, like the generator's key lamp at (6.4, -2.9, 4.3): the
    robot (left of the view, at the world origin) then casts its shadow out of the view."""
    az, el = (
        np.radians(rng.uniform(*rand.light_azimuth_deg)),
        np.radians(rng.uniform(*rand.light_elevation_deg)),
    )
    source = np.array([np.cos(az) * np.cos(el), np.sin(az) * np.cos(el), np.sin(el)])
    diffuse, ambient = rng.uniform(*rand.diffuse), rng.uniform(*rand.ambient)
    return Lighting(tuple(float(v) for v in -source), float(diffuse), float(ambient))


def _finish(image: np.ndarray, rng: np.random.Generator, rand: Randomisation) -> np.ndarray:
    """Blur and sensor grain on a rendered image (H, W, 3) uint8."""
    out = image.astype(np.float32)
    sigma = rng.uniform(*rand.blur)
    if sigma > 0.05:
        out = cv2.GaussianBlur(out, (0, 0), sigma)
    out += rng.normal(0.0, rng.uniform(*rand.grain), out.shape).astype(np.float32)
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


def downscale(images: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """(M, H, W, 3) uint8 -> (M, h, w, 3) by area averaging; ``size`` is (w, h)."""
    return np.stack([pdata.resize_image(im, size[::-1]) for im in images])


def generate(
    n: int,
    seed: int = 0,
    sims: Sequence[str] = SIMULATORS,
    min_blocks: int = 4,
    max_blocks: int = 4,
    rand: Randomisation = Randomisation(),
    exclude: Iterable[Layout] | None = None,
    exclude_source: str | None = None,
    progress: Callable[[int], None] | None = None,
    meta: dict | None = None,
) -> dict[tuple[int, int], pdata.SupportData]:
    """``n`` rendered samples at each of `SIZES`, seeded: {(W, H): SupportData}.

    The same scenes at both sizes (the 45x30 images are area-downscaled 150x100 renders, as
    LatPlan's are). ``exclude``: layouts never to draw (`evaluation_layouts`); ``meta['slots']``
    gives the table slot (0..4, left to right) of each block's tower, -1 for padding.
    """
    check_settings(sims, min_blocks, max_blocks, len(COLOURS))
    excluded = frozenset(exclude or ())
    scene, camera = latplan_scene(), latplan_camera()
    k = unit(scene.block_size)
    scene = replace(scene, jitter_xy=rand.place_clevr * k)
    jitter = ViewJitter(rand.eye_clevr * k, rand.target_clevr * k, rand.fovy_deg)
    images, colours_out, supports_out, slots_out = [], [], [], []
    slot_xs = np.asarray(scene.slot_xs)
    redrawn = 0
    renderers = {sim: StateRenderer(sim, scene, camera) for sim in sims}
    try:
        for i in range(n):
            rng = np.random.default_rng([seed, i])
            sim = renderers[sims[i % len(sims)]].sim
            (names, colours, state, slots), again = _layout(rng, (min_blocks, max_blocks), excluded)
            redrawn += again
            m = len(names)
            draw = int(rng.integers(2**31))
            view = View(jitter_camera(camera, jitter, rng), random_light(rng, rand), scene)
            poses = renderers[sims[i % len(sims)]].place(names, state, draw, colours, view, slots)
            _shade(sim, rng, rand)
            images.append(_finish(sim.render(), rng, rand))
            row_c, row_s = label_row(names, colours, state, max_blocks)
            colours_out.append(row_c)
            supports_out.append(row_s)
            where = [int(np.abs(slot_xs - poses[x].xyz[0]).argmin()) for x in names]
            slots_out.append(where + [-1] * (max_blocks - m))
            if progress is not None:
                progress(1)
    finally:
        for r in renderers.values():
            r.close()
    info = dict(meta or {})
    info.update(
        scene="latplan",
        seed=seed,
        sims=list(sims),
        n=n,
        blocks=[min_blocks, max_blocks],
        camera={**CAMERA_SOURCE, "world": camera.__dict__, "metres_per_clevr_unit": k},
        randomisation=rand.__dict__,
        slots=slots_out,
        evaluation_layouts_excluded=bool(excluded),
        excluded_layouts=len(excluded),
        excluded_from=exclude_source if excluded else None,
        redrawn_as_excluded=redrawn,
    )
    return _at_sizes(np.stack(images), np.stack(colours_out), np.stack(supports_out), info)


def _layout(rng: np.random.Generator, blocks: tuple[int, int], excluded: frozenset):
    """A drawn scene of ``blocks`` (least, most) blocks whose layout is not ``excluded``:
    its (names, colours, state, tower slots), and how many excluded ones were drawn first."""
    redrawn = 0
    while True:
        m = int(rng.integers(blocks[0], blocks[1] + 1))
        names = block_names(m)
        colours = [int(c) for c in rng.permutation(len(COLOURS))[:m]]
        state = random_towers(names, random.Random(int(rng.integers(2**31))))
        slots = [int(s) for s in rng.permutation(len(SLOTS_CLEVR))]
        slots = slots[: len(towers(names, state))]
        if layout_of(names, colours, state, slots) not in excluded:
            return (names, colours, state, slots), redrawn
        redrawn += 1


def _shade(sim, rng: np.random.Generator, rand: Randomisation) -> None:
    """Random greys of the floor and the backdrop and random shades of the block colours."""
    for part in ("floor", "backdrop"):
        sim.set_colour(part, [rng.uniform(*rand.grey)] * 3)
    for name, rgb in COLOURS:
        gain = rng.uniform(*rand.shade_gain)
        shade = np.asarray(rgb) * gain + rng.uniform(0.0, rand.shade_offset, 3)
        sim.set_colour(name, np.clip(shade, 0.0, 1.0))


def _at_sizes(full: np.ndarray, colours, supports, info: dict):
    """The samples at each of `SIZES`: the ``full`` (M, 100, 150, 3) renders, area-downscaled
    where the size is smaller, with their labels: {(W, H): SupportData}."""
    palette = np.asarray([rgb for _, rgb in COLOURS], dtype=np.float32)
    out = {}
    for size in SIZES:
        pics = full if full.shape[2:0:-1] == size else downscale(full, size)
        out[size] = pdata.SupportData(
            pics, colours, supports, palette, {**info, "size": list(size)}
        )
    return out
