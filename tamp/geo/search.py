"""Best-first search over world states with the arm's feasibility checked lazily: the complete
planner of the geometric TAMP room over its discretised grasp and placement choices.

A node is a world state (a `Scene` with the objects' poses; its facts read from the geometry),
its key the objects' poses rounded to a millimetre. A successor moves one clear object onto a
clear object, into a region or onto the table, at one of `candidate_places` (``places`` per
target). Successors are queued with f = g + weight * h, g the moves so far and h
`_Guide.estimate`: the objects that must still move (`heuristic`: the unmet goal atoms'
subjects and whatever is stacked on what they move or uncover) plus the neighbours hemming one
of them in (`_Guide.blockers`, the reference open hand of `tamp.world.canonical`), twice for a
neighbour that stands where the goal wants it (it must go out and come back). A move of an
object no goal atom plausibly involves, or of the object the last move moved, costs 1 more.
These are orderings, not prunings; h is a guide, not a bound, so a plan is short, not
guaranteed shortest. Ties go to the deeper node, then to the better-ranked place.

Feasibility is decided when a successor is popped, not when it is generated (PDDLStream's
incremental idea), first by the cheap test (`check_move(..., full=False)`: one batched IK call
of the grasp and place poses of every open grasp, the arm tested for collisions there), and
when a goal state is reached, by the full check of each of the plan's moves in order
(`check_move`: every waypoint's IK, every phase guarded). A move the full check refuses goes
into the failure memory and the search runs again (the cheap verdicts cached), so the full
check has the final word. The memory records what failed where it failed:

- a grasp that failed on the pick side (reaching or closing on the object) is ruled out for
  that object at that pose, for every place, while what the hand hit stands where it stood (a
  fixed box, the table or no IK solution: always; an object: until it moves);
- a grasp whose place pose has no IK solution is ruled out for that place in every state (the
  place pose's IK does not depend on where the other objects are);
- any other failure rules out (state, object, grasp, place) only: the same object may still go
  elsewhere, or with another grasp, or to the same place from another state.

Before searching, each goal atom that names a region or an object is tested for a place at all:
none fits (the region is too small for the object, the object too large for the top it must
stand on) or none is reachable by any grasp (one batched IK call over the region's places):
UNSOLVABLE at once, saying which. Otherwise the search ends SOLVED, UNSOLVABLE when the queue
empties (no plan within these choices) or BUDGET when ``max_nodes`` or ``max_time_s`` run out.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from motion.grasps import world_tcp
from tamp.geo.check import MoveCheck, Tools, candidate_grasps, check_move, grasp_order
from tamp.geo.places import apart, candidate_places, free, supported_on
from tamp.geo.types import TABLE, GeoMove, GeoPlan, GeoStatus, Place, moved
from tamp.outcome import Failure
from tamp.world.geometry import fixed_solids, footprint_gap, of_movable
from tamp.world.goal import Goal
from tamp.world.relations import Atom, read_facts
from tamp.world.schema import Scene

NEAR = 0.10  # m, objects this near a picked object make its pick-side neighbourhood


@dataclass(frozen=True)
class SearchConfig:
    """Budgets and choices of `plan_search` (and of the baseline, `tamp.geo.baseline`).

    ``places``: candidate places per target (`candidate_places`' ``n``); ``choices``: the grasp
    families (`motion.grasps.grasps`); ``max_nodes``: states expanded; ``max_time_s``: wall
    clock; ``seed``: the places' samples; ``weight``: 1 is A*, above 1 weighted A*;
    ``symbolic_nodes``: expansions of one symbolic search (`tamp.geo.baseline`)."""

    max_nodes: int = 500
    max_time_s: float = 120.0
    places: int = 6
    choices: tuple[str, ...] = ("top", "side", "tilt")
    seed: int = 0
    weight: float = 1.0
    symbolic_nodes: int = 200_000  # the baseline's and soft's symbolic searches, per plan


DEFAULT = SearchConfig()


@dataclass
class _Node:
    scene: Scene
    supports: dict  # object -> support (an object, a region or TABLE)
    g: int
    parent: int | None
    move: GeoMove | None


def state_key(scene: Scene) -> tuple:
    """The objects' poses rounded to a millimetre (yaw to 0.01 rad): a world state's key."""
    return tuple(
        (o.name, *(round(v, 3) for v in o.pose.xyz), round(o.pose.yaw % (2 * math.pi), 2))
        for o in scene.objects
    )


def heuristic(supports: dict, goal: Goal) -> int:
    """The objects that must move at least once: each unmet goal atom's subject (``clear x``:
    whatever is on x) and everything stacked above an object an unmet atom moves or uncovers.
    ``supports``: object -> what it rests on."""
    return len(_movers(supports, goal))


def _movers(supports: dict, goal: Goal) -> set[str]:
    above: dict[str, list[str]] = {}
    for x, s in supports.items():
        above.setdefault(s, []).append(x)

    def stack(x: str) -> set[str]:
        out, todo = set(), list(above.get(x, []))
        while todo:
            y = todo.pop()
            if y not in out:
                out.add(y)
                todo += above.get(y, [])
        return out

    movers: set[str] = set()
    for atom in goal.atoms:
        if holds_in(atom, supports):
            continue
        if atom[0] == "clear":
            movers |= stack(atom[1])
            continue
        movers |= {atom[1]} | stack(atom[1])
        if atom[0] == "on":
            movers |= stack(atom[2])
    return movers


def holds_in(atom: Atom, supports: dict) -> bool:
    """Whether a goal ``atom`` (clear, ontable, on or in) holds where every object rests on
    ``supports`` (object -> what it stands on, `TABLE` or a name)."""
    pred, x = atom[0], atom[1]
    if pred == "clear":
        return x not in supports.values()
    if pred == "ontable":
        return supports.get(x) == TABLE
    return supports.get(x) == atom[2]  # on / in


def _neighbourhood(scene: Scene, obj: str) -> tuple:
    """``obj``'s pose and those of the objects within `NEAR` of it, rounded (a memory key)."""
    me = of_movable(scene.object(obj))
    near = [
        x
        for x in scene.objects
        if x.name == obj
        or (not apart(me, of_movable(x), NEAR) and footprint_gap(me, of_movable(x)) < NEAR)
    ]
    return tuple((x.name, *(round(v, 3) for v in x.pose.xyz)) for x in near)


