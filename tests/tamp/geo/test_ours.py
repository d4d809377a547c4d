"""Motion-aware planning of scene-file problems (`tamp.geo.ours.plan_motion_aware`): a
hemmed-in target is reached by moving a neighbour first, the canonical packed boxes go into a
tray that holds them only when packed (the sampled packer's cells fail at the same budget), a
move the full check refuses is fed back and planned around, and UNSOLVABLE means the
planner's fallback proved it within the discretised places."""

from __future__ import annotations

import itertools
from dataclasses import replace

from tamp.geo.check import MoveCheck
from tamp.geo.ours import PLANNER, OursConfig, as_ours, plan_motion_aware
from tamp.geo.ours.bridge import PACK
from tamp.geo.ours.pack import pack_sampled
from tamp.geo.search import SearchConfig
from tamp.geo.types import GeoStatus, moved
from tamp.outcome import Failure
from tamp.world.geometry import of_movable, penetration
from tamp.world.goal import parse_goal
from tamp.world.relations import read_facts
from tests.tamp.geo.geo_scenes import blocked, cube, scene, tools


def _replay(world, moves):
    for m in moves:
        world = moved(world, m.obj, m.place.pose)
    return world


def _no_overlap(world) -> bool:
    solids = [of_movable(o) for o in world.objects]
    return all(penetration(u, v) == 0 for i, u in enumerate(solids) for v in solids[i + 1 :])


def test_a_hemmed_in_target_is_reached_by_moving_a_neighbour_first():
    s = blocked()
    goal = parse_goal("(in t goal)", s)
    result = plan_motion_aware(s, goal, tools())
    assert result.status is GeoStatus.SOLVED, result.reason
    assert len(result.moves) >= 2 and result.moves[-1].obj == "t"
    assert result.moves[0].obj in {"n", "w", "e"}  # a neighbour first
    assert all(m.grasp is not None for m in result.moves)  # each bound by the full check
    end = _replay(s, result.moves)
    assert goal.holds(read_facts(end)) and _no_overlap(end)
    assert result.stats["ms_per_state"] > 0 and result.stats["failures"] == []


def test_the_canonical_packed_boxes_go_into_the_tray_the_sampled_packer_cannot_fill():
    from tamp.world.canonical import generate

    made = generate("packed", 1)  # five boxes that fit only in two columns with a finger lane
    s, goal = made.scene, made.goal
    result = plan_motion_aware(s, goal, tools())
    assert result.status is GeoStatus.SOLVED, result.reason
    assert len(result.moves) == 5 and {m.place.target for m in result.moves} == {"tray"}
    assert all(m.grasp is not None for m in result.moves)
    end = _replay(s, result.moves)
    assert goal.holds(read_facts(end)) and _no_overlap(end)
    # the sampled packer, at the gradient packer's budget (R rows x steps), finds no cells
    budget = PACK.restarts * PACK.steps
    half = [s.object(a[1]).half[:2] for a in goal.atoms]
    inner = s.region("tray").inner()
    sampled = pack_sampled(inner, half, budget=budget, seed=0, config=PACK, walled=False)
    assert not sampled.ok
    print(
        f"packed: gradient {result.stats['packs']['tray']}, sampled ok={sampled.ok} "
        f"in {sampled.time:.3f} s ({sampled.tries} samples); plan {result.stats['time_s']:.1f} s"
    )


def test_packed_variant_3_is_planned_in_the_packers_order_and_no_object_moves_twice_in_a_row():
    """Packed variant 3 (six boxes, two columns with a finger lane): the packer's placing order
    is one the arm's prices allow move by move (it closed the fingers across a side no grasp
    closes across, and no order of its cells was open to the planner: no plan in 120 s), and
    the plan has no object moved twice in a row (a window parks it, the next moves it on)."""
    from tamp.geo.ours.bridge import bridge
    from tamp.geo.ours.costs import GeoCosts
    from tamp.world.canonical import generate
    from task.costs import IMPOSSIBLE
    from task.domains.blocksworld import apply_move
    from task.problem import Move

    made = generate("packed", 3)
    config = as_ours(SearchConfig(seed=1))
    b = bridge(made.scene, made.goal, config.table_places, config.pack, config.seed)
    ((_, packed),) = b.packs
    assert packed.ok
    costs = GeoCosts(b, tools().solver, tools().q, config.costs, pack=config.pack)
    state = b.problem.init
    for k in packed.order:
        move = Move(*b.cells[k])
        assert costs.price_of(state, move) < IMPOSSIBLE, move
        state = apply_move(b.problem, state, move)
    result = plan_motion_aware(made.scene, made.goal, tools(), config)
    assert result.status is GeoStatus.SOLVED, result.reason
    assert goal_holds(made, result.moves)
    objects = [m.obj for m in result.moves]
    assert all(a != b for a, b in itertools.pairwise(objects)), objects


