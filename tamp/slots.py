"""The table as the planner's K base slots: a scene's places, each holding one tower.

Motion-aware planning (`tamp.arm.costs`) plans on the table the arm really has: every table
slot of the scene with room for a block (`tamp.scene.SceneConfig.slots`, not under a board too
low for one) is a capacity-one target named ``slot<k>`` (`task.domains.blocksworld.with_slots`),
so a plan never needs more free places than the table has and each move onto the table names
its place. A tower standing off every slot (nudged, or laid out elsewhere) keeps its own place,
named ``spot_<base>``, which other towers may use once it is empty. The observed state reads
each tower base's place from its observed pose, nothing else.

The loop stays on the plain problem: `tamp.scene.plain_move` turns a planned move onto a place
into a move onto the table that carries the place's name and position
(`tamp.scene.PlacedMove.at`: with continuous placements, the position its window decided),
where the executor puts the block (`tamp.scene.place_pose`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

from tamp.arm.arm import Arm
from tamp.arm.costs import ArmCosts
from tamp.scene import XY, Pose, SceneConfig, SceneError, layout, plain_move
from task.config import PlannerConfig
from task.domains.blocksworld import with_slots
from task.planner import plan
from task.problem import TABLE, Move, Plan, PlanResult, PlanStatus, Problem


def places(
    problem: Problem, state: Sequence[str], poses: Mapping[str, Pose], scene: SceneConfig
) -> tuple[dict[str, XY], dict[str, str]]:
    """The table places of the scene (name -> (x, y)) and the place of every tower base
    (block -> place name) in the observed ``state``, read from the ``poses``."""
    bases = [x for x, s in zip(problem.entities, state, strict=True) if s == TABLE]
    usable = {f"slot{k}": xy for k, xy in enumerate(scene.slots) if scene.capacity(xy) > 0}
    reach = _half_spacing(scene)
    out: dict[str, XY] = dict(usable)
    where: dict[str, str] = {}
    for base in bases:
        xy = (float(poses[base].xyz[0]), float(poses[base].xyz[1]))
        near = min(usable, key=lambda k: math.dist(usable[k], xy), default=None)
        if near is not None and near not in where.values() and math.dist(usable[near], xy) < reach:
            where[base] = near
        else:
            where[base] = f"spot_{base}"
            out[where[base]] = xy
    for name, xy in usable.items():  # a slot crowded by a tower standing off it is no place
        crowded = any(
            math.dist(xy, out[p]) < 2 * scene.slot_radius for p in where.values() if p != name
        )
        if crowded and name not in where.values():
            del out[name]
    return out, where


def _half_spacing(scene: SceneConfig) -> float:
    """Half the least distance between two slots (a base nearer than this is on the slot)."""
    slots = scene.slots
    gaps = [math.dist(a, b) for i, a in enumerate(slots) for b in slots[i + 1 :]]
    return min(gaps, default=1.0) / 2


def slotted(
    problem: Problem, state: Sequence[str], poses: Mapping[str, Pose], scene: SceneConfig
) -> tuple[Problem, dict[str, XY]]:
    """``problem`` in the observed ``state`` on the scene's table places (see `places`):
    the slotted problem and the position of each place."""
    at, where = places(problem, state, poses, scene)
    current = Problem(
        problem.name,
        problem.domain,
        problem.entities,
        tuple(state),
        problem.goal,
        data=problem.data,
    )
    return with_slots(current, tuple(at), where), at


def plan_on_places(
    problem: Problem,
    poses: Mapping[str, Pose],
    scene: SceneConfig,
    arm: Arm,
    config: PlannerConfig,
    seed: int = 0,
    reach: float = 0.0,
) -> PlanResult:
    """Motion-aware planning of ``problem`` (its ``init``: the observed state) on the scene's
    table places, the cost of each move for ``arm`` in the objective (`ArmCosts`; `Arm`: the
    moves it failed priced out, ``arm.grasps``: the grasp families the executor has besides
    top-down over the highest stack, ``arm.check``: the executor's check of a move among
    poses, with which the windows vet each move they keep where it starts, `ArmCosts.verify`);
    the plan's moves are plain (`plain_move`). ``reach`` > 0: continuous placements, each
    place's position optimised within ``reach`` m of its centre with the logits, per window
    and restart row: every move onto a place carries the position that the restart row it was
    decoded from decided in its window (`ArmCosts.decided`). A goal tower taller
    than the scene's ``max_height`` is UNSOLVABLE at once, its reason in ``stats["reason"]``
    (the prices rule out every such tower)."""
    tall = goal_height(problem)
    if tall > scene.max_height:  # no tower on this table takes it: say so, do not search
        why = (
            f"the goal stacks {tall} blocks in one tower; this scene's towers take at most "
            f"{scene.max_height} (SceneConfig.max_height)"
        )
        stats = {"reason": why, "time_s": 0.0, "windows": 0}
        return PlanResult(PlanStatus.UNSOLVABLE, Plan(()), problem, stats=stats)
    current, at = slotted(problem, problem.init, poses, scene)
    moved = room_goals(current, at, scene)
    if moved:  # a goal tower's base stands where the tower has no room: it moves first
        current = with_room(current, moved)
    costs = ArmCosts([current], [poses], scene, arm, places=[at], reach=reach)
    result = plan(current, config, seed=seed, costs=costs)
    decided = costs.decided(0)
    if [m for m, _ in decided] != list(result.plan.moves):  # the planner commits every move
        raise RuntimeError("the planner's moves differ from those committed to the cost source")
    stats = dict(result.stats)
    if reach == 0 and result.status is PlanStatus.SOLVED:  # each move onto a place's centre
        merged = _merge_runs(current, [m for m, _ in decided], costs)
        if len(merged) < len(decided):
            stats["merged_runs"] = len(decided) - len(merged)
            decided = [(m, at.get(m.target)) for m in merged]
    moves = tuple(plain_move(m, at, xy) for m, xy in decided)
    if moved:  # each moved base and the position of the place it was sent to
        stats["room_goals"] = {x: at[p] for x, p in moved.items()}
    return replace(result, plan=Plan(moves), stats=stats)


def _merge_runs(problem: Problem, moves: Sequence[Move], costs: ArmCosts) -> tuple:
    """``moves`` (a plan of the slotted ``problem`` from its initial state) with each run of one
    block's moves made one move where the same state follows and the arm's prices leave that
    move open where it is made (`task.symbolic.shorten.merge_runs` with the cost source's
    `task.planner.fallback.cost_checks`): the receding windows commit their moves one by one,
    and a block parked twice or three times in a row costs the arm a pick-and-place each
    time. The fallback search's plans are merged so already."""
    from task.domains import get_domain
    from task.planner.fallback import cost_checks
    from task.symbolic.shorten import merge_runs

    domain = get_domain(problem.domain)
    feasible, _ = cost_checks(domain, problem, costs, 0)
    return merge_runs(domain, problem, problem.init, moves, feasible)


