"""Best-first search over world states with the arm's feasibility checked lazily: the complete
planner of the geometric TAMP room over its discretised grasp and placement choices.

A node is a world state (a `Scene` with the objects' poses; its facts read from the geometry),
its key the objects' poses rounded to a millimetre. A successor moves one clear object onto a
clear object, into a region or onto the table, at one of `candidate_places` (``places`` per
target). Successors are queued A*-like, f = g + h with g the moves so far and h (`heuristic`)
the objects that must still move at least once: the subjects of the unmet goal atoms and
everything stacked above an object such an atom needs to move or to uncover (admissible, so the
first plan found is a shortest one among the feasible choices). Ties go to the deeper node,
then to the better-ranked place, then to objects nearer the goal's objects (the blockers).

Feasibility is decided when a successor is popped, not when it is generated (PDDLStream's
incremental idea): `tamp.geo.check.check_move` with the grasps the failure memory has not
ruled out. The memory records what failed where it failed:

- a grasp that failed on the pick side (reaching or closing on the object) is ruled out for
  that object in that neighbourhood (its pose and those of the objects within `NEAR`), for
  every place, when what it hit is in that neighbourhood (else in that state only);
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
from dataclasses import dataclass, replace

import numpy as np

from motion.grasps import world_tcp
from tamp.geo.check import MoveCheck, Tools, candidate_grasps, check_move, grasp_order
from tamp.geo.places import candidate_places, supported_on
from tamp.geo.types import TABLE, GeoMove, GeoPlan, GeoStatus, Place, moved
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
    clock; ``seed``: the places' samples; ``weight``: 1 is A*, above 1 weighted A*."""

    max_nodes: int = 500
    max_time_s: float = 120.0
    places: int = 6
    choices: tuple[str, ...] = ("top", "side", "tilt")
    seed: int = 0
    weight: float = 1.0


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
        if _holds(atom, supports):
            continue
        if atom[0] == "clear":
            movers |= stack(atom[1])
            continue
        movers |= {atom[1]} | stack(atom[1])
        if atom[0] == "on":
            movers |= stack(atom[2])
    return len(movers)


def _holds(atom: Atom, supports: dict) -> bool:
    pred, x = atom[0], atom[1]
    if pred == "clear":
        return x not in supports.values()
    if pred == "ontable":
        return supports.get(x) == TABLE
    return supports.get(x) == atom[2]  # on / in


def _neighbourhood(scene: Scene, obj: str) -> tuple:
    """``obj``'s pose and those of the objects within `NEAR` of it, rounded (a memory key)."""
    me = of_movable(scene.object(obj))
    near = [x for x in scene.objects if x.name == obj or footprint_gap(me, of_movable(x)) < NEAR]
    return tuple((x.name, *(round(v, 3) for v in x.pose.xyz)) for x in near)


class _Memory:
    """The failure memory (see the module docstring): which grasps are ruled out for a move."""

    def __init__(self, scene: Scene) -> None:
        self.fixed = {s.name for s in fixed_solids(scene)} | {"table"}
        self.pick: set[tuple] = set()  # (neighbourhood, obj, grasp)
        self.place: set[tuple] = set()  # (obj, grasp, place name)
        self.move: set[tuple] = set()  # (state key, obj, grasp, place name)
        self.ruled_out = 0  # grasps skipped because the memory ruled them out

    def open(self, scene: Scene, key: tuple, move: GeoMove, grasps) -> tuple:
        hood = _neighbourhood(scene, move.obj)
        out = []
        for g in grasps:
            if (
                (hood, move.obj, g.name) in self.pick
                or (key, move.obj, g.name, move.place.name) in self.move
                or (move.obj, g.name, move.place.name) in self.place
            ):
                self.ruled_out += 1
                continue
            out.append(g)
        return tuple(out)

    def record(self, scene: Scene, key: tuple, move: GeoMove, check: MoveCheck) -> None:
        hood = _neighbourhood(scene, move.obj)
        local = {h[0] for h in hood} | self.fixed
        for t in check.tried:
            if t.failure is None:
                continue
            if t.side == "pick" and (t.failure == "ik_infeasible" or t.other in local):
                self.pick.add((hood, move.obj, t.grasp))
            elif t.failure == "ik_infeasible" and t.where == "place":
                self.place.add((move.obj, t.grasp, move.place.name))
            else:
                self.move.add((key, move.obj, t.grasp, move.place.name))


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


