"""Static obstacles on the table, the named scenes, and the clearance they leave above a slot.

A scene is the table, its slot grid and the boxes in `SceneConfig.obstacles`: ``tabletop`` has
none, ``shelf`` a board on two legs over the far row's ``y = 0.16`` and ``0.32`` slots,
``clutter`` thin posts between the slots and a wall close beside the ``y = -0.32`` column,
``cramped`` no obstacle but only 6 slots, two of them far from the robot.
Both simulators build the boxes, the camera sees them, and the arm's collision model checks
every trajectory against them (`motion.guard`, `robots.collision`). Obstacles are fixed and
known, like a map of the workcell; the blocks still come from observation.

The same four workcells ship as scene files, ``tamp/world/scenes/<name>.json`` (`tamp.world`,
schema 1, the obstacles as fixed boxes). This module is their source: the files are written from
`SCENES` and `GRIDS` by ``scripts/workcell_scenes.py`` (`tamp.world.convert.workcells`), and a
test fails when a file and its definition here differ.

The scene model knows what an overhead obstacle leaves free: `ceiling` is the highest the tool
(``panda_grasptarget``) may go above a point of the table with the arm still under every board
there, and `slot_capacity` the number of blocks a tower on a slot may have so the arm can still
pick its top block and place one more on it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from task.errors import TampError, one_of

# tool centre to the highest point of the wrist (link 6/7 and the hand) in a top-down grasp, and
# how far from the tool the hand and wrist reach sideways: the arm's footprint over a slot
ARM_ABOVE_TCP = 0.37  # m (measured: IK at the far row's slots against a board over them)
ARM_REACH = 0.12  # m
MIN_APPROACH = 0.03  # m, least room above a block top for the open hand to come down


@dataclass(frozen=True)
class Obstacle:
    """A fixed box: centre (m), half extents (m), yaw about z (rad), colour (RGB in [0, 1])."""

    name: str
    centre: tuple[float, float, float]
    half: tuple[float, float, float]
    yaw: float = 0.0
    rgb: tuple[float, float, float] = (0.62, 0.62, 0.6)

    def __post_init__(self) -> None:
        if len(self.centre) != 3 or len(self.half) != 3 or min(self.half) <= 0:
            raise TampError(f"obstacle {self.name!r}: centre and half extents must be 3 > 0 floats")

    @property
    def bottom(self) -> float:
        return self.centre[2] - self.half[2]

    def covers(self, xy: Sequence[float], pad: float = 0.0) -> bool:
        """True when the point ``xy`` lies within the footprint grown by ``pad`` (m)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = xy[0] - self.centre[0], xy[1] - self.centre[1]
        u, v = c * dx + s * dy, -s * dx + c * dy  # in the box frame
        return abs(u) <= self.half[0] + pad and abs(v) <= self.half[1] + pad


WOOD = (0.55, 0.5, 0.42)
# over the far row's y = 0.16 and 0.32 slots, 64 cm up (room for towers of 5 under it, the
# tallest in PlanBench, but not for the usual hover over them); both legs at its outer side,
# out of the arm's reach and of the camera's line of sight to the slots
SHELF = (
    Obstacle("shelf_board", (0.63, 0.285, 0.65), (0.15, 0.205, 0.01), rgb=WOOD),
    Obstacle("shelf_leg_a", (0.50, 0.475, 0.32), (0.012, 0.012, 0.32), rgb=WOOD),
    Obstacle("shelf_leg_b", (0.765, 0.475, 0.32), (0.012, 0.012, 0.32), rgb=WOOD),
)
POST = (0.015, 0.015, 0.075)  # half extents: 3 cm square, 15 cm tall
POSTS_Y = (-0.24, -0.08, 0.08, 0.24)  # between the slot columns, between the two rows
CLUTTER = (
    *(Obstacle(f"post_{i}", (0.48, y, 0.075), POST) for i, y in enumerate(POSTS_Y)),
    Obstacle("wall", (0.48, -0.455, 0.15), (0.2, 0.01, 0.15)),  # beside the y = -0.32 column
)
SCENES: dict[str, tuple[Obstacle, ...]] = {
    "tabletop": (),
    "shelf": SHELF,
    "clutter": CLUTTER,
    "cramped": (),
}
# scenes with their own slot grid (x values, y values): ``cramped`` has 6 slots in 3 rows, the
# far one (x = 0.72 m) near the end of the arm's comfortable reach
GRIDS = {"cramped": ((0.40, 0.56, 0.72), (-0.12, 0.12))}


def with_scene(config, name: str):
    """``config`` (a `tamp.scene.SceneConfig`) with the obstacles (and slot grid) of the named
    scene."""
    if name not in SCENES:
        raise TampError(f"unknown scene {one_of(name, tuple(SCENES))}")
    grid = dict(zip(("slot_xs", "slot_ys"), GRIDS[name], strict=True)) if name in GRIDS else {}
    return replace(config, obstacles=SCENES[name], name=name, **grid)


def ceiling(xy: Sequence[float], obstacles: Sequence[Obstacle]) -> float:
    """The highest tool (TCP) height (m) over table point ``xy`` that keeps the wrist under
    every overhead obstacle near it (inf when nothing is overhead). An obstacle that stands on
    the table is not overhead: the collision check, not this, keeps the arm off it."""
    tops = [
        o.bottom - ARM_ABOVE_TCP for o in obstacles if o.bottom > 0.05 and o.covers(xy, ARM_REACH)
    ]
    return min(tops, default=math.inf)


def slot_capacity(xy: Sequence[float], obstacles: Sequence[Obstacle], block: float) -> int | None:
    """How many blocks a tower on table point ``xy`` may have (None: no limit). The tool holds
    a block at its centre, so placing (or picking) block k needs its centre, ``(k - 1/2)``
    blocks up, plus the open hand's least approach, under the `ceiling`."""
    top = ceiling(xy, obstacles)
    if math.isinf(top):
        return None
    return max(0, math.floor((top - MIN_APPROACH) / block + 0.5))
