"""The search-then-check baseline: plan symbolically ignoring geometry, then bind each move to a
place and a grasp the arm can do; on a failure, forbid that move in that symbolic state and
replan. What a user would pick before a TAMP planner that searches over geometry.

The symbolic search is A* over supports (each object on an object, in a region or on the
table; moves put a clear object onto a clear object, into a region or onto the table; unit
costs, `tamp.geo.search.heuristic` as its admissible estimate), blind to where things are: a
move from the table to the table or within a region is no move to it. Binding walks the plan
in order from the scene: for each move, the places of `candidate_places` in order, each with
the grasps `check_move` tries, first feasible wins, and the scene moves on. A move no place
and grasp bind is added as a constraint, (symbolic state, move) forbidden, and the symbolic
search runs again from the start. Checks of a (world state, object, place) already decided
are reused, not repeated.

The constraints are symbolic, so the baseline is not complete over the geometric choices:
when every symbolic plan is forbidden it ends UNSOLVABLE saying so, and BUDGET when
``max_time_s`` (or ``symbolic_nodes`` expansions in one symbolic search) runs out.
"""

from __future__ import annotations

import heapq
import itertools
import time

from tamp.geo.check import MoveCheck, Tools, candidate_grasps, check_move, grasp_order
from tamp.geo.places import candidate_places, fixed_targets
from tamp.geo.search import DEFAULT, SearchConfig, heuristic, holds_in, state_key
from tamp.geo.types import GeoMove, GeoPlan, GeoStatus, moved
from tamp.world.goal import Goal
from tamp.world.relations import read_facts
from tamp.world.schema import Scene

Supports = tuple[tuple[str, str], ...]  # (object, support) in scene order
SymMove = tuple[str, str]  # (object, target)


def symbolic_moves(supports: Supports, targets: tuple[str, ...]) -> list[SymMove]:
    """The moves from ``supports``: a clear object onto another clear object, into a region or
    onto the table (``targets``: the regions' names and TABLE), not onto what it rests on."""
    under = {s for _, s in supports}
    clear = [x for x, _ in supports if x not in under]
    now = dict(supports)
    return [(x, t) for x in clear for t in (*clear, *targets) if t != x and t != now[x]]


def apply_symbolic(supports: Supports, move: SymMove) -> Supports:
    x, t = move
    return tuple((y, t if y == x else s) for y, s in supports)


def symbolic_plan(
    supports: Supports,
    goal: Goal,
    targets: tuple[str, ...],
    forbidden: set[tuple[Supports, SymMove]],
    max_nodes: int,
) -> tuple[list[SymMove] | None, int]:
    """A shortest move sequence from ``supports`` to ``goal`` avoiding ``forbidden`` (A*),
    and the states expanded; None when there is none (or ``max_nodes`` ran out: the count
    says which)."""
    tie = itertools.count()
    queue = [(heuristic(dict(supports), goal), 0, next(tie), supports, ())]
    seen = {supports}
    expanded = 0
    while queue and expanded < max_nodes:
        _, g, _, state, path = heapq.heappop(queue)
        if all(holds_in(a, dict(state)) for a in goal.atoms):
            return list(path), expanded
        expanded += 1
        for move in symbolic_moves(state, targets):
            if (state, move) in forbidden:
                continue
            nxt = apply_symbolic(state, move)
            if nxt in seen:
                continue
            seen.add(nxt)
            f = g + 1 + heuristic(dict(nxt), goal)
            heapq.heappush(queue, (f, g + 1, next(tie), nxt, (*path, move)))
    return None, expanded


def plan_search_then_check(
    scene: Scene, goal: Goal, tools: Tools, config: SearchConfig = DEFAULT
) -> GeoPlan:
    """Plan symbolically, bind to geometry, forbid what fails, replan (see the module
    docstring). ``stats``: plans (symbolic plans made), nodes (symbolic expansions, all plans),
    checks, failures, constraints, time_s, check_time_s."""
    t0 = time.perf_counter()
    stats = {"plans": 0, "nodes": 0, "checks": 0, "failures": 0, "check_time_s": 0.0}
    targets = fixed_targets(scene)
    start: Supports = tuple(read_facts(scene).supports)
    forbidden: set[tuple[Supports, SymMove]] = set()
    cache: dict[tuple, MoveCheck] = {}

    def end(status: GeoStatus, reason: str, moves=()) -> GeoPlan:
        stats["constraints"] = len(forbidden)
        stats["time_s"] = time.perf_counter() - t0
        return GeoPlan(status, tuple(moves), reason, stats)

    def check(world: Scene, move: GeoMove) -> MoveCheck:
        key = (state_key(world), move.obj, move.place.name)
        if key not in cache:
            o = world.object(move.obj)
            grasps = grasp_order(world, o, candidate_grasps(o, config.choices))
            cache[key] = check_move(world, move, tools, grasps=grasps)
            stats["checks"] += 1
            stats["check_time_s"] += cache[key].time_s
            stats["failures"] += not cache[key].ok
        return cache[key]

    while True:
        if time.perf_counter() - t0 > config.max_time_s:
            return end(GeoStatus.BUDGET, f"stopped after {stats['plans']} symbolic plans (time)")
        plan, expanded = symbolic_plan(start, goal, targets, forbidden, config.symbolic_nodes)
        stats["plans"] += 1
        stats["nodes"] += expanded
        if plan is None:
            if expanded >= config.symbolic_nodes:
                return end(GeoStatus.BUDGET, f"symbolic search stopped at {expanded} expansions")
            return end(
                GeoStatus.UNSOLVABLE,
                f"no symbolic plan left after {len(forbidden)} moves failed to bind "
                f"({config.places} places per target, grasps {', '.join(config.choices)})",
            )
        world, state, bound = scene, start, []
        for obj, target in plan:
            done = None
            for place in candidate_places(world, obj, target, config.places, config.seed):
                verdict = check(world, GeoMove(obj, place))
                if verdict.ok:
                    done = GeoMove(obj, place, verdict.grasp)
                    break
            if done is None:
                forbidden.add((state, (obj, target)))
                break
            bound.append(done)
            world = moved(world, obj, done.place.pose)
            state = apply_symbolic(state, (obj, target))
        else:
            if not goal.holds(read_facts(world)):
                return end(GeoStatus.FAILED, "the bound plan's last state misses the goal")
            return end(GeoStatus.SOLVED, f"a plan of {len(bound)} moves", bound)