def goal_holds(made, moves) -> bool:
    end = _replay(made.scene, moves)
    return made.goal.holds(read_facts(end)) and _no_overlap(end)


class _Refuse:
    """A move check that refuses the first ``n`` moves it sees, then passes everything."""

    def __init__(self, n: int) -> None:
        self.n, self.seen = n, []

    def __call__(self, world, move, tools, grasps=(), quick=None):
        self.seen.append((move.obj, move.place.name))
        if len(self.seen) <= self.n:
            return MoveCheck(ok=False, failure=Failure.COLLISION, evidence={"fake": True})
        return MoveCheck(ok=True, grasp=grasps[0] if grasps else None)


# the differentiable planner's attempt alone (no complete search after it)
FAST = OursConfig(
    planner=replace(PLANNER, max_windows=4, restarts=4, iters=30), replans=2, search=None
)


def test_a_move_the_full_check_refuses_is_planned_around_and_the_replans_are_bounded():
    s = scene(cube("a", 0.45, 0.2), cube("b", 0.55, 0.2))
    goal = parse_goal("(in a goal)", s)
    once = _Refuse(1)
    # a's move into its goal cell is the opening placing move (`tamp.geo.ours.placing`); the
    # check refuses it, and the windows plan around it, not that move there again
    result = plan_motion_aware(s, goal, None, FAST, check=once)
    assert result.status is GeoStatus.SOLVED and result.stats["plans"] == 1
    assert once.seen[0] == ("a", "goal.c0") and result.stats["placing_moves"] == 0
    (failed,) = result.stats["failures"]
    assert (result.moves[0].obj, result.moves[0].place.name) != once.seen[0]  # not that again
    assert failed["place"] == once.seen[0][1]
    always = _Refuse(10**6)
    result = plan_motion_aware(s, goal, None, FAST, check=always)
    assert result.status is GeoStatus.BUDGET and "replan budget" in result.reason
    assert len(result.stats["failures"]) == FAST.replans + 1
    assert len(set(always.seen)) == len(always.seen)  # each failure ruled out where it failed


def test_unsolvable_only_when_the_fallback_proves_it_within_the_places():
    posts = [
        {"name": f"post{i}", "centre": [0.5 + dx, dy, 0.04], "half": [hx, hy, 0.04]}
        for i, (dx, dy, hx, hy) in enumerate(
            [
                (0.045, 0.0, 0.01, 0.05),
                (-0.045, 0.0, 0.01, 0.05),
                (0.0, 0.045, 0.03, 0.01),
                (0.0, -0.045, 0.03, 0.01),
            ]
        )
    ]
    s = scene(cube("t", 0.5, 0.0), obstacles=posts)
    goal = parse_goal("(in t goal)", s)
    result = plan_motion_aware(s, goal, None, FAST, check=_Refuse(10**6))
    assert result.status is GeoStatus.UNSOLVABLE
    assert result.reason.startswith("within the discretised places: no plan exists")
    assert result.stats["fallback"]["status"] == "unsolvable"


def test_when_the_first_attempt_gives_up_the_complete_search_goes_on_from_its_moves():
    s = scene(cube("a", 0.45, 0.2), cube("b", 0.55, 0.2))
    goal = parse_goal("(in a goal)", s)
    # the first attempt's check refuses everything (its replans run out); the complete
    # search's own full check finds the move
    config = replace(FAST, search=SearchConfig(max_time_s=60.0))
    result = plan_motion_aware(s, goal, tools(), config, check=_Refuse(10**6))
    assert result.status is GeoStatus.SOLVED, result.reason
    assert result.stats["first"]["status"] == "budget" and "search" in result.stats
    assert goal.holds(read_facts(_replay(s, result.moves)))


def test_unsolvable_from_the_complete_search_is_said_with_the_first_attempts_reason():
    posts = [
        {"name": f"post{i}", "centre": [0.5 + dx, dy, 0.04], "half": [hx, hy, 0.04]}
        for i, (dx, dy, hx, hy) in enumerate(
            [(0.045, 0.0, 0.01, 0.05), (-0.045, 0.0, 0.01, 0.05), (0.0, 0.045, 0.03, 0.01)]
        )
    ]
    posts.append({"name": "post3", "centre": [0.5, -0.045, 0.04], "half": [0.03, 0.01, 0.04]})
    s = scene(cube("t", 0.5, 0.0), obstacles=posts)
    goal = parse_goal("(in t goal)", s)
    config = replace(FAST, search=SearchConfig(max_time_s=60.0))
    result = plan_motion_aware(s, goal, tools(), config)
    assert result.status is GeoStatus.UNSOLVABLE, result.reason
    assert "after the differentiable planner" in result.reason
    assert result.stats["first"]["status"] == "unsolvable"


