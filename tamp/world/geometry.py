"""Upright solids on the table: footprints, overlaps, and what each object rests on.

Every thing in a scene is an upright solid, a box turned about z (objects, obstacles, region
walls and base slabs) or an upright cylinder, so two things overlap when their height intervals
and their footprints both do, and an object rests on a face when its bottom lies at the face's
height and its footprint touches the face's. Both the loader's checks (`tamp.world.load`) and
the symbolic reading (`tamp.world.relations`) use these, with the same `Tolerances`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tamp.obstacles import Obstacle
from tamp.scene import SceneConfig
from tamp.world.schema import Movable, Region, Scene

TABLE_FACE = "table"


@dataclass(frozen=True)
class Tolerances:
    """How exact a scene must be (m). A file is authored, so the defaults are tight; reading
    observed poses wants looser ones (`loop_tolerances`, `LOOP`)."""

    z: float = 0.005  # a bottom this close to a face rests on it; farther above floats
    overlap: float = 0.002  # two solids may interpenetrate this much (contact, not overlap)
    edge: float = 0.0  # a footprint "in" a region may cross its edge this much (sensing)
    # an object rests on another object only when its centre lies over the other's footprint
    # grown by this (its weight is carried there); None: whenever the footprints overlap
    centre: float | None = None


TIGHT = Tolerances()  # the default: a scene file's


def loop_tolerances(config: SceneConfig = SceneConfig()) -> Tolerances:
    """The closed loop's tolerances for observed block poses
    (`tamp.world.convert.from_poses.read_state`): a bottom within ``config.tol_z`` of a face
    rests on it (sensing and settling), and a block rests on another only with its centre over
    that block's footprint, so a block across two reads as on the one that carries it, as the
    loop stacks, and a block tipped past its support's edge (which falls) rests on neither."""
    return Tolerances(z=config.tol_z, centre=0.0)


LOOP = loop_tolerances()  # the loop's, on the default table


@dataclass(frozen=True)
class Solid:
    """An upright solid: centre (m), half extents (m; a cylinder's are radius, radius, h / 2),
    yaw about z (rad)."""

    name: str
    cylinder: bool
    centre: tuple[float, float, float]
    half: tuple[float, float, float]
    yaw: float = 0.0

    @property
    def bottom(self) -> float:
        return self.centre[2] - self.half[2]

    @property
    def top(self) -> float:
        return self.centre[2] + self.half[2]

    def local(self, xy) -> tuple[float, float]:
        """The point ``xy`` in the solid's frame (x, y relative to the centre, unturned)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = xy[0] - self.centre[0], xy[1] - self.centre[1]
        return c * dx + s * dy, -s * dx + c * dy

    def covers(self, xy, pad: float = 0.0) -> bool:
        """True when the point ``xy`` lies within the footprint grown by ``pad`` (m)."""
        u, v = self.local(xy)
        if self.cylinder:
            return math.hypot(u, v) <= self.half[0] + pad
        return abs(u) <= self.half[0] + pad and abs(v) <= self.half[1] + pad

    def corners(self) -> list[tuple[float, float]]:
        """The footprint's corners (a cylinder: those of its bounding square, turned)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hx, hy = self.half[0], self.half[1]
        return [
            (self.centre[0] + c * u - s * v, self.centre[1] + s * u + c * v)
            for u, v in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))
        ]


def of_movable(o: Movable) -> Solid:
    return Solid(o.name, o.kind == "cylinder", o.pose.xyz, o.half, o.pose.yaw)


def of_box(o: Obstacle) -> Solid:
    return Solid(o.name, False, o.centre, o.half, o.yaw)


def fixed_solids(scene: Scene) -> list[Solid]:
    """The obstacles, region walls and region base slabs."""
    out = [of_box(o) for o in scene.obstacles]
    for r in scene.regions:
        out += [of_box(w) for w in r.walls()]
        slab = r.slab()
        if slab is not None:
            out.append(of_box(slab))
    return out


def _box_gap(a: Solid, b: Solid) -> float:
    """Separating distance of two turned rectangles (negative: they overlap by that much),
    by the separating axis theorem over both rectangles' edge normals."""
    best = -math.inf
    for r in (a, b):
        for ang in (r.yaw, r.yaw + math.pi / 2):
            ax = (math.cos(ang), math.sin(ang))
            pa = [p[0] * ax[0] + p[1] * ax[1] for p in a.corners()]
            pb = [p[0] * ax[0] + p[1] * ax[1] for p in b.corners()]
            best = max(best, min(pa) - max(pb), min(pb) - max(pa))
    return best


