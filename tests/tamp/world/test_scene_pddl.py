"""A scene read as the problem of a user's pick-and-place PDDL domain: the binding's ``scene``
section (its checks against the domain, its one-line errors), the problem written from the
geometry (the shipped tray scene in the example domain; Hanoi's canonical scene as its own
writer reads it), what cannot be written, and the plan the lift finds through it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tamp.world import load_named, parse_goal
from tamp.world.canonical import generate, hanoi_pddl
from tamp.world.scene_pddl import problem_text
from task.errors import ProblemError
from task.symbolic import pddl_io
from task.symbolic.pickplace import binding as binder
from task.symbolic.pickplace import hanoi
from task.symbolic.pickplace.binding import BindingError

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "domains"
TRAY_DOMAIN = (EXAMPLES / "tray.pddl").read_text()
TRAY_BINDING = json.loads((EXAMPLES / "tray.binding.json").read_text())
HANOI_SCENE = {
    "objects": "disc",
    "regions": "peg",
    "facts": {
        "on": "on",
        "in": "on",
        "clear": "clear",
        "empty": "clear",
        "narrower": "smaller",
        "fits": "smaller",
    },
}


def _bound(data: dict, domain_text: str = TRAY_DOMAIN):
    return binder.bind_text(json.dumps(data), pddl_io.parse_domain(domain_text, "d"))


def _with_scene(**scene) -> dict:
    return {**TRAY_BINDING, "scene": {**TRAY_BINDING["scene"], **scene}}


def _atoms(text: str, section: str) -> set[str]:
    """The atoms of a problem text's ``:init`` (one per line) or ``:goal`` section."""
    if section == "goal":
        body = text.split("(:goal (and ", 1)[1].rsplit(")))", 1)[0]
        return {f"({a.strip(' ()')})" for a in body.split(")") if a.strip(" ()")}
    lines = text.split("(:init", 1)[1].split("\n  )", 1)[0].splitlines()
    return {line.strip() for line in lines if line.strip()}


def test_the_tray_scene_reads_as_the_example_domain_s_state():
    scene = load_named("tray")
    goal = parse_goal("(and (in a tray) (on b a))", scene)
    text = problem_text(scene, goal, _bound(TRAY_BINDING))
    assert "(:objects a b c d - item tray - region)" in text
    # b stands on a, a and d on the table, c in the tray; the hand starts empty
    assert _atoms(text, "init") == {
        "(on b a)",
        "(ontable a)",
        "(ontable d)",
        "(in c tray)",
        "(clear b)",
        "(clear c)",
        "(clear d)",
        "(handempty)",
    }
    assert _atoms(text, "goal") == {"(in a tray)", "(on b a)"}


@pytest.mark.parametrize("seed", [0, 3])
def test_hanoi_through_the_generic_writer_is_hanoi_s_own_problem(seed):
    problem = generate("hanoi", seed)
    data = json.loads(hanoi.BINDING) | {"scene": HANOI_SCENE}
    generic = problem_text(problem.scene, problem.goal, _bound(data, hanoi.domain_text()))
    own = hanoi_pddl(problem)
    assert _atoms(generic, "init") == _atoms(own, "init")
    assert _atoms(generic, "goal") == _atoms(own, "goal")


def test_what_the_binding_does_not_write_is_refused_in_one_line():
    scene = load_named("tray")
    goal = parse_goal("(and (on b d))", scene)
    facts = {k: v for k, v in TRAY_BINDING["scene"]["facts"].items() if k != "in"}
    with pytest.raises(ProblemError, match="object c rests in tray, a relation the binding"):
        problem_text(scene, goal, _bound(_with_scene(facts=facts)))
    facts = {k: v for k, v in TRAY_BINDING["scene"]["facts"].items() if k != "on"}
    with pytest.raises(ProblemError, match="object b rests on a"):
        problem_text(scene, goal, _bound(_with_scene(facts=facts)))
    bare = {k: v for k, v in TRAY_BINDING.items() if k != "scene"}
    with pytest.raises(ProblemError, match="the binding has no scene section"):
        problem_text(scene, goal, _bound(bare))


@pytest.mark.parametrize(
    ("scene", "message"),
    [
        ({"facts": {"under": "on"}}, "unknown relation 'under'"),
        ({"facts": {"on": "sits"}}, "scene fact on: unknown predicate 'sits'"),
        ({"facts": {"clear": "on"}}, "(on) takes 2 argument(s), clear gives 1"),
        ({"objects": "widget"}, "scene objects: unknown type 'widget'"),
        ({"facts": {}}, "'facts' must map geometric relations"),
        ({"colour": "red"}, "scene: unknown key 'colour'"),
        ({"regions": 3}, "regions must be a PDDL type name"),
    ],
)
def test_a_bad_scene_section_is_a_one_line_error(scene, message):
    with pytest.raises(BindingError, match=None) as caught:
        _bound(_with_scene(**scene))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_the_lift_plans_the_tray_problem_and_the_binding_pairs_its_moves():
    from dataclasses import replace

    from task.config import PlannerConfig
    from task.domains.strips import problem_from_text
    from task.planner import plan
    from task.problem import Move

    scene = load_named("tray")
    bound = _bound(TRAY_BINDING)
    text = problem_text(scene, parse_goal("(and (in a tray) (on b a))", scene), bound)
    config = replace(PlannerConfig.for_domain("strips"), fallback=True, time_limit_s=60)
    result = plan(problem_from_text(TRAY_DOMAIN, text, "tray"), config)
    assert result.solved
    moves = binder.to_moves(bound, result.plan.moves)
    assert len(moves) == 3 and moves[-2:] == (Move("a", "tray"), Move("b", "a"))