class _Memory:
    """The failure memory (see the module docstring): which grasps are ruled out for a move."""

    def __init__(self, scene: Scene) -> None:
        self.fixed = {s.name for s in fixed_solids(scene)} | {"table"}
        # (obj, its pose, grasp) -> culprits: "fixed" (IK, or a fixed box or the table hit:
        # whatever the other objects do) or (object, its pose) hit
        self.pick: dict[tuple, set] = {}
        self.place: set[tuple] = set()  # (obj, grasp, place name)
        self.move: set[tuple] = set()  # (state key, obj, grasp, place name)
        self.ruled_out = 0  # grasps skipped because the memory ruled them out

    def open(self, scene: Scene, key: tuple, move: GeoMove, grasps) -> tuple:
        here = _pose_key(scene.object(move.obj))
        poses = {o.name: _pose_key(o) for o in scene.objects}
        out = []
        for g in grasps:
            culprits = self.pick.get((move.obj, here, g.name), ())
            if (
                any(c == "fixed" or poses.get(c[0]) == c[1] for c in culprits)
                or (key, move.obj, g.name, move.place.name) in self.move
                or (move.obj, g.name, move.place.name) in self.place
            ):
                self.ruled_out += 1
                continue
            out.append(g)
        return tuple(out)

    def record(self, scene: Scene, key: tuple, move: GeoMove, check: MoveCheck) -> None:
        here = _pose_key(scene.object(move.obj))
        names = {o.name for o in scene.objects}
        for t in check.tried:
            if t.failure is None:
                continue
            if t.side == "pick" and (t.failure is Failure.IK_INFEASIBLE or t.other in self.fixed):
                self.pick.setdefault((move.obj, here, t.grasp), set()).add("fixed")
            elif t.side == "pick" and t.other in names:
                culprit = (t.other, _pose_key(scene.object(t.other)))
                self.pick.setdefault((move.obj, here, t.grasp), set()).add(culprit)
            elif t.failure is Failure.IK_INFEASIBLE and t.where == "place":
                self.place.add((move.obj, t.grasp, move.place.name))
            else:
                self.move.add((key, move.obj, t.grasp, move.place.name))


