"""Motion-aware planning of a scene-file problem on the project's differentiable planner.

`plan_motion_aware(scene, goal, tools, config)`:

1. bridge the scene and goal to a Blocksworld problem on capacity-one places
   (`tamp.geo.ours.bridge`: the goal regions' cells placed jointly by gradient,
   `tamp.geo.ours.pack`);
2. take the moves that put a goal object onto the target its goal names where the prices
   leave them open, each bound by the full check as in step 3 (`tamp.geo.ours.placing`: a
   tower built bottom up, objects sorted into their cells), only before the first window
   (after one, they would put back what the window moved out of the way);
   then plan the rest with `task.planner.plan` and the arm's prices in the objective
   (`GeoCosts`): the receding windows (the empty cells' places optimised with each restart
   row's logits and fixed by the committed row, `tamp.geo.ours.cells`), then, when they
   revisit a state or run out, the planner's complete lazy fallback
   (`task.symbolic.lazy_search`) over the moves the prices allow, A* from the initial state
   first (`RESTART_PROBE` expansions); an object moved twice in a row in the plan is moved
   once (`merge_runs`);
3. map the plan back to `GeoMove`s in the predicted worlds and bind each to a grasp with the
   full check (`tamp.geo.check.check_move`, the grasps `GeoCosts` found free first). A move
   no grasp passes is fed back as failure memory (`GeoCosts.avoid`: that move, in that state,
   at that place, under the grasps that failed; a grasp that failed on the pick side, at
   every place) and the problem is planned on from the state
   the moves bound so far reached, at most `OursConfig.replans` times. A window prices all
   its moves in its start state, so a later move of it may be priced out in its own state
   (the hand no longer fits once a neighbour is placed): the plan's moves are first put in
   an order each move's own state allows (`reorder`, each object's moves kept in their
   order), and where none is found binding stops at that move and planning goes on from
   that state (`OursConfig.cuts`).

4. when that ends without a plan (the windows, the fallback's nodes, the replans or its
   share of the time, `OursConfig.soft_time_s`, ran out, or the prices, a proxy of the full
   check, allowed no plan at all), the complete geometric search
   (`tamp.geo.search.plan_search`, `OursConfig.search`) goes on from the world the bound
   moves reached, with what is left of the time, the bridged problem's places offered first
   (`cell_hints`: the packer's cells, each object's starting place).

The status is SOLVED with the moves; UNSOLVABLE only when the complete search proved that no
plan exists within the discretised grasps and places (or, with the search off, when the
planner's fallback proved it within the places and the moves the prices allow); BUDGET
otherwise. ``stats["first"]`` says how the differentiable planner's attempt ended.

`plan_pddl` does the same for a problem named by a PDDL domain instead of Blocksworld (Tower of
Hanoi): the generic STRIPS lift plans it (its fallback on), the declared binding
(`task.symbolic.pickplace.binding`) pairs its actions into object -> target moves, and each
move becomes a `GeoMove` onto a disc (centred on its top) or a peg region (the first of
`tamp.geo.places.candidate_places` the full check passes).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

from tamp.geo.ours.bridge import PACK, Bridged, bridge
from tamp.geo.ours.costs import GeoCostConfig, GeoCosts
from tamp.geo.ours.pack import PackConfig
from tamp.geo.ours.placing import next_placing
from tamp.geo.search import SearchConfig
from tamp.geo.types import GeoMove, GeoPlan, GeoStatus, moved
from tamp.outcome import Failure
from tamp.world.goal import Goal
from tamp.world.schema import Scene, SceneFileError
from task.config import PlannerConfig
from task.costs import IMPOSSIBLE
from task.domains.blocksworld import DOMAIN, apply_move, is_goal
from task.domains.blocksworld import check_move as legal
from task.errors import TampError
from task.planner import plan
from task.problem import PlanStatus
from task.symbolic.search import moves_lower_bound
from task.symbolic.shorten import merge_runs

SEARCH_NODES = 5_000  # the complete search's expansions at least (its time bounds it first)
# the differentiable planner's share of the wall clock: 1 / SOFT_SHARE (a sixth left a 10-cube
# tower's 20-move plan unfinished after 9 windows; with a third its 11 windows and binding took
# 24 s of 40)
SOFT_SHARE = 3
# A* from the initial state first when the windows end without a plan (`restart_probe`):
# windows that fill a region's cells in a bad order leave a state A* spent 36 s on, where from
# the initial state it found packed variant 18's 6-move plan in 30 expansions
RESTART_PROBE = 200
PLANNER = PlannerConfig(
    restarts=8,
    iters=40,
    max_windows=4,
    lambda_motion=0.05,
    fallback=True,
    proof_costs=True,
    restart_probe=RESTART_PROBE,
)
# receding windows at least per move the bridged problem's lower bound says the goal needs
# (`PlannerConfig.max_windows`): a window commits one to three moves, and 4 windows stopped a
# 10-cube tower's 20-move plan short; where the bound is small (a region to fill, objects to
# move out and back) the windows gain little over the fallback's search, which the bound
# guides (its cell goals count), so they stay few there
WINDOWS_PER_BOUND_MOVE = 1.5
# check failures no movable object takes part in: ruled out wherever the object stands as it
# stood (`GeoCosts.avoid`'s ``fixed``), not only in the state they happened in
FIXED_FAILURES = (Failure.IK_INFEASIBLE, Failure.NO_CLEARANCE)
# grasps a planned move's full check takes at a time, the grasps the prices found free at both
# ends first (`_check_in_turn`): the first of them passed every move of packed, sorting and
# tall, variants 0-2 (74 of 74), and the check's batched IK and collision tests then cover
# one grasp, not all twenty of a cuboid (bind time 5.6 s with four at a time, 3.7-4.2 with one)
CHECK_CHUNK = 1
BEFORE_GRASPS = (Failure.NOT_CLEAR, Failure.UNSUPPORTED)  # check failures whatever the grasp


@dataclass(frozen=True)
class OursConfig:
    """Settings of the motion-aware planner."""

    planner: PlannerConfig = PLANNER  # the differentiable planner, fallback on
    pack: PackConfig = PACK  # the goal regions' cells
    costs: GeoCostConfig = field(default_factory=GeoCostConfig)
    table_places: int | None = None  # table spots (None: objects + 2)
    replans: int = 4  # plans again after a move no grasp passes, at most this often
    cuts: int = 8  # plans on after a move priced out in its own state, at most this often
    seed: int = 0
    # when the differentiable planner ends without a plan, the complete geometric search
    # (`tamp.geo.search.plan_search`, every move under the full check) goes on from the world
    # its bound moves reached, with these budgets (None: no fallback)
    search: SearchConfig | None = field(default_factory=SearchConfig)
    # wall clock (s) of the differentiable planner's attempt, all its plans and bindings
    # together (None: only ``planner.time_limit_s`` per plan)
    soft_time_s: float | None = None
    # how the goal regions' cells are placed (`tamp.geo.ours.bridge.SAMPLERS`): by gradient,
    # or by rejection sampling at the same budget (the ablation ``motion-aware-sampled``)
    sampler: str = "gradient"
    # before the first window, the moves that put a goal object onto the target its goal names,
    # taken without a window where the prices leave them open (`tamp.geo.ours.placing`); False:
    # every move planned by the windows and the fallback
    placing: bool = True


def _check():
    from tamp.geo.check import check_move

    return check_move


def as_ours(config) -> OursConfig:
    """``config`` as an `OursConfig`: itself, or from the budgets every geometric planner is
    called with (`tamp.geo.search.SearchConfig`: its seed, grasp families and wall-clock limit,
    which bounds the differentiable planner's windows and fallback). Anything else: a
    `TampError` naming the two."""
    if isinstance(config, OursConfig):
        return config
    if not isinstance(config, SearchConfig):
        raise TampError(
            f"the motion-aware planner's config is a {type(config).__name__}; "
            "valid: OursConfig or SearchConfig"
        )
    # the complete search is bounded by the wall clock: at the shared 500 expansions it gave up
    # on nonmonotonic variants with half its time left (`SEARCH_NODES`)
    search = replace(config, max_nodes=max(config.max_nodes, SEARCH_NODES))
    limit = config.max_time_s
    # the differentiable planner gets a third of the wall clock (`SOFT_SHARE`); the complete
    # search what is left
    soft = limit / SOFT_SHARE if limit else None
    planner = replace(PLANNER, time_limit_s=soft) if limit else PLANNER
    return OursConfig(
        planner=planner,
        costs=GeoCostConfig(choices=tuple(config.choices)),
        seed=config.seed,
        search=search,
        soft_time_s=soft,
    )


def plan_motion_aware(
    scene: Scene,
    goal: Goal,
    tools,
    config=OursConfig(),
    check: Callable | None = None,
    domain: tuple[str, ...] | None = None,
) -> GeoPlan:
    """Plan ``goal`` in ``scene`` (module docstring). ``tools``: `tamp.geo.check.Tools` (its
    ``solver`` and ``q`` also price the moves); ``config``: an `OursConfig` or the geometric
    planners' shared `tamp.geo.search.SearchConfig` (`as_ours`); ``check``: the move check
    (default `tamp.geo.check.check_move`); ``domain``: ``(pddl_domain_text, binding_text)``
    or ``(..., problem_text)`` to plan through that PDDL domain instead (`plan_pddl`)."""
    if domain is not None:
        return plan_pddl(scene, goal, tools, domain, config, check)
    t0 = time.perf_counter()
    config = as_ours(config)
    check = check or _check()
    first = _plan_soft(scene, goal, tools, config, check, t0)
    bound = first.stats.pop("bound", ())
    bridged = first.stats.pop("bridged", None)
    if first.solved or config.search is None:
        return first
    attempt = _Attempt(first, bound, cell_hints(bridged))
    return _complete(scene, goal, tools, config, attempt, t0)


def plan_motion_aware_sampled(
    scene: Scene, goal: Goal, tools, config=OursConfig(), check: Callable | None = None
) -> GeoPlan:
    """`plan_motion_aware` with the goal regions' cells placed by rejection sampling
    (`tamp.geo.ours.pack.pack_sampled`) at the gradient packer's budget: the ablation that
    says what the gradient placements gain."""
    config = replace(as_ours(config), sampler="sampled")
    return plan_motion_aware(scene, goal, tools, config, check)


def cell_hints(bridged: Bridged | None) -> dict:
    """The bridged problem's places as `plan_search` hints, (object, target) -> places: the
    packer's cell of each goal object in its region, and the place each object stood on at
    the start (where it goes back to when it must move out of the way and return)."""
    if bridged is None:
        return {}
    p, out = bridged.problem, {}
    starts = [(x, s) for x, s in zip(p.entities, p.init, strict=True) if s in p.fixed]
    for x, name in (*bridged.cells, *starts):
        site = bridged.site(name)
        out.setdefault((x, site.target), []).append(site.place(bridged.scene.object(x)))
    return {k: tuple(v) for k, v in out.items()}


@dataclass(frozen=True)
class _Attempt:
    """The differentiable planner's unsolved attempt: its ``plan``, the moves it ``bound``
    (executable in order) and the places of the packer's cells (``hints``, per (object,
    target), `cell_hints`)."""

    plan: GeoPlan
    bound: tuple
    hints: dict


def _complete(scene, goal, tools, config: OursConfig, attempt: _Attempt, t0: float):
    """The complete geometric search from the world the first ``attempt``'s bound moves
    reached, within what is left of the time budget, the packer's cells (its ``hints``)
    offered first in their regions; its status is the answer (UNSOLVABLE from it is
    exhaustive over the discretised grasps and places under the full check), the bound
    moves first."""
    from tamp.geo.search import plan_search

    first, bound, hints = attempt.plan, attempt.bound, attempt.hints
    world = scene
    for move in bound:
        world = moved(world, move.obj, move.place.pose)
    left = config.search.max_time_s - (time.perf_counter() - t0)
    if left <= 0:
        return first
    found = plan_search(world, goal, tools, replace(config.search, max_time_s=left), hints)
    stats = {
        **first.stats,
        "first": {"status": first.status.value, "reason": first.reason, "bound": len(bound)},
        "search": found.stats,
        "time_s": time.perf_counter() - t0,
    }
    reason = found.reason
    if not found.solved:
        reason = f"{found.reason} (after the differentiable planner: {first.reason})"
    return GeoPlan(found.status, (*bound, *found.moves), reason, stats)


def _plan_soft(scene: Scene, goal: Goal, tools, config: OursConfig, check, t0: float) -> GeoPlan:
    """The differentiable planner's attempt (steps 1-3 of the module docstring); a plan that
    ends unsolved carries the moves it bound in ``stats["bound"]``."""
    try:
        bridged = bridge(scene, goal, config.table_places, config.pack, config.seed, config.sampler)
    except SceneFileError as exc:
        return GeoPlan(GeoStatus.FAILED, reason=str(exc), stats={"time_s": 0.0})
    stats: dict = {"places": len(bridged.sites), "packs": _packs(bridged), "bridged": bridged}
    unpacked = [r for r, p in bridged.packs if not p.ok]
    if unpacked:
        stats["time_s"] = time.perf_counter() - t0
        why = f"no free arrangement of the goal objects in region(s) {', '.join(unpacked)}"
        return GeoPlan(GeoStatus.BUDGET, reason=why, stats=stats)
    solver, q = (None, None) if tools is None else (tools.solver, tools.q)
    costs = GeoCosts(bridged, solver, q, config.costs, pack=config.pack)
    failures, plans, cuts = [], 0, 0
    state, world, bound = bridged.problem.init, bridged.scene, []
    least = moves_lower_bound(bridged.problem, bridged.problem.init)  # moves the goal needs
    windows = max(config.planner.max_windows, math.ceil(WINDOWS_PER_BOUND_MOVE * least))
    while len(failures) <= config.replans and cuts <= config.cuts:
        planner = replace(config.planner, max_windows=windows)
        if config.soft_time_s is not None:
            left = config.soft_time_s - (time.perf_counter() - t0)
            if left <= 0:
                stats["bound"] = tuple(bound)
                why = f"the differentiable planner's {config.soft_time_s:g} s ran out"
                return _done(GeoStatus.BUDGET, (), why, stats, t0, plans, failures)
            limit = planner.time_limit_s
            planner = replace(planner, time_limit_s=left if limit is None else min(limit, left))
        if config.placing and not plans:  # the opening moves into position (`placing`)
            state, world, more, failed = _take_placing(bridged, state, world, tools, costs, check)
            bound += more
            stats["placing_moves"] = stats.get("placing_moves", 0) + len(more)
            if failed is not None:
                failures.append(failed)
                continue
            if is_goal(bridged.problem, state):
                return _done(GeoStatus.SOLVED, tuple(bound), "", stats, t0, plans, failures)
        plans += 1
        now = replace(bridged.problem, init=state)
        result = plan(now, planner, seed=config.seed + plans - 1, costs=costs)
        bridged = costs.bridged  # the cells the committed windows settled
        stats["bridged"] = bridged
        stats.update(_planner_stats(result, costs))
        if result.status is PlanStatus.UNSOLVABLE and state == bridged.problem.init:
            why = result.stats.get("fallback", {}).get("reason", "no plan")
            why = f"within the discretised places: {why}"
            return _done(GeoStatus.UNSOLVABLE, (), why, stats, t0, plans, failures)
        if not result.solved:
            why = result.stats.get("fallback", {}).get("reason", "the windows ran out")
            if state != bridged.problem.init:
                why = f"after {len(bound)} bound moves: {why}"
            stats["bound"] = tuple(bound)
            return _done(GeoStatus.BUDGET, (), why, stats, t0, plans, failures)
        # an object moved twice in a row (one window parks it, the next moves it on, or back
        # where it stood): once, where its prices allow the one move, or not at all
        moves = merge_runs(DOMAIN, now, state, result.plan.moves, _allowed(costs))
        # a window prices its moves in its start state: put them in an order each move's own
        # state allows first, where one exists
        moves = reorder(bridged, costs, state, moves) or moves
        state, world, more, failed = _bind(bridged, state, world, moves, tools, costs, check)
        bound += more
        if failed is None:
            return _done(GeoStatus.SOLVED, tuple(bound), "", stats, t0, plans, failures)
        if failed.get("failure") == "priced":
            cuts += 1  # a window's later move its own state prices out: plan on from there
        else:
            failures.append(failed)
    why = f"{len(failures)} planned moves failed the full check; the replan budget is spent"
    stats["bound"] = tuple(bound)
    return _done(GeoStatus.BUDGET, (), why, stats, t0, plans, failures)


def _take_placing(bridged: Bridged, state, world, tools, costs: GeoCosts, check):
    """The placing moves (`tamp.geo.ours.placing.next_placing`) from crisp ``state`` and
    ``world``, each bound by the full check as it is taken (`_bind`), until none is open or
    one fails; returns as `_bind` does."""
    bound: list[GeoMove] = []
    while (move := next_placing(bridged.problem, state, costs)) is not None:
        state, world, more, failed = _bind(bridged, state, world, (move,), tools, costs, check)
        bound += more
        if failed is not None:
            return state, world, tuple(bound), failed
    return state, world, tuple(bound), None


def _allowed(costs: GeoCosts) -> Callable:
    """Whether a legal move is open in a crisp state under ``costs`` (not priced out)."""
    return lambda state, move: costs.price_of(state, move) < IMPOSSIBLE


def reorder(bridged: Bridged, costs: GeoCosts, state, moves, budget: int = 200):
    """``moves`` in an order in which each is legal and not priced out in its own state
    (`GeoCosts.price`), the moves of each object kept in their order (so the plan ends in the
    same state), the planned order tried first; None when no such order is found within
    ``budget`` states. A window prices all its moves in its start state: placing o5 then o4
    may look free there though o4's hand no longer fits beside o5; this repairs the order.
    Only the moves tried are priced in each state (`GeoCosts.price_of`)."""
    p = bridged.problem
    dead: set[frozenset] = set()
    seen = 0

    def search(state, left: tuple[int, ...]) -> list[int] | None:
        nonlocal seen
        if not left:
            return []
        key = frozenset(left)
        if key in dead or seen >= budget:
            return None
        seen += 1
        for k, i in enumerate(left):
            move = moves[i]
            if any(moves[j].entity == move.entity for j in left[:k]):
                continue  # an earlier move of the same object comes first
            if legal(p, state, move) is not None:
                continue
            if costs.price_of(state, move) >= IMPOSSIBLE:
                continue
            rest = search(apply_move(p, state, move), left[:k] + left[k + 1 :])
            if rest is not None:
                return [i, *rest]
        dead.add(key)
        return None

    order = search(tuple(state), tuple(range(len(moves))))
    return None if order is None else tuple(moves[i] for i in order)


def _bind(bridged: Bridged, state, world, moves, tools, costs: GeoCosts, check):
    """Each planned move, from crisp ``state`` and ``world``, as a `GeoMove` with the grasp the
    full check passes, in the world the moves before it leave. Returns the state and world
    after the bound moves, those moves, and None or why the next one was not bound: priced out
    in its own state (a window prices all its moves in its start state), or refused by the full
    check (recorded in ``costs``)."""
    from tamp.geo.check import candidate_grasps

    p, bound = bridged.problem, []
    for move in moves:
        if costs.price_of(state, move) >= IMPOSSIBLE:
            return state, world, tuple(bound), {"move": str(move), "failure": "priced"}
        geo = bridged.geo_move(world, move)
        o = world.object(move.entity)
        first = costs.grasps_left(state, move)
        grasps = candidate_grasps(o, costs.config.choices)
        by_name = {g.name: g for g in grasps}
        order = tuple(by_name[n] for n in first) + tuple(g for g in grasps if g.name not in first)
        verdict = _check_in_turn(check, world, geo, tools, order)
        if not verdict.ok:
            tried = verdict.tried
            movable = {x.name for x in world.objects}
            for t in tried:
                fixed = t.failure in FIXED_FAILURES or (
                    t.failure is Failure.COLLISION and bool(t.other) and t.other not in movable
                )
                costs.avoid(state, move, t.grasp, geo.place.name, fixed, t.side)
            if not tried:  # failed before any grasp: the move, at that place, in that state
                costs.avoid(state, move, None, geo.place.name)
            failure = {"move": str(move), "place": geo.place.name, "failure": verdict.failure}
            return state, world, tuple(bound), failure
        bound.append(GeoMove(geo.obj, geo.place, verdict.grasp))
        world = moved(world, geo.obj, geo.place.pose)
        state = apply_move(p, state, move)
    return state, world, tuple(bound), None


def _check_in_turn(check, world, geo: GeoMove, tools, order, chunk: int = CHECK_CHUNK):
    """The full check of ``geo`` with the grasps of ``order`` (best first), ``chunk`` at a
    time: the first that passes wins, as one call with them all would give (`check_move`
    tries its grasps in order), but the batched IK and the arm's collision tests of its cheap
    half (`tamp.geo.check.quick_check`) cover only the grasps up to the chunk that passes;
    a chunk of one grasp goes straight to its full plan (the cheap half would only repeat
    the poses and collision tests the full plan decides).
    A refusal is the last chunk's that tried a grasp, listing every grasp tried."""
    tried, verdict, last = [], None, None
    for k in range(0, max(len(order), 1), chunk):
        grasps = order[k : k + chunk]
        # one grasp: no cheap half first (`check_move`'s ``quick``), its full plan decides
        verdict = check(world, geo, tools, grasps=grasps, quick=None if len(grasps) > 1 else False)
        if verdict.ok or verdict.failure in BEFORE_GRASPS:
            return verdict
        if not verdict.tried:
            if verdict.failure is Failure.NO_GRASP:
                continue  # every grasp of this chunk too wide for the hand
            break  # refused before any grasp: the others would be too
        tried += verdict.tried
        last = verdict
    return verdict if last is None else replace(last, tried=tuple(tried))


