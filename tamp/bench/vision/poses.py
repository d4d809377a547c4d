"""The pose benchmark (``tamp bench poses``): block poses read from RGB-D images against truth.

`run` renders ``n`` random scenes in each simulator (`tamp.camera.dataset.sample_scene`: 3-6
blocks, random towers, the dataset's placement jitter; the default camera and light, or with
``jitter`` the dataset's random camera and light), estimates every block's pose from the
simulator's RGB-D image (`tamp.camera.poses`) and compares it with the pose the block was put
at. Scene ``i`` is the same in every simulator. `summarise` gives per simulator the blocks
estimated, the position error (mm) and the yaw error (degrees, modulo the cube's 90 degrees),
for all blocks and split by whether the block's top face is free (top of a tower, or alone)
or covered by the block on it. `tamp.bench.tables.poses_table` prints them.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, replace

import numpy as np

from tamp.camera.dataset import sample_scene
from tamp.camera.poses import estimate_fits
from tamp.camera.render import (
    StateRenderer,
    View,
    ViewJitter,
    block_colours,
    jitter_camera,
    random_lighting,
)
from tamp.scene import CAMERA_COLOURS, SceneConfig, towers
from tamp.sim.base import Lighting
from task.errors import TampError

SPLITS = ("all", "top", "covered")


@dataclass(frozen=True)
class BlockRow:
    """One block of one scene: where it is, and how far the estimate is (None: no estimate)."""

    sim: str
    scene: int
    block: str
    blocks: int  # blocks in the scene
    level: int  # 0 on the table, 1 on one block, ...
    top_free: bool  # nothing rests on it
    reason: str  # why there is no estimate ("" when there is one)
    error_mm: float | None
    dx_mm: float | None
    dy_mm: float | None
    dz_mm: float | None
    yaw_error_deg: float | None


@dataclass(frozen=True)
class PoseBench:
    """Every block row of one pose benchmark and its summary per simulator."""

    sims: tuple[str, ...]
    rows: tuple[BlockRow, ...]
    summary: dict[str, dict]


def yaw_error(estimate: float, truth: float) -> float:
    """|estimate - truth| in degrees, modulo the cube's 90-degree symmetry (0..45)."""
    quarter = math.pi / 2
    return math.degrees(abs((estimate - truth + quarter / 2) % quarter - quarter / 2))


def _stats(values: Sequence[float]) -> dict | None:
    if not values:
        return None
    v = np.asarray(values, dtype=float)
    return {
        "mean": float(v.mean()),
        "median": float(np.median(v)),
        "p95": float(np.percentile(v, 95)),
        "max": float(v.max()),
    }


def summarise(rows: Sequence[BlockRow]) -> dict:
    """Per split (all, top free, covered): blocks, estimated, position and yaw error stats."""
    out = {}
    for split in SPLITS:
        chosen = [r for r in rows if split == "all" or r.top_free == (split == "top")]
        done = [r for r in chosen if r.error_mm is not None]
        out[split] = {
            "blocks": len(chosen),
            "estimated": len(done),
            "position_mm": _stats([r.error_mm for r in done]),
            "yaw_deg": _stats([r.yaw_error_deg for r in done]),
        }
    return out


def run(
    sims: Sequence[str],
    n: int,
    seed: int = 0,
    min_blocks: int = 3,
    max_blocks: int = 6,
    jitter: bool = False,
    progress: Callable[[str], None] | None = None,
) -> PoseBench:
    """``n`` scenes per simulator; ``progress(sim)`` after each scene."""
    if not 1 <= min_blocks <= max_blocks <= CAMERA_COLOURS:
        raise TampError(
            f"--min-blocks/--max-blocks: need 1 <= min <= max <= {CAMERA_COLOURS}, "
            f"got {min_blocks} and {max_blocks}"
        )
    view = ViewJitter()
    scene = replace(SceneConfig(), jitter_xy=view.place_xy, jitter_yaw=view.place_yaw)
    palette = block_colours(CAMERA_COLOURS)
    rows, summary = [], {}
    for sim in sims:
        mine, estimate_s = [], 0.0
        with StateRenderer(sim, scene) as renderer:
            for i in range(n):
                rng = np.random.default_rng([seed, i])
                names, colours, state = sample_scene(rng, min_blocks, max_blocks)
                camera = jitter_camera(renderer.camera, view, rng) if jitter else renderer.camera
                light = random_lighting(rng) if jitter else Lighting()
                view = View(camera, light, scene)
                truth = renderer.place(names, state, int(rng.integers(2**31)), colours, view)
                rgb, depth = renderer.sim.render_rgbd()
                t0 = time.perf_counter()
                fits = estimate_fits(
                    rgb, depth, camera, names, [palette[c] for c in colours], scene.block_size
                )
                estimate_s += time.perf_counter() - t0
                mine += _rows(sim, i, names, state, truth, fits)
                if progress is not None:
                    progress(sim)
        summary[sim] = summarise(mine) | {"estimate_ms_per_image": 1000 * estimate_s / max(n, 1)}
        rows += mine
    return PoseBench(tuple(sims), tuple(rows), summary)


def _rows(sim, scene, names, state, truth, fits) -> list[BlockRow]:
    level = {x: k for tower in towers(names, state) for k, x in enumerate(tower)}
    free = {tower[-1] for tower in towers(names, state)}
    out = []
    for x in names:
        fit, true = fits[x], truth[x]
        out.append(
            BlockRow(
                sim=sim,
                scene=scene,
                block=x,
                blocks=len(names),
                level=level[x],
                top_free=x in free,
                reason=fit if isinstance(fit, str) else "",
                **_errors(fit, true),
            )
        )
    return out


def _errors(fit, true) -> dict:
    """A `BlockRow`'s error fields: the estimate ``fit`` against the true pose, or all None
    when ``fit`` is the reason there is no estimate."""
    if isinstance(fit, str):
        return dict(error_mm=None, dx_mm=None, dy_mm=None, dz_mm=None, yaw_error_deg=None)
    d = 1000.0 * (np.asarray(fit.pose.xyz) - np.asarray(true.xyz))  # (3,) mm
    return dict(
        error_mm=float(np.linalg.norm(d)),
        dx_mm=float(d[0]),
        dy_mm=float(d[1]),
        dz_mm=float(d[2]),
        yaw_error_deg=yaw_error(fit.pose.yaw, true.yaw),
    )


def block_rows(bench: PoseBench) -> list[dict]:
    """One ``blocks.csv`` row per block and simulator."""
    return [asdict(r) for r in bench.rows]