def _pose_key(o) -> tuple:
    return (*(round(v, 3) for v in o.pose.xyz), round(o.pose.yaw % (2 * math.pi), 2))


def _without_others(scene: Scene, obj: str) -> Scene:
    return replace(scene, objects=tuple(o for o in scene.objects if o.name == obj))


def dead_goal(scene: Scene, goal: Goal, tools: Tools, config: SearchConfig) -> str:
    """Why no plan can exist, from the goal's atoms alone ("" when this test finds none): an
    object that fits on no place of the region it must go in, or on the object it must stand
    on; or whose region places no grasp reaches (one batched IK call of every place pose)."""
    for atom in goal.atoms:
        if atom[0] not in ("in", "on"):
            continue
        x, target = scene.object(atom[1]), atom[2]
        if atom[0] == "on":
            y = scene.object(target)
            if not any(supported_on(x, y, y.pose.yaw + k * math.pi / 2) for k in range(2)):
                return f"object {x.name} does not fit on {y.name}'s top"
            continue
        alone = _without_others(scene, x.name)
        pool = candidate_places(alone, x.name, target, 10**6, config.seed, config.places)
        if not pool:
            return f"no place of object {x.name} fits in region {target}"
        grasps = candidate_grasps(x, config.choices)
        if not grasps:
            return f"no grasp of object {x.name} fits the gripper"
        tcps = np.stack([world_tcp(g, p.xyz, p.yaw) for p in pool for g in grasps])
        found = tools.solver.solve(tcps, tools.q)
        if not found.ok.any():
            return (
                f"no place of object {x.name} in region {target} is reachable "
                f"({len(pool)} places x {len(grasps)} grasps)"
            )
    return ""


def plan_search(
    scene: Scene,
    goal: Goal,
    tools: Tools,
    config: SearchConfig = DEFAULT,
    hints: Mapping[tuple[str, str], Sequence[Place]] | None = None,
) -> GeoPlan:
    """Plan moves from ``scene`` to ``goal`` (see the module docstring). ``hints``: places
    to try first, per (object, target), before `candidate_places` (e.g. a joint packing of a
    region, `tamp.geo.ours`): each offered where it is free (`tamp.geo.places.free`).
    ``stats``: nodes (expanded, all rounds), generated, checks (`check_move` calls: quick and
    full), full_checks, failures (checks that failed), restarts (plans a full check refused),
    ruled_out (grasps the failure memory skipped), time_s, check_time_s."""
    t0 = time.perf_counter()
    stats = {
        "nodes": 0,
        "generated": 0,
        "checks": 0,
        "full_checks": 0,
        "failures": 0,
        "restarts": 0,
        "check_time_s": 0.0,
    }
    memory = _Memory(scene)

    def end(status: GeoStatus, reason: str = "", moves=()) -> GeoPlan:
        stats["ruled_out"] = memory.ruled_out
        stats["time_s"] = time.perf_counter() - t0
        return GeoPlan(status, tuple(moves), reason, stats)

    if goal.holds(read_facts(scene)):
        return end(GeoStatus.SOLVED, "the goal holds already")
    dead = dead_goal(scene, goal, tools, config)
    if dead:
        return end(GeoStatus.UNSOLVABLE, f"no plan: {dead}")
    cache: dict[tuple, MoveCheck] = {}  # (state key, object, place name) -> quick verdict
    run = _Run(
        goal=goal,
        tools=tools,
        config=config,
        memory=memory,
        cache=cache,
        stats=stats,
        t0=t0,
        hints=hints or {},
    )
    while True:
        found = _search(run, scene)
        if isinstance(found, tuple):  # (status, reason): no plan this round
            return end(*found)
        verified = _verify(scene, found, tools, config, memory, cache, stats)
        if verified is not None:
            return end(GeoStatus.SOLVED, f"a plan of {len(verified)} moves", verified)
        stats["restarts"] += 1


def _verify(scene, moves, tools, config, memory, cache, stats) -> list[GeoMove] | None:
    """The full check of each move of a plan found with quick checks, in order: the moves
    with the grasps that passed, or None after recording the first failure in the memory and
    the cache (the next round searches around it)."""
    world, out = scene, []
    for move in moves:
        key = state_key(world)
        o = world.object(move.obj)
        grasps = memory.open(world, key, move, candidate_grasps(o, config.choices))
        first = [g for g in grasps if move.grasp is not None and g.name == move.grasp.name]
        grasps = (*first, *grasp_order(world, o, [g for g in grasps if g not in first]))
        check = check_move(world, GeoMove(move.obj, move.place), tools, grasps=grasps)
        _count(stats, check, full=True)
        if not check.ok:
            memory.record(world, key, move, check)
            cache[(key, move.obj, move.place.name)] = check
            return None
        out.append(replace(move, grasp=check.grasp))
        world = moved(world, move.obj, move.place.pose)
    return out


