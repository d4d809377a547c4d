"""Discretised placements: where an object may go on another object, in a region, on the table.

`candidate_places(scene, obj, target, n, seed)` lists up to ``n`` `Place` choices for object
``obj`` onto ``target`` in the scene as it is now (the other objects where they stand), each a
centre and a yaw at which the object rests on the target, inside it, and free of everything
else. The same call in another world state gives the same name to the same position: names are
the failure memory's keys (`tamp.geo.search`), so a place is a stable choice, not a sample.

- On an object ``y`` (``"on.y"``): centred on its top, turned as ``y`` is (a cuboid whose
  footprint is not square also a quarter turn, ``"on.y.r"``), only when the object is
  *supported*: its footprint at that yaw lies within ``y``'s top grown by `SUPPORT_PAD` (a cube
  on a cube of its size or larger, a small disc on a large one; never a large object on a
  small one: it would tip or overhang). ``y`` must be clear of anything but ``obj``.
- In a region ``r`` (``"r.p<x>_<y>"``, ``"r.g<i>"``, ``"r.s<j>"``): first the packing
  places, flush against the inner rectangle's edges (`PACK_MARGIN` in) and against the objects
  already in the region (`PACK_GAP` beside them), every combination of those x and y in
  order of x then y (columns filled from the low corner), named by their position in mm;
  along an axis where the object leaves less play than the scene's narrowest object is wide
  (a Hanoi peg under its largest disc), centred instead; then
  the grid over the inner rectangle at pitch object width + `REGION_GAP`, centred in the
  rectangle, nearest the region's centre first; then ``samples`` seeded uniform positions
  (nearest the centre first). Every one has the object's footprint inside the inner rectangle
  and `REGION_CLEARANCE` from the other objects. Yaws: the region's axes (a non-square cuboid
  also turned a quarter, suffix ``.r``). A region with a smaller region marked inside it (an
  alcove in a larger area) offers only its free part: a place wholly inside the inner region
  would have the inner one as its support (`tamp.world.relations.innermost`), so it is
  offered as a place in the inner region, not in this one.
- On the table (`task.problem.TABLE`; ``"table.s<i>"``, ``"table.g<i>"``): the scene's slot
  grid first (if it has one), then a grid of pitch `TABLE_PITCH` over the table within
  `TABLE_REACH` of the robot base's axis (its phase drawn from ``seed``), nearest the object
  first; away from the regions and obstacles, and `TABLE_CLEARANCE` from the other objects,
  so a spot on the table never hems in a neighbour's grasp.

Freedom here is geometry only (footprints and heights); whether the arm can make the move, the
fingers included, is `tamp.geo.check.check_move`'s to say.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import replace

import numpy as np

from tamp.geo.types import Place
from tamp.world.geometry import (
    TIGHT,
    Solid,
    fixed_solids,
    footprint_gap,
    inside,
    of_movable,
    penetration,
)
from tamp.world.relations import innermost
from tamp.world.schema import Movable, Region, Scene, SceneFileError
from task.errors import one_of
from task.problem import TABLE

SUPPORT_PAD = 0.002  # m, an object's footprint may reach this far past the top it stands on
REGION_GAP = 0.02  # m, between neighbouring grid places in a region (a finger's room)
REGION_CLEARANCE = 0.003  # m, a region place keeps this far from the other objects
PACK_GAP = 0.004  # m, a packing place stands this far from the object it packs against
PACK_MARGIN = 0.002  # m, ... and this far inside the region's inner rectangle
TABLE_PITCH = 0.08  # m, the table grid's spacing
TABLE_REACH = (0.30, 0.70)  # m, table spots lie this far from the robot base's z axis
TABLE_CLEARANCE = 0.04  # m, a table spot keeps this far from objects, regions and obstacles
OVERLAP = 0.001  # m, a place may touch what is around it this deep (contact, not overlap)
TURN = math.pi / 2


def candidate_places(
    scene: Scene,
    obj: str,
    target: str,
    n: int = 8,
    seed: int = 0,
    samples: int | None = None,
) -> tuple[Place, ...]:
    """Up to ``n`` places of object ``obj`` onto ``target`` (an object's name, a region's name
    or `task.problem.TABLE`) in ``scene`` as it stands, in the order a planner should try them
    (see the module docstring). ``samples``: seeded region positions added after the grid
    (default ``n``). An unknown name is a `SceneFileError` listing the valid ones; a target
    nothing fits on gives ``()``, as does the table in a scene without parking
    (`Scene.parking`)."""
    o = scene.object(obj)
    objects = {x.name for x in scene.objects}
    regions = {r.name for r in scene.regions}
    if target == TABLE:
        pool = _on_table(scene, o, seed) if scene.parking else []
    elif target in regions:
        pool = _in_region(scene, o, scene.region(target), seed, n if samples is None else samples)
    elif target in objects:
        pool = _on_object(scene, o, scene.object(target))
    else:
        valid = [*sorted(objects - {obj}), *sorted(regions), TABLE]
        raise SceneFileError(f"unknown place target {one_of(target, valid)}")
    out = []
    clearance = _clearance(target, objects, regions)
    for place in pool:
        if len(out) >= n:
            break
        if target == TABLE and not _table_spot(scene, o, place):
            continue
        if free(scene, obj, place, clearance):
            out.append(place)
    return tuple(out)


def fixed_targets(scene: Scene) -> tuple[str, ...]:
    """What an object may be set on besides the other objects: the regions and, where the
    scene allows parking (`Scene.parking`), the table."""
    return (*(r.name for r in scene.regions), *((TABLE,) if scene.parking else ()))


def free(scene: Scene, obj: str, place: Place, clearance: float = 0.0) -> bool:
    """True when object ``obj`` at ``place`` overlaps nothing fixed (obstacles, region walls
    and floors: at most `OVERLAP` deep) and keeps ``clearance`` (m) from every other object
    whose height range it shares (objects under it: at most `OVERLAP` deep)."""
    me = placed_solid(scene.object(obj), place)
    for s in fixed_solids(scene):
        if not apart(me, s, 0.0) and penetration(me, s) > OVERLAP:
            return False
    for x in scene.objects:
        if x.name == obj:
            continue
        s = of_movable(x)
        if apart(me, s, clearance):
            continue
        shared = min(me.top, s.top) - max(me.bottom, s.bottom) > OVERLAP
        if shared and footprint_gap(me, s) < clearance - 1e-9:
            return False
        if penetration(me, s) > OVERLAP:
            return False
    return True


def apart(a: Solid, b: Solid, gap: float) -> bool:
    """True when the footprints of ``a`` and ``b`` are surely more than ``gap`` (m) apart
    (their bounding circles are): a cheap test before `footprint_gap`."""
    reach = math.hypot(a.half[0], a.half[1]) + math.hypot(b.half[0], b.half[1])
    return math.dist(a.centre[:2], b.centre[:2]) - reach > gap


def placed_solid(o: Movable, place: Place) -> Solid:
    """The solid ``o`` would be at ``place``."""
    return Solid(o.name, o.kind == "cylinder", place.xyz, o.half, place.yaw)


def supported_on(o: Movable, below: Movable, yaw: float) -> bool:
    """True when ``o`` turned ``yaw``, centred on ``below``'s top, has its whole footprint
    within that top grown by `SUPPORT_PAD` (a disc: its radius within the top's)."""
    top = of_movable(below)
    if o.kind == "cylinder":
        room = below.half[0] if below.kind == "cylinder" else min(below.half[:2])
        return o.half[0] <= room + SUPPORT_PAD
    me = Solid(o.name, False, below.pose.xyz, o.half, yaw)
    return all(top.covers(c, SUPPORT_PAD) for c in me.corners())


def _clearance(target: str, objects: set[str], regions: set[str]) -> float:
    if target == TABLE:
        return TABLE_CLEARANCE
    if target in regions:
        return REGION_CLEARANCE
    return 0.0  # on an object: only overlaps matter


def _yaws(o: Movable, base: float) -> tuple[tuple[str, float], ...]:
    """(suffix, yaw) choices: ``base``, and a quarter turn when the footprint is not square."""
    if o.kind == "cuboid" and abs(o.half[0] - o.half[1]) > 1e-6:
        return (("", base), (".r", base + TURN))
    return (("", base),)


def _on_object(scene: Scene, o: Movable, below: Movable) -> list[Place]:
    if below.name == o.name:
        return []
    z = below.top + o.half[2]
    return [
        Place(f"on.{below.name}{suffix}", below.name, (*below.pose.xyz[:2], z), yaw)
        for suffix, yaw in _yaws(o, below.pose.yaw)
        if supported_on(o, below, yaw)
    ]


def _stream(seed: int, *names: str) -> np.random.Generator:
    """A generator seeded by ``seed`` and the names (stable across processes and states)."""
    key = zlib.crc32("/".join(names).encode())
    return np.random.default_rng([seed, key])


def _in_region(scene: Scene, o: Movable, r: Region, seed: int, samples: int) -> list[Place]:
    (x0, y0), (x1, y1) = r.inner()
    z = r.surface + o.half[2]
    centre = ((x0 + x1) / 2, (y0 + y1) / 2)
    grid, drawn, packed = [], [], []
    inside_now = [
        of_movable(x)
        for x in scene.objects
        if x.name != o.name
        and r.lo[0] <= x.pose.xyz[0] <= r.hi[0]
        and r.lo[1] <= x.pose.xyz[1] <= r.hi[1]
    ]
    narrowest = min(2 * min(x.half[:2]) for x in scene.objects)  # m, the least footprint side
    for suffix, yaw in _yaws(o, 0.0):
        hx, hy = _extent(o, yaw)
        lo, hi = (
            (x0 + hx + PACK_MARGIN, y0 + hy + PACK_MARGIN),
            (x1 - hx - PACK_MARGIN, y1 - hy - PACK_MARGIN),
        )
        if lo[0] > hi[0] + 1e-9 or lo[1] > hi[1] + 1e-9:
            continue  # the object does not fit inside the region at this yaw
        xs, ys = {lo[0], hi[0]}, {lo[1], hi[1]}
        for s in inside_now:
            ex, ey = _extent_of(s)
            xs |= {s.centre[0] + ex + PACK_GAP + hx, s.centre[0] - ex - PACK_GAP - hx}
            ys |= {s.centre[1] + ey + PACK_GAP + hy, s.centre[1] - ey - PACK_GAP - hy}
        # along an axis with less play than any object is wide, packing against an edge
        # leaves a gap nothing can use: the place is centred there, as far from both edges as
        # it can be (a placed object settles millimetres from where it was released)
        if hi[0] - lo[0] < narrowest + PACK_GAP:
            xs = {(lo[0] + hi[0]) / 2}
        if hi[1] - lo[1] < narrowest + PACK_GAP:
            ys = {(lo[1] + hi[1]) / 2}
        for x, y in sorted((x, y) for x in xs for y in ys):
            if lo[0] - 1e-9 <= x <= hi[0] + 1e-9 and lo[1] - 1e-9 <= y <= hi[1] + 1e-9:
                name = f"{r.name}.p{round(x * 1000)}_{round(y * 1000)}{suffix}"
                packed.append(Place(name, r.name, (x, y, z), yaw))
        xs = _centred(lo[0], hi[0], 2 * hx + REGION_GAP)
        ys = _centred(lo[1], hi[1], 2 * hy + REGION_GAP)
        for i, (x, y) in enumerate((x, y) for x in xs for y in ys):
            grid.append(Place(f"{r.name}.g{i}{suffix}", r.name, (x, y, z), yaw))
        rng = _stream(seed, o.name, r.name, suffix)
        for j in range(samples):
            x, y = rng.uniform(lo[0], hi[0]), rng.uniform(lo[1], hi[1])
            drawn.append(Place(f"{r.name}.s{j}{suffix}", r.name, (float(x), float(y), z), yaw))

    def near(place: Place) -> float:
        return math.dist(place.xyz[:2], centre)

    pool = packed + sorted(grid, key=near) + sorted(drawn, key=near)
    nested = [
        q
        for q in scene.regions
        if q.name != r.name
        and abs(q.surface - r.surface) <= TIGHT.z
        and innermost(scene, [r.name, q.name]) == q.name
    ]
    if not nested:
        return pool
    return [p for p in pool if not any(inside(q, replace(o, pose=p.pose)) for q in nested)]


def _extent_of(s: Solid) -> tuple[float, float]:
    """Half extents along x and y of solid ``s``'s footprint (its bounding box)."""
    if s.cylinder:
        return s.half[0], s.half[1]
    c, n = abs(math.cos(s.yaw)), abs(math.sin(s.yaw))
    return c * s.half[0] + n * s.half[1], n * s.half[0] + c * s.half[1]


def _extent(o: Movable, yaw: float) -> tuple[float, float]:
    """Half extents along x and y of ``o``'s footprint turned ``yaw`` (its bounding box)."""
    if o.kind == "cylinder":
        return o.half[0], o.half[1]
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    return c * o.half[0] + s * o.half[1], s * o.half[0] + c * o.half[1]


def _centred(lo: float, hi: float, pitch: float) -> list[float]:
    """Positions ``pitch`` apart from ``lo`` to ``hi``, as many as fit, centred in the span."""
    count = math.floor((hi - lo) / pitch + 1e-9) + 1
    start = (lo + hi) / 2 - (count - 1) * pitch / 2
    return [start + k * pitch for k in range(count)]


def _on_table(scene: Scene, o: Movable, seed: int) -> list[Place]:
    z = o.half[2]
    slots = []
    if scene.slots is not None:
        points = [(x, y) for x in scene.slots.xs for y in scene.slots.ys]
        slots = [Place(f"table.s{i}", TABLE, (x, y, z), 0.0) for i, (x, y) in enumerate(points)]
    rng = _stream(seed, "table")
    phase = rng.uniform(0.0, TABLE_PITCH, size=2)
    (tx0, ty0), (tx1, ty1) = scene.table.lo, scene.table.hi
    xs = np.arange(tx0 + phase[0], tx1, TABLE_PITCH)
    ys = np.arange(ty0 + phase[1], ty1, TABLE_PITCH)
    grid = [
        Place(f"table.g{i}", TABLE, (float(x), float(y), z), 0.0)
        for i, (x, y) in enumerate((x, y) for x in xs for y in ys)
    ]
    here = o.pose.xyz[:2]
    grid.sort(key=lambda place: math.dist(place.xyz[:2], here))
    return [*slots, *grid]  # `_table_spot` filters them as they are taken


def _table_spot(scene: Scene, o: Movable, place: Place) -> bool:
    """On the table, within `TABLE_REACH`, and `TABLE_CLEARANCE` from regions and obstacles."""
    me = placed_solid(o, place)
    if not all(scene.table.holds(c) for c in me.corners()):
        return False
    if not TABLE_REACH[0] <= math.hypot(*place.xyz[:2]) <= TABLE_REACH[1]:
        return False
    for r in scene.regions:
        rect = Solid(
            r.name,
            False,
            ((r.lo[0] + r.hi[0]) / 2, (r.lo[1] + r.hi[1]) / 2, 0.0),
            ((r.hi[0] - r.lo[0]) / 2, (r.hi[1] - r.lo[1]) / 2, 1.0),
        )
        if not apart(me, rect, TABLE_CLEARANCE) and footprint_gap(me, rect) < TABLE_CLEARANCE:
            return False
    for s in fixed_solids(scene):
        near = s.bottom < me.top and not apart(me, s, TABLE_CLEARANCE)
        if near and footprint_gap(me, s) < TABLE_CLEARANCE:
            return False
    return True