def _packs(bridged: Bridged) -> dict:
    return {
        r: {"ok": p.ok, "time_s": round(p.time, 4), "overlap_m": round(p.overlap, 5)}
        for r, p in bridged.packs
    }


def _planner_stats(result, costs: GeoCosts) -> dict:
    cells = costs.cells
    out = {
        "cells_settled": 0 if cells is None else len(cells.moved) - cells.kept,
        "cells_kept": 0 if cells is None else cells.kept,
        "windows": result.stats.get("windows", 0),
        "plan_s": result.stats.get("time_s", 0.0),
        "priced_states": costs.stats["states"],
        "ms_per_state": 1000 * costs.stats["price_s"] / max(costs.stats["states"], 1),
    }
    if "fallback" in result.stats:
        out["fallback"] = result.stats["fallback"]
    return out


def _done(status, moves, reason, stats, t0, plans, failures) -> GeoPlan:
    stats = {**stats, "time_s": time.perf_counter() - t0, "plans": plans, "failures": failures}
    return GeoPlan(status, tuple(moves), reason, stats)


# ---- a pick-and-place PDDL domain (Hanoi, a user's) ---------------------------------------------

PDDL_PLACES = 32  # region places `plan_pddl` tries per move, in `candidate_places`' order
# (nearest the walls and neighbours first, for packing): 8 were all too tight for the fingers
# when a cube goes into the tray scene's tray beside another object