def _count(stats: dict, check: MoveCheck, full: bool) -> None:
    stats["checks"] += 1
    stats["full_checks"] += full
    stats["failures"] += not check.ok
    stats["check_time_s"] += check.time_s


@dataclass(frozen=True)
class _Run:
    """What every round of one `plan_search` shares: the goal, the tools and budgets, the
    failure memory, the quick checks' verdicts (``cache``), the counts (``stats``), the start
    time and the ``hints`` places."""

    goal: Goal
    tools: Tools
    config: SearchConfig
    memory: _Memory
    cache: dict[tuple, MoveCheck]  # (state key, object, place name) -> quick verdict
    stats: dict
    t0: float
    hints: Mapping


@dataclass
class _Round:
    """One round's best-first search: its nodes (by id), its open queue and its guide."""

    run: _Run
    guide: _Guide
    nodes: list[_Node] = field(default_factory=list)
    queue: list = field(default_factory=list)
    tie: itertools.count = field(default_factory=itertools.count)


def _search(run: _Run, scene: Scene):
    """One round of the best-first search with quick checks: the moves of a plan, or
    (status, reason) when the round ends without one."""
    goal, tools, config, memory = run.goal, run.tools, run.config, run.memory
    cache, stats = run.cache, run.stats
    search = _Round(run, _Guide(goal))
    nodes, queue = search.nodes, search.queue
    nodes.append(_Node(scene, dict(read_facts(scene).supports), 0, None, None))
    closed = {state_key(scene)}
    _expand(search, 0)
    while queue:
        if time.perf_counter() - run.t0 > config.max_time_s:
            return GeoStatus.BUDGET, f"stopped after {stats['nodes']} expansions (time)"
        *_, parent_id, move = heapq.heappop(queue)
        parent = nodes[parent_id]
        child = moved(parent.scene, move.obj, move.place.pose)
        key = state_key(child)
        if key in closed:
            continue
        parent_key = state_key(parent.scene)
        known = cache.get((parent_key, move.obj, move.place.name))
        if known is None:
            o = parent.scene.object(move.obj)
            grasps = memory.open(
                parent.scene, parent_key, move, candidate_grasps(o, config.choices)
            )
            if not grasps:
                continue
            grasps = grasp_order(parent.scene, o, grasps)
            known = check_move(parent.scene, move, tools, grasps=grasps, full=False)
            _count(stats, known, full=False)
            cache[(parent_key, move.obj, move.place.name)] = known
            if not known.ok:
                memory.record(parent.scene, parent_key, move, known)
        if not known.ok:
            continue
        closed.add(key)
        facts = read_facts(child)
        done = replace(move, grasp=known.grasp)
        node = _Node(child, dict(facts.supports), parent.g + 1, parent_id, done)
        nodes.append(node)
        if goal.holds(facts):
            return _path(nodes, len(nodes) - 1)
        if stats["nodes"] >= config.max_nodes:
            return GeoStatus.BUDGET, f"stopped after {stats['nodes']} expansions (nodes)"
        _expand(search, len(nodes) - 1)
    return (
        GeoStatus.UNSOLVABLE,
        f"no plan within the discretised choices: {config.places} places per target, grasps "
        f"{', '.join(config.choices)} ({len(closed)} states reached, {stats['failures']} "
        "checks failed)",
    )


def _path(nodes: list[_Node], i: int) -> list[GeoMove]:
    out = []
    while nodes[i].parent is not None:
        out.append(nodes[i].move)
        i = nodes[i].parent
    return out[::-1]