def room_goals(problem: Problem, at: Mapping[str, XY], scene: SceneConfig) -> dict[str, str]:
    """The goal towers of the slotted ``problem`` (its ``init``: the observed state, on the
    places ``at``) whose base stands where the whole tower has no room (a slot under a board,
    `SceneConfig.capacity`), each with the place it is to stand on instead: base -> place.

    A Blocksworld goal names which block stands on which, rarely where a tower stands; the
    windows and the fallback price each move in the state it is made, so a tower grows under
    the board until its next block has no room, and only then must it come down again. Reading
    the room from the geometry, as a robot would, the base's place is chosen here instead: the
    places with room for the whole tower, not chosen for another tower nor holding a base that
    stays, the least covered first, then the nearest. A base stays where it may stay (its goal
    leaves its support free, or it is on the table already) and the tower has room (with the
    blocks below the base); a tower every place has room for is left to the planner, and so is
    a base with no place to go (the prices rule out every move onto a tower at its slot's
    capacity)."""
    goal = dict(problem.goal)
    support = dict(zip(problem.entities, problem.init, strict=True))
    above = {y: x for x, y in problem.goal if y in problem.entities}
    room = {p: scene.capacity(xy) for p, xy in at.items() if p in problem.fixed}

    def stand(x: str) -> tuple[str, int]:  # the place under x now and the blocks below x
        below = 0
        while support[x] in support:
            x, below = support[x], below + 1
        return support[x], below

    stands = {x: stand(x) for x in problem.entities}
    bases = [x for x in above if goal.get(x, TABLE) in (TABLE, *problem.fixed)]
    height = {x: _chain(x, above) for x in bases}  # the goal tower from each base up
    stays: set[str] = set()
    homeless = []
    for base in bases:
        place, below = stands[base]
        if goal.get(base) in problem.fixed:  # the goal names its place: the planner's to keep
            stays.add(goal[base])
        elif (base not in goal or below == 0) and room.get(place, 0) >= height[base] + below:
            stays.add(place)  # it may stay where it stands, and the tower has room there
        elif any(room[p] < height[base] for p in room):  # not every place takes the tower
            homeless.append(base)
    covered = {p: sum(at_place == p for at_place, _ in stands.values()) for p in room}
    out: dict[str, str] = {}
    for base in sorted(homeless, key=height.get, reverse=True):  # the tallest chooses first
        now = at[stands[base][0]]  # every tower stands on one of the places
        fits = [p for p in room if room[p] >= height[base] and p not in (*stays, *out.values())]
        if fits:
            out[base] = min(fits, key=lambda p: (covered[p], math.dist(at[p], now)))
    return out


def with_room(problem: Problem, moved: Mapping[str, str]) -> Problem:
    """``problem`` with each base of ``moved`` (`room_goals`) to stand on its place (the goal
    atom replaces any on the table). The table's places stay capacity-one slots a block never
    moves between directly (the loop's plain problem has one table): a clear base on a low
    slot goes to its place over another block."""
    goal = tuple((x, y) for x, y in problem.goal if x not in moved) + tuple(moved.items())
    return replace(problem, goal=goal)


def goal_height(problem: Problem) -> int:
    """Blocks in the tallest tower ``problem``'s goal names: its longest chain of blocks
    each on the next (1 when the goal puts no block on another)."""
    below = {x: y for x, y in problem.goal if y in problem.entities}
    return max((_chain(x, below) for x in problem.entities), default=1)


def _chain(x: str, step: Mapping[str, str]) -> int:
    """Blocks in the chain from ``x`` following ``step`` (the goal's block on x, or under it)
    until it ends or comes back to a block already counted (a cyclic goal)."""
    n, seen = 1, {x}
    while x in step and step[x] not in seen:
        x = step[x]
        n, seen = n + 1, seen | {x}
    return n


def fits(problem: Problem, scene: SceneConfig) -> bool:
    """Whether ``problem``'s initial towers can be laid out on ``scene`` (`tamp.scene.layout`:
    a slot each, one slot to spare, none taller than the arm can clear)."""
    try:
        layout(problem.entities, problem.init, scene, 0)
    except SceneError:
        return False
    return True
