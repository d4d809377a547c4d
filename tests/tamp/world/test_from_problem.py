"""A Blocksworld problem laid out as a scene (`tamp.world.convert.from_problem`): the facts
read from its geometry are the problem's initial state, on every named workcell, as the loop
lays it out."""

from __future__ import annotations

import pytest

from tamp.obstacles import SCENES
from tamp.scene import SceneConfig, layout
from tamp.world import load_named, read_facts, scene_config
from tamp.world.convert.from_problem import problem_scene
from task.errors import TampError
from task.problem import TABLE, Problem
from task.symbolic.generate import random_problem


def support_facts(problem: Problem) -> frozenset:
    """The problem's initial state as on / ontable / clear atoms."""
    atoms = {
        ("ontable", x) if s == TABLE else ("on", x, s)
        for x, s in zip(problem.entities, problem.init, strict=True)
    }
    atoms |= {("clear", x) for x in problem.entities if x not in problem.init}
    return frozenset(atoms)


@pytest.mark.parametrize("workcell", sorted(SCENES))
@pytest.mark.parametrize("seed", [0, 1, 2, 3])
@pytest.mark.parametrize("blocks", [3, 5])
def test_the_scene_reads_as_the_problems_initial_state(workcell, seed, blocks):
    problem = random_problem(blocks, seed)
    laid = problem_scene(problem, workcell, seed)
    facts = read_facts(laid.scene)
    assert not facts.unexplained, facts.issues
    assert facts.atoms == support_facts(problem)
    assert dict(facts.supports) == dict(zip(problem.entities, problem.init, strict=True))


@pytest.mark.parametrize("workcell", sorted(SCENES))
def test_the_blocks_stand_where_the_loop_puts_them_among_the_workcells_obstacles(workcell):
    """Same slots, jitter and seed as `tamp.loop.Episode`'s layout; the workcell's obstacles."""
    problem = random_problem(4, 7)
    laid = problem_scene(problem, workcell, 7)
    config = scene_config(load_named(workcell), SceneConfig())
    poses = layout(problem.entities, problem.init, config, 7)
    assert {o.name: o.pose for o in laid.scene.objects} == poses
    assert all(o.kind == "cube" and o.size == (config.block_size,) for o in laid.scene.objects)
    assert laid.scene.obstacles == SCENES[workcell]
    assert laid.scene.name == problem.name


def test_the_goal_becomes_on_and_ontable_atoms():
    problem = Problem(
        "p", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("c", TABLE))
    )
    laid = problem_scene(problem)
    assert laid.goal.atoms == (("on", "a", "c"), ("ontable", "c"))
    assert not laid.goal.holds(read_facts(laid.scene))


def test_another_seed_lays_the_problem_out_elsewhere():
    problem = random_problem(4, 0)
    one, two = problem_scene(problem, seed=0), problem_scene(problem, seed=1)
    assert one.scene.objects != two.scene.objects
    assert read_facts(one.scene).atoms == read_facts(two.scene).atoms


def test_what_cannot_be_laid_out_is_one_line():
    towers = Problem("wide", "blocksworld", tuple("abcdefg"), (TABLE,) * 7, (("a", "b"),))
    with pytest.raises(TampError, match="7 towers leave no free table slot") as err:
        problem_scene(towers, "cramped")
    assert "\n" not in str(err.value)
    with pytest.raises(TampError, match="unknown scene 'attic'"):
        problem_scene(random_problem(3, 0), "attic")
    other = Problem("l", "logistics", ("a",), (TABLE,), (("a", TABLE),))
    with pytest.raises(TampError, match="this is a logistics problem"):
        problem_scene(other)