def plan_search(scene: Scene, goal: Goal, tools: Tools, config: SearchConfig = DEFAULT) -> GeoPlan:
    """Plan moves from ``scene`` to ``goal`` (see the module docstring). ``stats``: nodes
    (expanded), generated, checks (`check_move` calls), failures (checks that failed),
    ruled_out (grasps the failure memory skipped), time_s, check_time_s."""
    t0 = time.perf_counter()
    stats = {"nodes": 0, "generated": 0, "checks": 0, "failures": 0, "check_time_s": 0.0}

    def end(status: GeoStatus, reason: str = "", moves=()) -> GeoPlan:
        stats["ruled_out"] = memory.ruled_out
        stats["time_s"] = time.perf_counter() - t0
        return GeoPlan(status, tuple(moves), reason, stats)

    memory = _Memory(scene)
    start = _Node(scene, dict(read_facts(scene).supports), 0, None, None)
    dead = dead_goal(scene, goal, tools, config)
    if dead:
        return end(GeoStatus.UNSOLVABLE, f"no plan: {dead}")
    nodes = [start]
    closed = {state_key(scene)}
    goal_objects = [of_movable(scene.object(a[1])) for a in goal.atoms]
    if goal.holds(read_facts(scene)):
        return end(GeoStatus.SOLVED, "the goal holds already")
    tie = itertools.count()
    queue: list = []
    _expand(0, nodes, goal, config, queue, tie, goal_objects, stats)
    while queue:
        if time.perf_counter() - t0 > config.max_time_s:
            return end(GeoStatus.BUDGET, f"stopped after {stats['nodes']} expansions (time)")
        *_, parent_id, move = heapq.heappop(queue)
        parent = nodes[parent_id]
        child = moved(parent.scene, move.obj, move.place.pose)
        key = state_key(child)
        if key in closed:
            continue
        parent_key = state_key(parent.scene)
        o = parent.scene.object(move.obj)
        grasps = memory.open(parent.scene, parent_key, move, candidate_grasps(o, config.choices))
        if not grasps:
            continue
        check = check_move(parent.scene, move, tools, grasps=grasp_order(parent.scene, o, grasps))
        stats["checks"] += 1
        stats["check_time_s"] += check.time_s
        if not check.ok:
            stats["failures"] += 1
            memory.record(parent.scene, parent_key, move, check)
            continue
        closed.add(key)
        facts = read_facts(child)
        done = replace(move, grasp=check.grasp)
        node = _Node(child, dict(facts.supports), parent.g + 1, parent_id, done)
        nodes.append(node)
        if goal.holds(facts):
            return end(GeoStatus.SOLVED, f"a plan of {node.g} moves", _path(nodes, len(nodes) - 1))
        if stats["nodes"] >= config.max_nodes:
            return end(GeoStatus.BUDGET, f"stopped after {stats['nodes']} expansions (nodes)")
        _expand(len(nodes) - 1, nodes, goal, config, queue, tie, goal_objects, stats)
    grasps = ", ".join(config.choices)
    return end(
        GeoStatus.UNSOLVABLE,
        f"no plan within the discretised choices: {config.places} places per target, grasps "
        f"{grasps} ({len(closed)} states reached, {stats['failures']} checks failed)",
    )


def _path(nodes: list[_Node], i: int) -> list[GeoMove]:
    out = []
    while nodes[i].parent is not None:
        out.append(nodes[i].move)
        i = nodes[i].parent
    return out[::-1]


def _expand(i, nodes, goal, config, queue, tie, goal_objects, stats) -> None:
    """Queue every successor of node ``i`` unchecked, keyed (f, -g, place rank, distance of
    the moved object to the goal's objects, insertion)."""
    node = nodes[i]
    stats["nodes"] += 1
    scene, supports = node.scene, node.supports
    under = set(supports.values())
    clear = [o.name for o in scene.objects if o.name not in under and o.name in supports]
    targets = [*clear, *(r.name for r in scene.regions), TABLE]
    g = node.g + 1
    for x in clear:
        me = of_movable(scene.object(x))
        near = min((footprint_gap(me, s) for s in goal_objects if s.name != x), default=0.0)
        for target in targets:
            if target == x or (target == supports[x] and target not in (TABLE, *_regions(scene))):
                continue
            for rank, place in enumerate(
                candidate_places(scene, x, target, config.places, config.seed)
            ):
                if _same_spot(scene, x, place):
                    continue
                after = dict(supports)
                after[x] = target
                f = g + config.weight * heuristic(after, goal)
                stats["generated"] += 1
                heapq.heappush(queue, (f, -g, rank, near, next(tie), i, GeoMove(x, place)))


def _regions(scene: Scene) -> tuple[str, ...]:
    return tuple(r.name for r in scene.regions)


def _same_spot(scene: Scene, obj: str, place: Place) -> bool:
    """True when ``place`` is where ``obj`` stands already (within 5 mm)."""
    here = scene.object(obj).pose.xyz
    return math.dist(here, place.xyz) < 0.005
