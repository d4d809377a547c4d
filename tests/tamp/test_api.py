"""`tamp.api`, the entry layer: plans come back validated (the planner alone leaves
``validation`` None), every problem input (PDDL text, a file, a `Problem`, a `PddlTask`) gives
the same plan, plans from any source are validated, cost sources steer the planner, and bad
input is one line before any work. The simulated paths (episodes, given plans, scenes, images)
run in tests/test_examples.py."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

from tamp import api
from task.config import PlannerConfig
from task.domains import get_domain
from task.errors import PDDLError, TampError
from task.planner import plan as soft_plan

SMALL = api.Problem(
    "small", "blocksworld", ("a", "b", "c"), ("table", "a", "table"), (("a", "b"), ("b", "c"))
)
FAST = PlannerConfig(restarts=4, iters=30)
SMALL_PDDL = get_domain("blocksworld").to_pddl(SMALL)
WIDE = api.Problem("wide", "blocksworld", tuple("abcdefghij"), ("table",) * 10, (("a", "b"),))
LIGHTS = """(define (domain lights) (:requirements :strips)
  (:predicates (on ?x) (off ?x))
  (:action switch :parameters (?x) :precondition (off ?x) :effect (and (on ?x) (not (off ?x)))))"""


def test_a_plan_comes_back_validated_where_the_planner_leaves_it_none():
    assert soft_plan(SMALL, FAST).validation is None
    planned = api.plan(SMALL, config=FAST)
    assert planned.valid and planned.validation.status is api.ValidationStatus.VALID
    assert planned.validation.length == len(planned.actions) == 2 * len(planned.moves)
    assert api.validate(SMALL, planned.text()).valid  # the plan file round-trips


def test_every_problem_input_gives_the_same_plan(tmp_path):
    domain, problem = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    domain.write_text(api.BLOCKSWORLD)
    problem.write_text(SMALL_PDDL)
    task = api.load_problem(SMALL_PDDL)
    plans = {
        api.plan(source, config=FAST).text()
        for source in (task, task.problem, SMALL, SMALL_PDDL, problem)
    }
    plans.add(api.plan(problem, domain, config=FAST).text())
    assert len(plans) == 1
    assert task.problem.entities == SMALL.entities and task.instance.optimal is None


def test_an_unfinished_plan_validates_as_not_reaching_the_goal():
    stuck = PlannerConfig(max_windows=1, horizon=1, lookahead_share=0.0, restarts=2, iters=5)
    planned = api.plan(api.EXAMPLE, config=stuck)
    assert planned.status is api.PlanStatus.NO_PLAN
    assert planned.validation.status is api.ValidationStatus.NON_GOAL_REACHING
    assert not planned.valid


def test_plans_from_any_source_are_validated(tmp_path):
    bad = [api.Action("unstack", ("a", "b")), api.Action("stack", ("a", "c"))]
    moves = [api.Move("b", "c"), api.Move("a", "b")]
    path = tmp_path / "moves.plan"
    path.write_text("move(b -> c)\nmove(a -> b)\n")
    assert api.validate(SMALL, moves).valid and api.validate(SMALL, path).valid
    verdict = api.validate(SMALL, bad)
    assert verdict.status is api.ValidationStatus.INEXECUTABLE and verdict.step == 1
    assert "(on a b)" in verdict.reason


def test_a_cost_function_steers_the_plan_among_equally_short_ones():
    """a sits on b and must go first, to the table or onto d: pricing the table steers it."""
    problem = api.Problem(
        "unstack",
        "blocksworld",
        ("a", "b", "c", "d"),
        ("b", "table", "table", "table"),
        (("b", "c"),),
    )

    def pricing(expensive: int):
        def price(p: api.Problem, state) -> torch.Tensor:
            costs = torch.ones(p.n, p.n + 1)  # (N, Y): targets a, b, c, d, table
            costs[0, expensive] = 3.0  # a onto the expensive target
            return costs

        return price

    for expensive, other in ((4, "d"), (3, "table")):
        source = api.CostFunction(pricing(expensive), (problem,))
        window = source([0], [get_domain("blocksworld").initial_state(problem)], 16)
        assert window.compute().shape == (1, 4, 5) and window.parameters() == []
        planned = api.plan(problem, costs=source)
        assert planned.valid and planned.moves[0] == api.Move("a", other)


def test_domain_rules_are_recognised_from_the_pddl():
    assert api.domain_rules(api.BLOCKSWORLD) == "blocksworld"
    assert api.domain_rules(LIGHTS) == "strips"
    assert api.domain_names() == ("blocksworld", "logistics", "sokoban", "strips")


def test_the_generic_lift_plans_a_problem_given_as_a_problem():
    task = api.load_problem(SMALL_PDDL, rules="strips")
    assert task.problem.domain == "strips"
    planned = api.plan(task.problem, config=PlannerConfig.for_domain("strips"))
    assert planned.valid


def test_a_shipped_scene_loads_by_name():
    scene = api.load_scene("tower")
    assert [o.name for o in scene.objects] == ["a", "b", "c"]


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: api.load_problem("problem.pddl"), "not PDDL text"),
        (lambda: api.load_problem(42), "problem must be PDDL text (str) or a PDDL file"),
        (lambda: api.load_problem(Path("/nonexistent/p.pddl")), "/nonexistent/p.pddl"),
        (lambda: api.load_problem(api.EXAMPLE, rules="towers"), "valid: blocksworld"),
        (lambda: api.validate(SMALL, "(fly a)"), "fly"),
        (lambda: api.plan_images("a.png", "b.png", scene="lego"), "valid: cubes, latplan"),
        (
            lambda: api.run(next(get_domain("logistics").samples(0))),
            "executes blocksworld problems only",
        ),
        (lambda: api.execute_plan(next(get_domain("sokoban").samples(0)), ""), "blocksworld"),
    ],
)
def test_bad_input_is_one_line(call, words):
    with pytest.raises(TampError) as caught:
        call()
    message = str(caught.value)
    assert words in message and "\n" not in message


def test_text_that_is_no_pddl_says_how_to_pass_a_file():
    with pytest.raises(PDDLError, match=r"pathlib\.Path"):
        api.plan("examples/problem.pddl")


# the api functions that wrap a benchmark; nothing else in the entry layer imports tamp.bench
BENCHMARK_WRAPPERS = {"random_suite", "folder_suite", "planbench_suite", "benchmark"}
BENCHMARK_WRAPPERS |= {"benchmark_motion"}


def test_only_the_benchmark_wrappers_import_tamp_bench():
    """The library's defaults live in its components' configs (the geometric episode's limits:
    `tamp.geo.types.GeoLimits`), never in a benchmark: outside the functions that wrap one,
    `tamp.api` (every module of the package) imports nothing from ``tamp.bench`` (type hints
    aside)."""
    import ast

    found = set()
    for path in sorted(Path(api.__file__).parent.glob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in tree.body:
            top_level = isinstance(node, ast.Import | ast.ImportFrom)
            if top_level:  # a module-level import of tamp.bench would load it with tamp.api
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
                module = node.module if isinstance(node, ast.ImportFrom) else None
                assert not any(n.startswith("tamp.bench") for n in [*names, module or ""]), path
        for fn in (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)):
            for node in ast.walk(fn):
                if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                    "tamp.bench"
                ):
                    found.add(fn.name)
    assert found and found <= BENCHMARK_WRAPPERS, sorted(found - BENCHMARK_WRAPPERS)


def test_importing_the_api_loads_no_benchmark():
    import subprocess
    import sys

    code = "import sys, tamp.api; print(sorted(m for m in sys.modules if m.startswith('tamp.b')))"
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        cwd=Path(__file__).parents[2],
    )
    assert out.stdout.strip() == "[]"


TASK = api.load_problem(SMALL_PDDL)


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: api.plan(TASK, seed="0"), "api.plan: seed must be an int, got '0' (str)"),
        (lambda: api.plan(TASK, seed=1.5), "api.plan: seed must be an int, got 1.5 (float)"),
        (
            lambda: api.plan(TASK, config={"horizon": 3}),
            "api.plan: config must be a task.config.PlannerConfig or None, got {'horizon': 3}",
        ),
        (lambda: api.validate(TASK, 5), "api.validate: plan must be plan text (str), a plan file"),
        (
            lambda: api.run(TASK, config=api.PlannerConfig()),
            "api.run: config must be a tamp.loop.LoopConfig or a tamp.geo.config.GeoEpisodeConfig "
            "or None, got PlannerConfig(",
        ),
        (lambda: api.load_scene({"schema": 1}), "scene: name: missing (required: name, schema"),
        (lambda: api.load_scene(3.0), "api.load_scene: scene must be a scene file"),
        (
            lambda: api.run("tower", 5),
            "api.run: goal must be a PDDL goal (str) or a goal file (pathlib.Path) or None, got 5",
        ),
        (
            lambda: api.benchmark(api.random_suite((3,), 1), seeds=()),
            "api.benchmark: seeds must be a non-empty list or tuple of ints, got () (tuple)",
        ),
        (
            lambda: api.benchmark(SMALL),
            "api.benchmark: suite must be a tamp.bench.suites.Suite (api.random_suite, ...)",
        ),
        (
            lambda: api.plan(TASK, costs=api.FixedCosts(torch.zeros(1, 3, 4))),
            "api.plan: costs must be a CostSource: a callable (indices, states, restarts)",
        ),
        (lambda: api.plan(TASK, sed=1), "api.plan: got an unexpected keyword argument 'sed'"),
        (lambda: api.random_suite(3), "api.random_suite: blocks must be a non-empty list"),
        (
            lambda: api.execute_plan(TASK, "", replan="yes"),
            "api.execute_plan: replan must be a bool",
        ),
    ],
)
def test_arguments_of_the_wrong_kind_are_one_line_naming_them(call, words, monkeypatch):
    """Every public function checks its arguments' kinds at the edge (`tamp.api.args`): one
    line naming the function, the argument, what was given and what is expected, never a
    Python error from inside (manual_seed, 'dict' has no attribute, not iterable)."""
    import tamp.bench.planning
    import task.planner

    def no_work(*args, **kw):
        raise AssertionError("worked before checking the arguments")

    monkeypatch.setattr(task.planner, "plan", no_work)
    monkeypatch.setattr(tamp.bench.planning, "run", no_work)
    with pytest.raises(TampError) as caught:
        call()
    message = str(caught.value)
    assert words in message and "\n" not in message


def test_a_plan_given_as_step_strings_is_validated_as_a_plan():
    steps = ["(unstack b a)", "(stack b c)", "(pick-up a)", "(stack a b)"]
    planned = api.validate(SMALL, steps)
    assert planned.valid and planned.length == 4
    assert not api.validate(SMALL, steps[1:]).valid
    assert api.validate(SMALL, ["move(b -> c)", api.Move("a", "b")]).valid


def test_an_unknown_scene_name_lists_the_shipped_scenes():
    with pytest.raises(TampError) as caught:
        api.load_scene("towerz")
    assert "towerz: no such scene file, nor a shipped scene 'towerz' (valid: " in str(caught.value)
    assert "tower, tray" in str(caught.value)
    assert [o.name for o in api.load_scene({**_tower_dict()}).objects] == ["a", "b", "c"]


def _tower_dict() -> dict:
    import json

    from tamp.world.load import SCENES_DIR

    return json.loads((SCENES_DIR / "tower.json").read_text())


def test_one_entry_runs_every_kind_of_episode_and_the_old_entries_are_gone():
    assert "run" in api.__all__
    for old in ("run_episode", "run_scene", "run_geometric"):
        assert not hasattr(api, old) and old not in api.__all__


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: api.run(api.EXAMPLE, "(on a b)"), "goal is for a scene file"),
        (lambda: api.run("shelf", "(on a b)"), "a workcell has its own goal"),
        (  # with the geometric episode's config: laid out, but no room for its towers
            lambda: api.run(WIDE, config=_geo_config()),
            "10 towers leave no free table slot",
        ),
        (
            lambda: api.run("tray", "(in a tray)", config=_loop_config()),
            "runs as a geometric episode",
        ),
        (  # a loaded Scene is a scene: the same routing, before any work
            lambda: api.run(api.load_scene("tray"), "(in a tray)", config=_loop_config()),
            "tray runs as a geometric episode",
        ),
        (lambda: api.run("tray", "(in a tray)", domain=Path("d.pddl")), "go together"),
    ],
)
def test_run_refuses_what_does_not_fit_the_episode_in_one_line(call, words):
    with pytest.raises(TampError) as caught:
        call()
    assert words in str(caught.value) and "\n" not in str(caught.value), caught.value


def _geo_config():
    from tamp.geo.config import GeoEpisodeConfig

    return GeoEpisodeConfig()


def _loop_config():
    from tamp.loop import LoopConfig

    return LoopConfig()