def _disc_box_gap(disc: Solid, box: Solid) -> float:
    u, v = box.local(disc.centre)
    du, dv = abs(u) - box.half[0], abs(v) - box.half[1]
    if du <= 0 and dv <= 0:
        return max(du, dv) - disc.half[0]
    return math.hypot(max(du, 0.0), max(dv, 0.0)) - disc.half[0]


def footprint_gap(a: Solid, b: Solid) -> float:
    """Distance (m) between two footprints on the table; negative when they overlap."""
    if a.cylinder and b.cylinder:
        return math.dist(a.centre[:2], b.centre[:2]) - a.half[0] - b.half[0]
    if a.cylinder:
        return _disc_box_gap(a, b)
    if b.cylinder:
        return _disc_box_gap(b, a)
    return _box_gap(a, b)


def apart(a: Solid, b: Solid) -> bool:
    """True when the circles around two footprints do not meet, so neither do the footprints
    (`footprint_gap` > 0): the cheap test that spares a scene of hundreds of objects its
    pairwise footprint tests."""
    reach = math.hypot(a.half[0], a.half[1]) + math.hypot(b.half[0], b.half[1])
    return math.dist(a.centre[:2], b.centre[:2]) > reach


def penetration(a: Solid, b: Solid) -> float:
    """How deep (m) two solids interpenetrate: the lesser of their overlaps in height and on
    the table (0 when they do not)."""
    dz = min(a.top, b.top) - max(a.bottom, b.bottom)
    if dz <= 0 or apart(a, b):  # apart in height or on the table
        return 0.0
    dxy = -footprint_gap(a, b)
    return max(0.0, min(dz, dxy))


@dataclass(frozen=True)
class Support:
    """What an object rests on: the faces under it at its bottom's height (by name: objects,
    obstacles, ``region:<name>`` for a region's surface, ``<region>:wall_*`` for its walls,
    `TABLE_FACE`), and which of them is under its centre."""

    faces: tuple[str, ...]
    under_centre: tuple[str, ...]


def support(scene: Scene, o: Movable, tol: Tolerances) -> Support:
    """The faces ``o`` rests on (within ``tol.z`` of its bottom and touching its footprint; an
    object's only under ``o``'s centre when ``tol.centre`` says so)."""
    me = of_movable(o)
    faces, centre = [], []
    if abs(o.bottom) <= tol.z and scene.table.holds(o.pose.xyz):
        faces.append(TABLE_FACE)
        centre.append(TABLE_FACE)
    others = [of_movable(x) for x in scene.objects if x.name != o.name]
    walls = [of_box(w) for r in scene.regions for w in r.walls()]
    fixed = [*(of_box(b) for b in scene.obstacles), *walls]
    for k, s in enumerate([*others, *fixed]):
        if abs(o.bottom - s.top) > tol.z or (tol.overlap >= 0 and apart(me, s)):
            continue  # not at its bottom's height, or no footprint contact to test
        if footprint_gap(me, s) < -tol.overlap:
            if k < len(others) and not _carries(s, o, tol):
                continue
            faces.append(s.name)
            if s.covers(o.pose.xyz):
                centre.append(s.name)
    for r in scene.regions:
        if abs(o.bottom - r.surface) <= tol.z and _over_region(r, o.pose.xyz):
            faces.append(f"region:{r.name}")
            centre.append(f"region:{r.name}")
    return Support(tuple(faces), tuple(centre))


def _carries(s: Solid, o: Movable, tol: Tolerances) -> bool:
    """True when object ``s``, touching ``o``'s footprint, carries it by ``tol.centre``: its
    footprint (grown by that) lies under ``o``'s centre, or ``tol.centre`` is None."""
    return tol.centre is None or s.covers(o.pose.xyz, tol.centre)


def _over_region(r: Region, xy) -> bool:
    return r.lo[0] <= xy[0] <= r.hi[0] and r.lo[1] <= xy[1] <= r.hi[1]


def inside(r: Region, o: Movable, pad: float = 0.0) -> bool:
    """True when ``o``'s whole footprint lies inside the region's rectangle within its walls
    (shrunk by ``pad``, m, less than nothing when negative)."""
    (x0, y0), (x1, y1) = r.inner()
    return all(
        x0 - pad <= x <= x1 + pad and y0 - pad <= y <= y1 + pad for x, y in of_movable(o).corners()
    )
