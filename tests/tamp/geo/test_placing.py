"""Moves into position taken without a window (`tamp.geo.ours.placing`): which moves count, the
order the prices give them, and the motion-aware planner taking them only before its first
window (a tower is built without one; objects a window moved out of an alcove are not put
back before the target goes in)."""

from __future__ import annotations

from dataclasses import replace

from tamp.geo.ours import as_ours, plan_motion_aware
from tamp.geo.ours.placing import next_placing, placing_moves
from tamp.geo.search import SearchConfig
from tamp.geo.types import GeoStatus, moved
from tamp.world.relations import read_facts
from task.costs import IMPOSSIBLE
from task.domains.blocksworld import HOP
from task.problem import TABLE, Move, Problem
from tests.tamp.geo.geo_scenes import tools


def _problem(init, goal) -> Problem:
    """Blocks a-d on capacity-one places p0-p3 and cells c0, c1."""
    places = ("p0", "p1", "p2", "p3", "c0", "c1")
    entities = ("a", "b", "c", "d")
    return Problem("placing", "blocksworld", entities, tuple(init), tuple(goal), places, HOP)


def test_only_goal_objects_go_onto_the_target_their_goal_names():
    # a, b, c on p0-p2, d on c: goal tower a on c1, b on a; c into c0; d free
    p = _problem(("p0", "p1", "p2", "c"), (("a", "c1"), ("b", "a"), ("c", "c0")))
    # a onto its free cell; c is covered by d: not clear; b's goal block a is not in position
    assert placing_moves(p, p.init) == [Move("a", "c1")]
    state = ("c1", "p1", "p2", "c")
    assert placing_moves(p, state) == [Move("b", "a")]  # a in position and clear now
    # a goal cell something stands on is not free; a goal "on any place" names no target
    taken = _problem(("p0", "c1", "d", "p3"), (("a", "c1"), ("c", TABLE)))
    assert placing_moves(taken, taken.init) == []


class _Prices:
    """Prices and cell closings of a fake `GeoCosts`."""

    def __init__(self, prices: dict, closes: dict) -> None:
        self.prices, self._closes = prices, closes

    def price_of(self, state, move) -> float:
        return self.prices[move]

    def closes(self, state) -> dict:
        return self._closes


def test_the_move_closing_fewest_cells_goes_first_then_the_cheapest_and_never_a_priced_out_one():
    p = _problem(("p0", "p1", "p2", "p3"), (("a", "c0"), ("b", "c1"), ("c", "p2")))
    both = {Move("a", "c0"): 1.0, Move("b", "c1"): 2.0}
    # c1 closes nothing, c0 closes c1 (c0's body is in c1's hand room): b first, though dearer
    assert next_placing(p, p.init, _Prices(both, {"c0": 1, "c1": 0})) == Move("b", "c1")
    assert next_placing(p, p.init, _Prices(both, {})) == Move("a", "c0")  # then the cheapest
    out = {Move("a", "c0"): float(IMPOSSIBLE), Move("b", "c1"): float(IMPOSSIBLE)}
    assert next_placing(p, p.init, _Prices(out, {})) is None


def _config(k: int, placing: bool = True):
    return replace(as_ours(SearchConfig(seed=k, max_time_s=60.0)), placing=placing)


def test_a_tall_tower_is_built_without_a_window_every_move_bound_by_the_full_check():
    from tamp.world.canonical import generate

    made = generate("tall", 0)  # ten cubes on the table into one tower at the edge of reach
    result = plan_motion_aware(made.scene, made.goal, tools(), _config(0))
    assert result.status is GeoStatus.SOLVED, result.reason
    assert result.stats["placing_moves"] == len(result.moves) == 10
    assert result.stats["plans"] == 0 and "windows" not in result.stats  # no window ran
    assert all(m.grasp is not None for m in result.moves)
    world = made.scene
    for m in result.moves:
        world = moved(world, m.obj, m.place.pose)
    assert made.goal.holds(read_facts(world))


def test_objects_moved_out_of_an_alcove_are_not_put_back_before_the_target_goes_in():
    from tamp.world.canonical import generate

    # the target at the back of the alcove has no open move at the start and the others are
    # in position: no placing move, the windows plan it all. Placing moves taken after a
    # window would put f1 and f2 straight back where the window took them from (11 moves)
    made = generate("nonmonotonic", 0)
    result = plan_motion_aware(made.scene, made.goal, tools(), _config(0))
    assert result.status is GeoStatus.SOLVED, result.reason
    assert result.stats["placing_moves"] == 0 and result.stats["plans"] >= 1
    assert len(result.moves) == 6
