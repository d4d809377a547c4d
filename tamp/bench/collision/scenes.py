"""The checker benchmark's scenes and seeded configuration samples.

A scene is a named scene's fixed boxes (`tamp.obstacles.SCENES`: the shelf's board and legs, the
clutter's posts and wall; ``cramped`` has none) plus seeded towers of blocks on its slots, each
tower no taller than the slot's capacity under an overhead board. The samples are configurations
drawn half uniformly in the datasheet joint box and half about q_home (normal, 0.8 rad per
joint, clipped): ``uniform`` keeps them all; ``near`` keeps those a wide sphere model (a 10 cm
margin) flags, i.e. within about 10 cm of a box, the table or another link, or touching one;
``moves`` pairs configurations both ends of which are free under the mesh model while the
straight joint path between them is not.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from motion.sphere_check import SphereCollision
from robots.collision import Box
from robots.panda import PANDA
from tamp.obstacles import SCENES, slot_capacity, with_scene
from tamp.scene import SceneConfig

NEAR_MARGIN = 0.10  # m: a configuration is near when the sphere model flags it at this margin
SPREAD = 0.8  # rad: the normal spread about q_home of half of every sample
TOWERS = 4  # towers of blocks per scene
MAX_TOWER = 4  # blocks in the tallest tower


def scene_boxes(name: str, seed: int) -> list[Box]:
    """The named scene's obstacles and ``TOWERS`` seeded towers (1 to ``MAX_TOWER`` blocks,
    at most the slot's capacity) on distinct slots, as collision boxes."""
    config = with_scene(SceneConfig(), name)
    boxes = [Box(o.name, tuple(o.centre), tuple(o.half), o.yaw) for o in SCENES[name]]
    rng = np.random.default_rng(seed)
    slots = config.slots
    edge = config.block_size
    half = (edge / 2,) * 3
    for k in rng.choice(len(slots), size=min(TOWERS, len(slots)), replace=False):
        x, y = slots[int(k)]
        room = slot_capacity((x, y), config.obstacles, edge)
        height = int(rng.integers(1, MAX_TOWER + 1))
        height = height if room is None else min(height, room)
        yaw = float(rng.uniform(-0.15, 0.15))
        for level in range(height):
            centre = (float(x), float(y), edge * (level + 0.5))
            boxes.append(Box(f"block_{int(k)}_{level}", centre, half, yaw))
    return boxes


def _candidates(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, J) configurations: the first half uniform in the joint box, the rest about q_home."""
    lo, hi = np.asarray(PANDA.q_min), np.asarray(PANDA.q_max)
    uniform = rng.uniform(lo, hi, (n - n // 2, lo.size))
    home = np.clip(np.asarray(PANDA.q_home) + rng.normal(0.0, SPREAD, (n // 2, lo.size)), lo, hi)
    return np.concatenate([uniform, home])  # (n, J)


def uniform(n: int, seed: int) -> np.ndarray:
    """(n, J) seeded configurations, shuffled (half in the joint box, half about q_home)."""
    rng = np.random.default_rng(seed)
    return rng.permutation(_candidates(rng, n))


def near(boxes: Sequence[Box], n: int, seed: int, margin: float) -> np.ndarray:
    """(n, J) seeded configurations near the scene: flagged by the sphere model at ``margin`` +
    `NEAR_MARGIN` (colliding, or within that of a box, the table or another link)."""
    wide = SphereCollision(margin=margin + NEAR_MARGIN)
    wide.set_boxes(boxes)
    rng = np.random.default_rng(seed)
    found, count = [], 0
    while count < n:
        q = _candidates(rng, 4096)
        q = q[~wide.valid_batch(q)]
        found.append(q)
        count += len(q)
    return rng.permutation(np.concatenate(found))[:n]


def blocked_moves(mesh, spheres: SphereCollision, n: int, seed: int, max_step: float = 0.02):
    """``n`` seeded (start, goal) pairs ((n, J) each) about q_home, both ends free under the mesh
    model ``mesh`` (its boxes and margin as set) and its straight joint path not (checked every
    ``max_step`` rad); ``spheres`` (the same scene) screens the candidates first."""
    from robots.collision import densify

    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(PANDA.q_min), np.asarray(PANDA.q_max)
    starts, goals = [], []
    while len(starts) < n:
        q = np.clip(np.asarray(PANDA.q_home) + rng.normal(0.0, SPREAD, (512, lo.size)), lo, hi)
        q = q[spheres.valid_batch(q)]
        for a, b in zip(q[0::2], q[1::2], strict=False):
            _, line, _ = densify(np.stack([a, b]), np.full(2, PANDA.finger_open), max_step)
            if spheres.valid_batch(line).all():
                continue  # the straight path is free (the sphere model is conservative)
            if mesh.valid(a) and mesh.valid(b) and not mesh.check_path(np.stack([a, b])).ok:
                starts.append(a)
                goals.append(b)
                if len(starts) == n:
                    break
    return np.array(starts), np.array(goals)  # (n, J) each
