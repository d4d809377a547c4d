"""Where every block stands in a planned state: the poses that motion-aware planning prices a
move among (`tamp.arm.costs.ArmCosts`). Blocks keep their observed places; a tower moved to the
table stands on a free slot, or on its planned table place (`tamp.slots`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from tamp.scene import Pose, SceneConfig, free_slot, towers
from tamp.world.convert.from_poses import read_state
from task.domains.base import State


def predict_poses(
    entities: Sequence[str],
    state: State,
    poses: Mapping[str, Pose],
    scene: SceneConfig,
    bases: Mapping[str, tuple[float, float]] | None = None,
) -> dict[str, Pose]:
    """Block poses after the plan reached ``state`` from the observed ``poses``: a block with
    the same blocks under it as observed keeps its observed pose; otherwise its tower keeps
    the base block's observed table position when that base was on the table, else it stands
    on a free slot, and the block stands exactly above the base. ``bases``: where each tower
    base stands (a planned table place, `tamp.slots`) instead."""
    s, out = scene.block_size, {}
    stacks = towers(entities, state)
    seen = read_state(entities, poses, scene).state
    before = (
        {}
        if seen is None
        else {x: tuple(t[:k]) for t in towers(entities, seen) for k, x in enumerate(t)}
    )
    grounded = [t for t in stacks if abs(poses[t[0]].xyz[2] - s / 2) <= scene.tol_z]
    if bases is not None:
        grounded = stacks
    for tower in grounded:
        base, stays = poses[tower[0]], True
        if bases is not None:  # moved onto its planned place unless it stands there already
            xy = bases[tower[0]]
            if before.get(tower[0]) != () or math.dist(base.xy, xy) > scene.slot_radius:
                base, stays = Pose((*xy, s / 2), 0.0), False
        for level, x in enumerate(tower):
            out[x] = Pose((base.xyz[0], base.xyz[1], s / 2 + level * s), base.yaw)
            if stays and before.get(x) == tuple(tower[:level]):
                out[x] = poses[x]  # nothing under it changed
    for tower in (t for t in stacks if t not in grounded):
        taken = {k: v for k, v in out.items()}
        slot = free_slot(taken, poses[tower[0]].xyz, scene) or scene.slots[0]
        for level, x in enumerate(tower):
            out[x] = Pose((slot[0], slot[1], s / 2 + level * s), 0.0)
    return out
