"""A check of the colour segmentation's thresholds on rendered datasets that are not evaluation
data: how many blocks of each colour it finds, how many scenes the model then reads right, and
how far the found dark (black) blocks sit from each threshold of the dark class.

Run on ``tamp perception dataset`` files (fresh seeds, never the LatPlan-40 images)::

    tamp bench segmentation FILE.npz [MORE.npz ...] --checkpoint FILE.pt [--out DIR]

Every image is first resized to the checkpoint's ``input_hw`` when it has one, as
`perception.perceive.Perceiver` does before segmenting. Each file gets its counts under the
current `SegmentConfig` and under the same thresholds without the two guards added against
one-colour images (``dark_contrast`` 0, ``max_area_share`` 1), so a change in what is found
shows. The margins are per image: the median over the black region's pixels of its value V,
its chroma, its ratio to the local background's V and its contrast below it; the report gives
their worst and 5th-percentile values across images next to the thresholds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, replace

import cv2
import numpy as np

from perception import data as pdata
from perception.errors import PerceptionError
from perception.segment import SegmentConfig, colour_labels, is_dark, present
from perception.train import checkpoint_scene, evaluate

UNGUARDED = replace(SegmentConfig(), dark_contrast=0, max_area_share=1.0)


def _margins(image: np.ndarray, palette: np.ndarray, dark: int, config: SegmentConfig):
    """Medians over the pixels labelled dark: (V, chroma, V / background V, background V - V);
    None when no pixel is."""
    labels = colour_labels(image, palette, config)  # (H, W)
    where = labels == dark
    if not where.any():
        return None
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    value = hsv[..., 2]
    rgb = image.astype(np.int16)
    chroma = rgb.max(-1) - rgb.min(-1)
    k = max(3, round(config.background_window * min(value.shape)) | 1)
    background = cv2.medianBlur(value, k).astype(np.float32)
    v, bg = value[where].astype(np.float32), background[where]
    return (
        float(np.median(v)),
        float(np.median(chroma[where])),
        float(np.median(v / np.maximum(bg, 1.0))),
        float(np.median(bg - v)),
    )


def check(
    data: pdata.SupportData,
    model,
    input_hw=None,
    progress: Callable[[int], None] | None = None,
) -> dict:
    """Blocks found per colour (current and unguarded thresholds), scenes read right by
    ``model``, and the dark class's margins, on every image of ``data``; ``input_hw``: the
    model's (H, W), each image resized to it first; ``progress(1)`` after each image."""
    if input_hw is not None:
        data = pdata.resize_data(data, input_hw)
    names = [f"#{k}" for k in range(len(data.palette))]
    dark = next((k for k, rgb in enumerate(data.palette) if is_dark(rgb)), None)
    found = {"current": dict.fromkeys(names, 0), "unguarded": dict.fromkeys(names, 0)}
    shown = dict.fromkeys(names, 0)
    all_found, margins = 0, []
    for i, image in enumerate(data.images):
        colours = [int(c) for c in data.colours[i] if c >= 0]
        for label, config in (("current", SegmentConfig()), ("unguarded", UNGUARDED)):
            seen = present(image, data.palette[colours], config)
            for c, ok in zip(colours, seen, strict=True):
                found[label][names[c]] += int(ok)
            all_found += int(label == "current" and all(seen))
        for c in colours:
            shown[names[c]] += 1
        if dark is not None and dark in colours:
            margin = _margins(image, data.palette[colours], colours.index(dark), SegmentConfig())
            if margin is not None:
                margins.append(margin)
        if progress is not None:
            progress(1)
    scores = evaluate(model, pdata.tensors(data))
    out = {
        "images": len(data),
        "palette": [[round(float(c), 4) for c in rgb] for rgb in data.palette],
        "blocks_shown": shown,
        "blocks_found": found,
        "images_with_every_block_found": all_found,
        "relation_accuracy": scores["relation_accuracy"],
        "scene_accuracy": scores["scene_accuracy"],
        "scenes_read": scores["scenes"],
        "scenes_right": round(scores["scene_accuracy"] * scores["scenes"]),
        "unreadable": scores["unreadable"],
    }
    if margins:
        m = np.asarray(margins)  # (images, 4)
        config = SegmentConfig()
        out["dark_margins"] = {
            "images": len(m),
            "value (<= dark_value)": _spread(m[:, 0], config.dark_value, high=True),
            "chroma (< dark_chroma)": _spread(m[:, 1], config.dark_chroma, high=True),
            "ratio to background (<= dark_ratio)": _spread(m[:, 2], config.dark_ratio, high=True),
            "contrast (>= dark_contrast)": _spread(m[:, 3], config.dark_contrast, high=False),
        }
    return out


def _spread(values: np.ndarray, threshold: float, high: bool) -> dict:
    """The worst value and the 5th percentile from the threshold's side, and the median."""
    worst = float(values.max() if high else values.min())
    tail = float(np.percentile(values, 95 if high else 5))
    return {
        "threshold": threshold,
        "worst": worst,
        "p95" if high else "p5": tail,
        "median": float(np.median(values)),
    }


def thresholds() -> dict:
    """The two threshold sets every file is counted under: ``current`` (`SegmentConfig`) and
    what ``unguarded`` changes in it."""
    current = asdict(SegmentConfig())
    unguarded = {k: v for k, v in asdict(UNGUARDED).items() if current[k] != v}
    return {"current": current, "unguarded": unguarded}


def check_scene(path: str, data_meta: dict, checkpoint_meta: dict) -> None:
    """One PerceptionError line when the dataset at ``path`` shows another image scene than
    the checkpoint was trained on: its readings would be confidently wrong, and the scene
    counts would measure the wrong model."""
    shown, trained = data_meta.get("scene"), checkpoint_scene(checkpoint_meta)
    if shown is not None and trained is not None and shown != trained:
        raise PerceptionError(
            f"{path} shows the {shown} scene but the checkpoint was trained on {trained}; "
            f"pass a checkpoint trained on {shown} images"
        )