class _Guide:
    """The search's guidance beyond `heuristic`: how many neighbours hem in an object that must
    move (`blockers`), and which objects a plan plausibly moves at all (`relevant`)."""

    def __init__(self, goal: Goal) -> None:
        self.goal = goal
        self.subjects = {a[1] for a in goal.atoms if a[0] != "clear"}
        self._blockers: dict[tuple, frozenset[str]] = {}

    def blockers(self, scene: Scene, x: str) -> frozenset[str]:
        """The neighbours of ``x`` that hem in every top-down grasp of it (the reference open
        hand of `tamp.world.canonical.free_top_axes`): none when one is free; else the first
        neighbour, or pair of neighbours, whose removal frees one; none when no such set
        exists (posts or walls hem it in, or no top grasp fits: side grasps may)."""
        from tamp.world.canonical import free_top_axes

        hood = _neighbourhood(scene, x)
        if hood not in self._blockers:
            near = [h[0] for h in hood if h[0] != x]
            found: frozenset[str] = frozenset()
            if near and not free_top_axes(scene, x):
                for k in (1, 2):
                    sets = (frozenset(c) for c in itertools.combinations(near, k))
                    found = next((c for c in sets if free_top_axes(scene, x, without=c)), found)
                    if found:
                        break
            self._blockers[hood] = found
        return self._blockers[hood]

    def estimate(self, scene: Scene, supports: dict) -> int:
        """`heuristic`'s movers plus the objects hemming them in (`blockers`), twice for a
        blocker whose own goal atoms hold now (it must go out and come back): a guide, not a
        bound."""
        must = self.movers(supports)
        hemming: set[str] = set()
        for x in must:
            hemming |= self.blockers(scene, x)
        back = {y for y in hemming - must if y in self.subjects}
        return len(must | hemming) + len(back)

    def movers(self, supports: dict) -> set[str]:
        return _movers(supports, self.goal)

    def relevant(self, scene: Scene, supports: dict) -> set[str]:
        """The objects that must move, those near them (blockers), and those in or on the
        regions and objects unmet goal atoms put things in or on."""
        must = self.movers(supports)
        out = set(must)
        solids = {o.name: of_movable(o) for o in scene.objects}
        for x in must:
            out |= {y for y, s in solids.items() if footprint_gap(solids[x], s) < NEAR}
        for atom in self.goal.atoms:
            if atom[0] in ("in", "on") and not holds_in(atom, supports):
                out |= {y for y, s in supports.items() if s == atom[2]}
        return out


def _expand(search: _Round, i: int) -> None:
    """Queue every successor of node ``i`` unchecked, keyed (f, -g, place rank, insertion);
    f = g + weight (h + blockers) plus a penalty of 1 for moving an object no goal atom
    plausibly involves and 1 for moving the object the last move moved (orderings only:
    nothing is pruned); h is `_Guide.estimate`. The ``hints`` places of (object, target)
    where they are free rank before `candidate_places`'."""
    config, stats, hints, guide = (
        search.run.config,
        search.run.stats,
        search.run.hints,
        search.guide,
    )
    node = search.nodes[i]
    stats["nodes"] += 1
    scene, supports = node.scene, node.supports
    under = set(supports.values())
    clear = [o.name for o in scene.objects if o.name not in under and o.name in supports]
    targets = [*clear, *(r.name for r in scene.regions), TABLE]
    relevant = guide.relevant(scene, supports)
    last = None if node.move is None else node.move.obj
    g = node.g + 1
    for x in clear:
        penalty = (x not in relevant) + (x == last)
        for target in targets:
            if target == x or (target == supports[x] and target not in (TABLE, *_regions(scene))):
                continue
            hinted = [p for p in hints.get((x, target), ()) if free(scene, x, p)]
            places = candidate_places(scene, x, target, config.places, config.seed)
            for rank, place in enumerate([*hinted, *places]):
                if _same_spot(scene, x, place):
                    continue
                after = dict(supports)
                after[x] = target
                child = moved(scene, x, place.pose)
                h = guide.estimate(child, after)
                f = g + config.weight * h + penalty
                stats["generated"] += 1
                entry = (f, -g, rank, next(search.tie), i, GeoMove(x, place))
                heapq.heappush(search.queue, entry)


def _regions(scene: Scene) -> tuple[str, ...]:
    return tuple(r.name for r in scene.regions)


def _same_spot(scene: Scene, obj: str, place: Place) -> bool:
    """True when ``place`` is where ``obj`` stands already (within 5 mm)."""
    here = scene.object(obj).pose.xyz
    return math.dist(here, place.xyz) < 0.005