def pddl_problem_text(scene: Scene, goal: Goal) -> str:
    """The Hanoi problem PDDL of ``scene`` and ``goal`` (`tamp.world.canonical.hanoi_pddl`:
    the discs and pegs, ``smaller`` by width, the state read from the geometry)."""
    from types import SimpleNamespace

    from tamp.world.canonical import hanoi_pddl

    return hanoi_pddl(SimpleNamespace(scene=scene, goal=goal))


def plan_pddl(
    scene: Scene,
    goal: Goal,
    tools,
    domain: tuple[str, ...],
    config=OursConfig(),
    check: Callable | None = None,
) -> GeoPlan:
    """Plan through a pick-and-place PDDL domain (module docstring). ``domain``:
    ``(domain_text, binding_text)`` (the problem written by `tamp.world.scene_pddl` when the
    binding has a scene section, else by `pddl_problem_text`, Hanoi's) or ``(domain_text,
    binding_text, problem_text)``. The lift plans with its fallback on; each paired move goes
    onto an object (centred on its top), or into a region or onto the table at the first of
    `candidate_places` (``config.table_places`` of them, default `PDDL_PLACES`) that the full
    check passes. A move none passes ends planning with BUDGET (the lift gets no failure
    memory)."""
    from tamp.geo.places import candidate_places
    from tamp.world import scene_pddl
    from task.domains.strips import problem_from_text
    from task.symbolic import pddl_io
    from task.symbolic.pickplace import binding as binder

    t0 = time.perf_counter()
    config = as_ours(config)
    check = check or _check()
    domain_text, binding_text = domain[0], domain[1]
    bound = binder.bind_text(binding_text, pddl_io.parse_domain(domain_text, "domain"))
    try:
        if len(domain) > 2:
            problem_text = domain[2]
        elif bound.scene is not None:  # the binding says how the scene reads as its state
            problem_text = scene_pddl.problem_text(scene, goal, bound)
        else:
            problem_text = pddl_problem_text(scene, goal)
        lifted = problem_from_text(domain_text, problem_text, scene.name)
    except TampError as exc:  # e.g. a disc that slid off its peg: no state of the domain
        why = f"the scene is no state of the PDDL domain: {exc}"
        return GeoPlan(GeoStatus.FAILED, reason=why, stats={"time_s": time.perf_counter() - t0})
    planner = replace(
        PlannerConfig.for_domain("strips"),
        fallback=True,
        max_windows=config.planner.max_windows,
        time_limit_s=config.planner.time_limit_s,
    )
    result = plan(lifted, planner, seed=config.seed)
    stats = {"windows": result.stats.get("windows", 0), "plan_s": result.stats.get("time_s")}
    if "fallback" in result.stats:
        stats["fallback"] = result.stats["fallback"]
    if result.status is PlanStatus.UNSOLVABLE:
        why = f"within the PDDL problem's moves: {stats['fallback']['reason']}"
        return _done(GeoStatus.UNSOLVABLE, (), why, stats, t0, 1, [])
    if not result.solved:
        why = stats.get("fallback", {}).get("reason", "the windows ran out")
        return _done(GeoStatus.BUDGET, (), why, stats, t0, 1, [])
    world, out = scene, []
    objects = {o.name for o in scene.objects}
    for move in binder.to_moves(bound, result.plan.moves):
        if move.target in objects:
            places = (bridge_on(world, move.entity, move.target),)
        else:
            n = config.table_places or PDDL_PLACES
            places = candidate_places(world, move.entity, move.target, n, config.seed)
        verdict, place = None, None
        for place in places:
            verdict = check(world, GeoMove(move.entity, place), tools)
            if verdict.ok:
                break
        if verdict is None or not verdict.ok:
            failure = {"move": str(move), "failure": None if verdict is None else verdict.failure}
            why = f"{move}: no place of {len(places)} passes the full check"
            return _done(GeoStatus.BUDGET, (), why, stats, t0, 1, [failure])
        out.append(GeoMove(move.entity, place, verdict.grasp))
        world = moved(world, move.entity, place.pose)
    return _done(GeoStatus.SOLVED, out, "", stats, t0, 1, [])


def bridge_on(world: Scene, obj: str, target: str):
    """The place of ``obj`` centred on the top of object ``target`` in ``world``."""
    from tamp.geo.types import Place

    o, y = world.object(obj), world.object(target)
    xyz = (y.pose.xyz[0], y.pose.xyz[1], y.top + o.half[2])
    return Place(f"on.{y.name}", y.name, xyz, y.pose.yaw)
