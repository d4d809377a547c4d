"""A scene and its goal as a Blocksworld problem on capacity-one places, and back.

The motion-aware planner (`tamp.geo.ours.planner`) plans with the project's differentiable planner,
whose Blocksworld domain moves entities onto entities or onto K capacity-one places
(`task.domains.blocksworld.with_slots`, here with ``hop``: a block may go from one place
straight to another, e.g. from the table into a tray). `bridge` builds that problem:

- entities: the scene's movable objects, in scene order;
- places (`Site`), the K fixed targets:
  - region cells: for each region the goal puts objects in, the cells `tamp.geo.ours.pack.pack`
    places all of them at jointly (the region's inner rectangle, kept `PACK_MARGIN` inside
    it where that fits, the objects already inside as fixed occupants, finger room for a top
    grasp): goal object i gets cell i,
    ``<region>.c<i>``;
  - table spots: `tamp.geo.places.candidate_places` of the largest object on the table (the
    scene's slot grid first), ``table.s<i>`` / ``table.g<i>``; none in a scene without
    parking (`Scene.parking`), where each empty region without cells offers its centre,
    ``<region>.centre``;
  - the place each object standing on the table or in a region stands on now: a table spot
    when it stands on one (within `ON_SPOT`), else its own, ``spot_<object>`` (as
    `tamp.slots` does with ``spot_<base>``);
- init: each object's support read from the geometry (`tamp.world.relations.read_facts`), an
  object on the table or in a region on its place;
- goal: ``(in o r)`` -> o on its cell (an object already in r stays on its own place), ``(on a
  b)`` as it is, ``(ontable a)`` -> a on any place, with a kept out of every place that is not
  on the table (`Bridged.banned`), ``(clear x)`` -> nothing is ever put on x (banned) and an
  object resting on x at the start with no goal of its own goes to any place (the domain's
  goal names supports only, so "nothing on x" is folded into the moves allowed).

And back: `Bridged.predict` gives the world after the plan reached a crisp state (objects keep
their observed poses unless moved; on a place: at its position; on an object: centred on its
top, turned as it is), and `Bridged.geo_move` a planned move as a `GeoMove` in a world (the
place's position, or centred on the top of the object it goes onto; grasp None: chosen when the
move is bound, `tamp.geo.ours.planner`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from tamp.geo.ours.pack import (
    Occupants,
    PackConfig,
    PackError,
    PackResult,
    pack_sampled,
    pack_tries,
)
from tamp.geo.places import PACK_MARGIN, TABLE_CLEARANCE, candidate_places, placed_solid
from tamp.geo.types import GeoMove, Place
from tamp.scene import Pose
from tamp.world.geometry import footprint_gap, of_movable
from tamp.world.goal import Goal
from tamp.world.relations import read_facts
from tamp.world.schema import Movable, Region, Scene, SceneFileError
from task.domains.blocksworld import with_slots
from task.problem import TABLE, Move, Problem

ON_SPOT = 0.01  # m, an object this near a table spot stands on it
# m, the hand's reach from an object's centre along the closing axis of a top grasp and across
# it, with the collision model's margin, as `tamp.geo.check.check_move` finds it for a 5 cm
# cube next to a tray wall (it passes at 6.5 cm along and 3 cm across, fails at 6 and 2.6 cm)
FINGERS = 0.07
SIDE = 0.033
PACK = PackConfig(fingers=FINGERS, side=SIDE)
PACK_TRIES = 4  # packings tried (seeds) with the margin ...
# ... and then flush with the region's edges, before it counts as too small: a tight tray packed
# (free, with a placing order) from about a third of the seeds (packed variant 3: 3 of 8) when
# only each seed's least-overlap row was tried, so 4 seeds left one episode in seven with no
# arrangement; trying every free row packs it from 6 of 8 (`tamp.geo.ours.pack`)
FLUSH_TRIES = 12
# tries packed in one tensor program (`tamp.geo.ours.pack.pack_tries`: the same packings; a
# step's cost is mostly fixed, so four tries of 32 rows cost about what one does)
PACK_BATCH = 4


@dataclass(frozen=True)
class Site:
    """A place of the bridged problem: ``name``, the ``target`` an object there rests on (a
    region's name or `task.problem.TABLE`), the centre ``xy`` (m), the height of the face it
    rests on (``surface``, m) and the yaw (rad) of an object put there."""

    name: str
    target: str
    xy: tuple[float, float]
    surface: float = 0.0
    yaw: float = 0.0

    def place(self, o: Movable) -> Place:
        """Object ``o`` at this site: its centre ``o.half[2]`` above the surface."""
        return Place(self.name, self.target, (*self.xy, self.surface + o.half[2]), self.yaw)


@dataclass(frozen=True)
class Bridged:
    """A scene and goal as a Blocksworld problem on places (module docstring). ``sites`` in
    ``problem.fixed`` order; ``cells``: (object, cell) the packer assigned; ``banned``:
    (object, target) moves the goal rules out; ``packs``: (region, `PackResult`)."""

    scene: Scene
    goal: Goal
    problem: Problem
    sites: tuple[Site, ...]
    cells: tuple[tuple[str, str], ...] = ()
    banned: frozenset[tuple[str, str]] = frozenset()
    packs: tuple[tuple[str, PackResult], ...] = field(default=(), compare=False)

    def site(self, name: str) -> Site:
        return self.sites[self.problem.fixed.index(name)]

    def predict(self, state) -> Scene:
        """The world after a plan reached the crisp ``state`` (supports in entity order) from
        the scene: see the module docstring."""
        problem, scene = self.problem, self.scene
        support = dict(zip(problem.entities, state, strict=True))
        start = dict(zip(problem.entities, problem.init, strict=True))
        poses: dict[str, Pose] = {}
        kept: set[str] = set()  # objects at their observed pose

        def pose(x: str) -> Pose:
            if x in poses:
                return poses[x]
            o, s = scene.object(x), support[x]
            if s in problem.fixed:
                poses[x] = o.pose if s == start[x] else self.site(s).place(o).pose
            else:
                below = pose(s)
                if s == start[x] and s in kept:
                    poses[x] = o.pose
                else:
                    top = below.xyz[2] + scene.object(s).half[2]
                    poses[x] = Pose((below.xyz[0], below.xyz[1], top + o.half[2]), below.yaw)
            if poses[x] is o.pose:
                kept.add(x)
            return poses[x]

        for x in problem.entities:
            pose(x)
        objects = tuple(replace(o, pose=poses[o.name]) for o in scene.objects)
        return replace(scene, objects=objects)

    def geo_move(self, world: Scene, move: Move) -> GeoMove:
        """The planned ``move`` in ``world`` (the scene before it) as a `GeoMove`."""
        o = world.object(move.entity)
        if move.target in self.problem.fixed:
            return GeoMove(o.name, self.site(move.target).place(o))
        y = world.object(move.target)
        xyz = (y.pose.xyz[0], y.pose.xyz[1], y.top + o.half[2])
        return GeoMove(o.name, Place(f"on.{y.name}", y.name, xyz, y.pose.yaw))


def own_footprint(o: Movable) -> tuple[float, float]:
    """Half extents (x, y) of ``o``'s footprint in its own frame (m): the packer turns it."""
    return o.half[0], o.half[1]


def footprint(o: Movable) -> tuple[float, float]:
    """Half extents (x, y) of ``o``'s axis-aligned bounding footprint (m)."""
    c, s = abs(math.cos(o.pose.yaw)), abs(math.sin(o.pose.yaw))
    hx, hy = o.half[0], o.half[1]
    if o.kind == "cylinder":
        return hx, hy
    return c * hx + s * hy, s * hx + c * hy


SAMPLERS = ("gradient", "sampled")  # how region cells are placed: `pack`, `pack_sampled`


def _too_small(scene: Scene, r: Region, name: str) -> SceneFileError:
    """The one line for object ``name``, whose footprint region ``r``'s inner rectangle
    cannot hold however it is turned."""
    o = scene.object(name)
    (x0, y0), (x1, y1) = r.inner()
    return SceneFileError(
        f"(in {name} {r.name}): {name}'s footprint ({2 * o.half[0]:g} x {2 * o.half[1]:g} m) "
        f"does not fit region {r.name}'s inner rectangle ({x1 - x0:g} x {y1 - y0:g} m)"
    )


def bridge(
    scene: Scene,
    goal: Goal,
    table_places: int | None = None,
    config: PackConfig = PACK,
    seed: int = 0,
    sampler: str = "gradient",
) -> Bridged:
    """The Blocksworld problem of ``scene`` and ``goal`` (module docstring). ``table_places``:
    how many table spots (default: the number of objects + 2). ``sampler``: how the region
    cells are placed, ``gradient`` (`pack`) or ``sampled`` (`pack_sampled`, the rejection
    sampling a greedy TAMP system uses, at the same budget per try: as many position samples
    as `pack` spends row-steps, and the same tries). SceneFileError, one line, for an object
    the geometry cannot explain or a goal the domain cannot express."""
    if sampler not in SAMPLERS:
        raise SceneFileError(
            f"placement sampler {sampler!r}: expected one of {', '.join(SAMPLERS)}"
        )
    facts = read_facts(scene)
    if facts.unexplained:
        raise SceneFileError(f"scene {scene.name}: {'; '.join(facts.issues)}")
    if not scene.objects:
        raise SceneFileError(f"scene {scene.name}: objects: no movable object to plan for")
    support = dict(facts.supports)
    names = [o.name for o in scene.objects]
    wanted, clear = _wanted(goal)
    sites: list[Site] = []
    cells: list[tuple[str, str]] = []
    packs: list[tuple[str, PackResult]] = []
    for r in scene.regions:
        inside = [x for x in names if support.get(x) == r.name]
        movers = [x for x, t in wanted.items() if t == r.name and x not in inside]
        if not movers:
            continue
        result = _pack_region(scene, r, movers, inside, config, seed, sampler)
        packs.append((r.name, result))
        sites += _cell_sites(r, result, len(movers))
        cells += [(x, site.name) for x, site in zip(movers, sites[-len(movers) :], strict=True)]
    if not scene.parking:  # no table spots: each region that has no cell offers its centre
        taken = {s.target for s in sites}
        for r in scene.regions:
            if r.name not in taken and not any(support.get(x) == r.name for x in names):
                (x0, y0), (x1, y1) = r.inner()
                centre = ((x0 + x1) / 2, (y0 + y1) / 2)
                sites.append(Site(f"{r.name}.centre", r.name, centre, r.surface))
    table = _table_sites(scene, table_places, seed)
    bases = _bases(scene, support, table, sites)  # appends the spots of those not on a table one
    sites += table
    goal_atoms, banned = _goal_atoms(scene, support, (wanted, clear), dict(cells), bases, sites)
    plain = Problem(
        name=scene.name,
        domain="blocksworld",
        entities=tuple(names),
        init=tuple(TABLE if x in bases else support[x] for x in names),
        goal=tuple(goal_atoms),
    )
    problem = with_slots(plain, tuple(s.name for s in sites), bases, hop=True)
    return Bridged(
        scene, goal, problem, tuple(sites), tuple(cells), frozenset(banned), tuple(packs)
    )


def _wanted(goal: Goal) -> tuple[dict[str, str], list[str]]:
    """The support each object of ``goal`` must end on (object -> region / object / TABLE)
    and the objects that must end clear; SceneFileError for a goal the domain cannot express
    (two supports for one object, a clear object something must stand on)."""
    wanted: dict[str, str] = {}
    clear: list[str] = []
    for atom in goal.atoms:
        if atom[0] == "clear":
            clear.append(atom[1])
            continue
        target = atom[2] if atom[0] in ("in", "on") else TABLE
        if wanted.get(atom[1], target) != target:
            raise SceneFileError(
                f"goal: {atom[1]} has two supports ({wanted[atom[1]]} and {target}); "
                "an object rests on one"
            )
        wanted[atom[1]] = target
    for x in clear:
        on_x = [o for o, t in wanted.items() if t == x]
        if on_x:
            raise SceneFileError(f"goal: (clear {x}) and (on {on_x[0]} {x}) contradict")
    return wanted, clear


def _pack_region(scene, r: Region, movers, inside, config: PackConfig, seed: int, sampler: str):
    """The packing of the ``movers``' footprints in region ``r`` around the objects
    ``inside`` it: a few seeds (each R restart rows already), first with the footprints kept
    `PACK_MARGIN` inside the rectangle, then flush with it where nothing else fits; the
    first that packs wins (else the last tried), the gradient's tries `PACK_BATCH` at a time
    in one program."""
    fixed = [scene.object(x) for x in inside]
    tries = [(PACK_MARGIN, attempt) for attempt in range(PACK_TRIES)]
    tries += [(0.0, attempt) for attempt in range(FLUSH_TRIES)]
    args = (
        r.inner(),
        [own_footprint(scene.object(x)) for x in movers],
        Occupants([o.pose.xyz[:2] for o in fixed], [footprint(o) for o in fixed]),
    )
    step = 1 if sampler == "sampled" else PACK_BATCH
    for k in range(0, len(tries), step):
        batch = tries[k : k + step]
        try:
            if sampler == "sampled":
                margin, attempt = batch[0]
                budget = config.restarts * config.steps  # `pack`'s row-steps
                at = replace(config, margin=margin)
                results = [
                    pack_sampled(*args, budget, seed + attempt, at, walled=r.wall_height > 0)
                ]
            else:
                at = [(replace(config, margin=margin), seed + a) for margin, a in batch]
                results = pack_tries(*args, at, walled=r.wall_height > 0)
        except PackError as exc:
            if exc.index is None:
                raise
            if batch[0][0] > 0:  # too wide for the margin: flush with the edges may fit
                continue
            raise _too_small(scene, r, movers[exc.index]) from None
        result = next((x for x in results if x.ok), results[-1])
        if result.ok:
            break
    return result


def _cell_sites(r: Region, result: PackResult, n: int) -> list[Site]:
    """The ``n`` cells of region ``r`` where its packing ``result`` put them; a failed
    sampled packing places only some: the rest at the centre (the planner refuses a packing
    that is not ok before it plans, `tamp.geo.ours.planner`)."""
    (x0, y0), (x1, y1) = r.inner()
    out = []
    for i in range(n):
        xy, yaw = ((x0 + x1) / 2, (y0 + y1) / 2), 0.0
        if i < len(result.positions):
            xy = (float(result.positions[i, 0]), float(result.positions[i, 1]))
            yaw = float(result.yaws[i])
        out.append(Site(f"{r.name}.c{i}", r.name, xy, r.surface, yaw))
    return out


def _table_sites(scene: Scene, table_places: int | None, seed: int) -> list[Site]:
    """The table spots (`bridge`'s ``table_places``; none where the scene has no parking),
    placed for the widest object and kept off its own footprint."""
    probe = max(scene.objects, key=lambda o: max(footprint(o)))
    n_table = len(scene.objects) + 2 if table_places is None else table_places
    n_table = n_table if scene.parking else 0
    spots = candidate_places(scene, probe.name, TABLE, 3 * n_table, seed)
    me = of_movable(probe)  # the probe ignores itself: keep spots off its footprint too
    spots = [
        p
        for p in spots
        if math.dist(p.xyz[:2], probe.pose.xyz[:2]) <= ON_SPOT
        or footprint_gap(me, placed_solid(probe, p)) >= TABLE_CLEARANCE
    ][:n_table]
    return [Site(p.name, TABLE, p.xyz[:2], 0.0, p.yaw) for p in spots]


def _bases(scene: Scene, support: dict, table: list[Site], sites: list[Site]) -> dict[str, str]:
    """Object on the table or in a region -> the place it stands on now: a ``table`` spot
    under it, else a spot of its own (appended to ``sites``)."""
    regions = {r.name for r in scene.regions}
    bases: dict[str, str] = {}
    for o in scene.objects:
        x, s = o.name, support.get(o.name)
        if s != TABLE and s not in regions:
            continue
        near = [
            t for t in table if math.dist(t.xy, o.pose.xyz[:2]) <= ON_SPOT and t.name not in bases
        ]
        if s == TABLE and near:
            bases[x] = near[0].name
            continue
        r = None if s == TABLE else scene.region(s)
        surface = 0.0 if r is None else r.surface
        sites.append(Site(f"spot_{x}", s, tuple(o.pose.xyz[:2]), surface, o.pose.yaw))
        bases[x] = sites[-1].name
    return bases


def _goal_atoms(scene: Scene, support: dict, wanted_clear, cell: dict, bases: dict, sites):
    """The problem's goal supports and the banned (object, place) pairs: an object wanted
    in a region goes to its cell (or stays on its base), one wanted on the table to no
    region's place; nothing onto an object that must end clear, and what stands on it now
    goes to the table."""
    wanted, clear = wanted_clear
    regions = {r.name for r in scene.regions}
    names = [o.name for o in scene.objects]
    goal_atoms, banned = [], set()
    for x, t in wanted.items():
        if t in regions:
            goal_atoms.append((x, cell.get(x, bases.get(x))))
        else:
            goal_atoms.append((x, t))
        if t == TABLE:
            banned |= {(x, s.name) for s in sites if s.target != TABLE}
    for x in clear:
        banned |= {(o, x) for o in names if o != x}
        for o in names:
            if support.get(o) == x and o not in wanted:
                goal_atoms.append((o, TABLE))
    return goal_atoms, banned


def positions(bridged: Bridged) -> np.ndarray:
    """(K, 2) the sites' centres (m), in ``problem.fixed`` order."""
    return np.array([s.xy for s in bridged.sites], dtype=np.float64).reshape(-1, 2)
