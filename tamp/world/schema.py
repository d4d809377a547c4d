"""The scene file: its versioned JSON schema and the frozen dataclasses it parses into.

A scene file is one JSON object (read with the standard library's `json`). Units are metres and
radians throughout; the world frame is the robot base frame (``panda_link0``, z up) and the
table surface is z = 0, as in `tamp.scene`. Names are PDDL names (lowercase letters, digits,
``-`` and ``_``, starting with a letter), unique over objects, regions and obstacles, and never
``table``. Fields marked optional may be left out; no other field is allowed.

Schema version 1::

    {
      "schema": 1,                       # this format's version (an integer; only 1 exists)
      "name": "tray-demo",               # the scene's name
      "table": {"min": [x, y], "max": [x, y]},     # the table top's extent in the base frame
      "slots": {"xs": [x, ...], "ys": [y, ...]},   # optional: the table slot grid
                                                    #   (`tamp.scene.SceneConfig.slot_xs/ys`)
      "regions": [                       # optional: named rectangles on the table
        {"name": "tray",
         "min": [x, y], "max": [x, y],   # axis-aligned rectangle, inside the table
         "on": "shelf_board",            # optional: lies on this obstacle's top (default: table)
         "floor": 0.0,                   # optional: thickness of the region's base (a plate,
                                         #   a tray's bottom), a solid slab; its top is the
                                         #   surface objects rest on
         "wall_height": 0.0,             # optional: walls along the rectangle's edges rising
         "wall_thickness": 0.01,         #   this high above the surface (0: no walls), inside
                                         #   the rectangle, this thick
         "colour": "brown"}              # optional: a palette name or [r, g, b] in [0, 1]
      ],
      "obstacles": [                     # optional: fixed boxes (`tamp.obstacles.Obstacle`)
        {"name": "post_0", "centre": [x, y, z], "half": [hx, hy, hz],
         "yaw": 0.0,                     # optional, about z
         "colour": [0.62, 0.62, 0.6]}    # optional
      ],
      "objects": [                       # optional: the movable objects
        {"name": "a",
         "kind": "cube",                 # cube | cuboid | cylinder
         "size": 0.05,                   # cube: its edge; cuboid: [x, y, z] full extents in
                                         #   its own frame; cylinder: [diameter, height]
         "colour": "red",                # a palette name (`tamp.scene.PALETTE`) or [r, g, b]
         "pose": {"xyz": [x, y, z],      # the centre
                  "yaw": 0.0}}           # optional, about z (objects stand upright)
      ],
      "camera": {"eye": [x, y, z], "target": [x, y, z],    # optional (`tamp.sim.base.Camera`);
                 "up": [0, 0, 1], "fovy": 40.0,            #   every key but eye and target is
                 "width": 320, "height": 240},             #   optional, fovy in degrees
      "parking": true                    # optional: whether an object may be set down on the
                                         #   bare table (default true); false: only in the
                                         #   regions and on objects (Tower of Hanoi's pegs)
    }

`tamp.world.load` checks a file against this schema and against geometry (nothing overlaps,
nothing floats, everything within the arm's reach); `tamp.world.relations` reads the symbolic
state from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tamp.obstacles import Obstacle
from tamp.scene import Pose
from tamp.sim.base import Camera
from task.errors import TampError, one_of

SCHEMA = 1  # the version this code reads and writes


class SceneFileError(TampError):
    """A scene file (or its goal) is malformed: one line naming the field and the problem."""


@dataclass(frozen=True)
class Table:
    """The table top: an axis-aligned rectangle at z = 0, ``lo`` and ``hi`` its (x, y) corners."""

    lo: tuple[float, float]
    hi: tuple[float, float]

    def holds(self, xy, pad: float = 0.0) -> bool:
        """True when the point ``xy`` lies on the table (grown by ``pad``, m)."""
        return all(self.lo[i] - pad <= xy[i] <= self.hi[i] + pad for i in range(2))


@dataclass(frozen=True)
class Region:
    """A named rectangle on the table (or on an obstacle's top, ``on``) that objects go in.

    ``surface`` is the height objects in it rest at: the top of what it lies on plus ``floor``.
    Walls, when ``wall_height`` > 0, stand inside the rectangle along its four edges.
    """

    name: str
    lo: tuple[float, float]
    hi: tuple[float, float]
    surface: float = 0.0  # m, z of the face objects rest on
    floor: float = 0.0  # m, thickness of the base slab (0: a marked area)
    on: str | None = None  # the obstacle it lies on (None: the table)
    wall_height: float = 0.0  # m above the surface (0: no walls)
    wall_thickness: float = 0.01  # m
    rgb: tuple[float, float, float] = (0.5, 0.3, 0.1)

    @property
    def base(self) -> float:
        """z of the face the region lies on (the table's 0 or the obstacle's top)."""
        return self.surface - self.floor

    def inner(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """The rectangle inside the walls (the whole rectangle when it has none)."""
        t = self.wall_thickness if self.wall_height > 0 else 0.0
        return (self.lo[0] + t, self.lo[1] + t), (self.hi[0] - t, self.hi[1] - t)

    def walls(self) -> tuple[Obstacle, ...]:
        """The four walls as boxes (none when ``wall_height`` is 0)."""
        if self.wall_height <= 0:
            return ()
        t, h = self.wall_thickness, self.wall_height
        (x0, y0), (x1, y1) = self.lo, self.hi
        z, cx, cy = self.surface + h / 2, (x0 + x1) / 2, (y0 + y1) / 2
        hx, hy = (x1 - x0) / 2, (y1 - y0) / 2
        return (
            Obstacle(f"{self.name}:wall_x0", (x0 + t / 2, cy, z), (t / 2, hy, h / 2), rgb=self.rgb),
            Obstacle(f"{self.name}:wall_x1", (x1 - t / 2, cy, z), (t / 2, hy, h / 2), rgb=self.rgb),
            Obstacle(f"{self.name}:wall_y0", (cx, y0 + t / 2, z), (hx, t / 2, h / 2), rgb=self.rgb),
            Obstacle(f"{self.name}:wall_y1", (cx, y1 - t / 2, z), (hx, t / 2, h / 2), rgb=self.rgb),
        )

    def slab(self) -> Obstacle | None:
        """The base slab as a box (None when ``floor`` is 0)."""
        if self.floor <= 0:
            return None
        centre = ((self.lo[0] + self.hi[0]) / 2, (self.lo[1] + self.hi[1]) / 2)
        half = ((self.hi[0] - self.lo[0]) / 2, (self.hi[1] - self.lo[1]) / 2, self.floor / 2)
        return Obstacle(f"{self.name}:floor", (*centre, self.base + self.floor / 2), half)


@dataclass(frozen=True)
class Movable:
    """A movable object standing upright: ``kind`` (one of `motion.grasps.KINDS`), ``size`` as
    in the file (cube: (edge,); cuboid: (x, y, z) full extents; cylinder: (diameter, height)),
    colour and the pose of its centre."""

    name: str
    kind: str
    size: tuple[float, ...]
    rgb: tuple[float, float, float]
    pose: Pose

    @property
    def half(self) -> tuple[float, float, float]:
        """Half extents (x, y, z) in the object's frame (a cylinder: radius, radius, h / 2)."""
        if self.kind == "cube":
            return (self.size[0] / 2,) * 3
        if self.kind == "cylinder":
            return (self.size[0] / 2, self.size[0] / 2, self.size[1] / 2)
        return (self.size[0] / 2, self.size[1] / 2, self.size[2] / 2)

    @property
    def width(self) -> float:
        """The footprint's larger side (m): how wide the object is however it is turned."""
        return 2.0 * max(self.half[0], self.half[1])

    @property
    def bottom(self) -> float:
        return self.pose.xyz[2] - self.half[2]

    @property
    def top(self) -> float:
        return self.pose.xyz[2] + self.half[2]

    @property
    def reach(self) -> float:
        """Horizontal distance (m) of the centre from the robot base's z axis."""
        return math.hypot(self.pose.xyz[0], self.pose.xyz[1])


@dataclass(frozen=True)
class Slots:
    """The table slot grid (`tamp.scene.SceneConfig.slot_xs` x ``slot_ys``)."""

    xs: tuple[float, ...]
    ys: tuple[float, ...]


@dataclass(frozen=True)
class Scene:
    """A parsed scene file (see the module docstring for the schema)."""

    name: str
    table: Table
    regions: tuple[Region, ...] = ()
    obstacles: tuple[Obstacle, ...] = ()
    objects: tuple[Movable, ...] = ()
    slots: Slots | None = None
    camera: Camera | None = None
    parking: bool = True  # an object may be set down on the bare table (else: regions, objects)

    def object(self, name: str) -> Movable:
        """The object named ``name``; SceneFileError listing the objects when there is none."""
        for o in self.objects:
            if o.name == name:
                return o
        raise SceneFileError(f"unknown object {one_of(name, [o.name for o in self.objects])}")

    def region(self, name: str) -> Region:
        """The region named ``name``; SceneFileError listing the regions when there is none."""
        for r in self.regions:
            if r.name == name:
                return r
        raise SceneFileError(f"unknown region {one_of(name, [r.name for r in self.regions])}")