def test_the_episode_planners_shared_config_is_accepted():
    ours = as_ours(SearchConfig(max_time_s=30.0, seed=3, choices=("top",)))
    assert ours.seed == 3 and ours.costs.choices == ("top",)
    # a third of the wall clock for the differentiable planner, the complete search the rest
    assert ours.planner.time_limit_s == 10.0 and ours.soft_time_s == 10.0
    assert ours.search.max_time_s == 30.0 and ours.search.max_nodes == 5_000
    assert ours.planner.fallback is True


def _hanoi(check, n: int = 3):
    from tamp.world.canonical import generate
    from task.symbolic.pickplace import hanoi

    made = generate("hanoi", 0, n=n)
    domain = (hanoi.domain_text(), hanoi.BINDING)
    one = OursConfig(planner=replace(PLANNER, max_windows=1))  # then the lift's fallback
    return made, plan_motion_aware(made.scene, made.goal, None, one, check, domain=domain)


def test_hanoi_is_planned_through_its_pddl_domain_and_mapped_to_moves_onto_discs_and_pegs():
    made, result = _hanoi(_Refuse(0), n=3)
    assert result.status is GeoStatus.SOLVED, result.reason
    assert len(result.moves) >= 7  # the optimum is 2^3 - 1
    world, pegs = made.scene, {r.name for r in made.scene.regions}
    for m in result.moves:
        target = m.place.target
        if target not in pegs:  # onto a disc: a wider one
            assert 2 * world.object(target).half[0] > 2 * world.object(m.obj).half[0]
        world = moved(world, m.obj, m.place.pose)
    facts = read_facts(world)
    assert made.goal.holds(facts) and not facts.unexplained and _no_overlap(world)


def test_the_sampled_ablation_places_cells_by_rejection_sampling_and_says_when_none_fit():
    """``motion-aware-sampled`` bridges with `pack_sampled` at the packer's budget: on a roomy
    region it plans as ours does; on the tight tray of packed variant 1 no sampled arrangement
    is free, and the planner says so (its complete search may still go on)."""
    from tamp.geo.episode import planner_by_name
    from tamp.geo.ours.bridge import bridge
    from tamp.world.canonical import generate

    s = scene(cube("a", 0.45, 0.2), cube("b", 0.55, 0.2))
    goal = parse_goal("(on a b)", s)
    plan = planner_by_name("motion-aware-sampled")
    result = plan(s, goal, tools(), SearchConfig(seed=0, max_time_s=60))
    assert result.status is GeoStatus.SOLVED, result.reason
    made = generate("packed", 1)
    gradient = bridge(made.scene, made.goal, sampler="gradient")
    sampled = bridge(made.scene, made.goal, sampler="sampled")
    assert [p.ok for _, p in gradient.packs] == [True]
    assert [p.ok for _, p in sampled.packs] == [False]
    assert sampled.packs[0][1].tries > 0
    first = as_ours(SearchConfig(seed=0, max_time_s=5))
    only = replace(first, sampler="sampled", search=None)
    said = plan_motion_aware(made.scene, made.goal, tools(), only)
    assert not said.solved and "no free arrangement" in said.reason


def test_a_hanoi_scene_that_is_no_state_of_its_domain_ends_planning_in_one_line():
    """A disc that slid off the pegs onto the bare table: Tower of Hanoi has no such state, so
    planning through its PDDL domain fails with that reason instead of raising (which ended a
    whole benchmark run)."""
    from tamp.scene import Pose
    from tamp.world.canonical import generate

    made = generate("hanoi", 0)
    off = moved(made.scene, "d1", Pose((0.35, 0.35, 0.012)))
    result = plan_motion_aware(off, made.goal, tools(), domain=made.domain)
    assert result.status is GeoStatus.FAILED and not result.moves
    assert "no state of the PDDL domain" in result.reason and "d1" in result.reason
    assert "\n" not in result.reason


def test_as_ours_takes_the_shared_search_config_and_refuses_anything_else():
    """`as_ours` reads a `SearchConfig`'s seed, grasp families and wall clock directly, and
    a config of neither kind is one line naming the two valid kinds, not silent defaults."""
    import pytest

    from tamp.geo.ours.planner import SOFT_SHARE
    from task.errors import TampError

    config = as_ours(SearchConfig(seed=3, choices=("top",), max_time_s=30.0))
    assert config.seed == 3 and config.costs.choices == ("top",)
    assert config.soft_time_s == pytest.approx(30.0 / SOFT_SHARE)
    with pytest.raises(TampError, match="valid: OursConfig or SearchConfig"):
        as_ours({"seed": 3})
