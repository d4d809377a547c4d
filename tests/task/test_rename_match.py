"""Renamed domains plan as their originals: the structural match (`task.domains.match`).

Each hand-written domain's PDDL file is renamed at random (`match.rename`: predicates,
actions, types, variables and objects renamed, parameter and argument orders and declarations
shuffled); the renamed domain must be recognised as the original with the true renaming, its
problems must plan to the original's plan mapped through the renaming, the plan must speak the
user's names and validate against the renamed files, and a near miss (one atom dropped) must
go to the generic lift with one line naming the action.
"""

from __future__ import annotations

import pytest
import torch

from task import data
from task.config import PlannerConfig
from task.domains import get_domain
from task.domains.blocksworld import to_pddl as blocksworld_pddl
from task.domains.match import Match, NearMiss, match_domain, recognise, rename
from task.errors import PDDLError
from task.instances import choose_rules, from_text
from task.planner import plan
from task.symbolic import pddl_io, strips
from task.symbolic.generate import random_problem
from task.symbolic.validate import validate

torch.set_num_threads(1)

BLOCKSWORLD = data.read_text(data.DOMAIN_FILE)
EXAMPLE = data.read_text(data.EXAMPLE_FILE)
# pick-up without (not (handempty)): the near miss of the 4-op domain
NEAR_MISS = BLOCKSWORLD.replace(
    "(not (ontable ?x)) (not (clear ?x)) (not (handempty))))",
    "(not (ontable ?x)) (not (clear ?x))))",
)


def _domain_text(rules: str) -> str:
    return get_domain(rules).pddl_domain_text()


def _sample(rules: str, k: int) -> str:
    return get_domain(rules).to_pddl(list(get_domain(rules).samples(0))[k])


def _solve(domain_text: str, problem_text: str):
    """Plan as ``tamp plan`` does: recognised rules, their default config, seed 0; the PDDL
    actions and their validation against the files themselves."""
    domain = pddl_io.parse_domain(domain_text)
    instance = from_text(domain, problem_text, "<problem>")
    config = PlannerConfig.for_domain(instance.problem.domain)
    result = plan(instance.problem, config, 0)
    assert result.solved
    actions = get_domain(instance.problem.domain).to_actions(instance.problem, result.plan.moves)
    return instance, actions, validate(domain, instance.pddl, actions)


@pytest.mark.parametrize("rules", ["blocksworld", "logistics", "sokoban"])
@pytest.mark.parametrize("seed", range(4))
def test_a_renamed_domain_is_recognised_with_the_true_renaming(rules, seed):
    renamed = rename(_domain_text(rules), (), seed)
    found = match_domain(pddl_io.parse_domain(renamed.domain))
    assert isinstance(found, Match) and found.rules == rules
    assert found.renaming == renamed.renaming
    assert recognise(pddl_io.parse_domain(renamed.domain)) == rules


@pytest.mark.parametrize("rules", ["blocksworld", "logistics", "sokoban"])
def test_the_hand_written_files_match_themselves_under_the_identity(rules):
    domain = pddl_io.parse_domain(_domain_text(rules))
    found = match_domain(domain)
    assert isinstance(found, Match) and found.rules == rules and found.renaming.identity
    assert choose_rules(domain).renaming is None  # the plain path, unchanged


PROBLEMS = [
    ("blocksworld", EXAMPLE),
    ("blocksworld", blocksworld_pddl(random_problem(4, 7))),
    ("logistics", None),
    ("sokoban", None),
]


@pytest.mark.parametrize(("rules", "problem_text"), PROBLEMS)
def test_a_renamed_problem_plans_the_original_plan_in_the_users_names(rules, problem_text):
    domain_text = _domain_text(rules)
    problem_text = problem_text or _sample(rules, 1 if rules == "sokoban" else 0)
    renamed = rename(domain_text, (problem_text,), seed=11)
    _, want, _ = _solve(domain_text, problem_text)
    instance, actions, validation = _solve(renamed.domain, renamed.problems[0])
    assert instance.problem.domain == rules and instance.problem.renaming is not None
    assert validation.valid, validation  # against the renamed files themselves
    assert [renamed.original(a) for a in actions] == list(want)
    users = {r.user for r in renamed.renaming.actions}
    assert {a.name for a in actions} <= users
    objects = {new for _, new in renamed.objects}
    assert {x for a in actions for x in a.args} <= objects
    rules_domain = get_domain(rules)
    start = rules_domain.to_atoms(instance.problem, rules_domain.initial_state(instance.problem))
    assert start >= strips.initial_state(instance.pddl)  # atoms in the user's names too


def test_freely_renamed_objects_still_plan_a_valid_plan():
    renamed = rename(BLOCKSWORLD, (blocksworld_pddl(random_problem(3, 5)),), 2, monotone=False)
    instance, _, validation = _solve(renamed.domain, renamed.problems[0])
    assert instance.problem.domain == "blocksworld" and validation.valid


def test_a_near_miss_goes_to_the_lift_with_one_line_naming_the_action():
    renamed = rename(NEAR_MISS, (EXAMPLE,), seed=4)
    domain = pddl_io.parse_domain(renamed.domain)
    found = match_domain(domain)
    assert isinstance(found, NearMiss) and found.rules == "blocksworld"
    grab = {r.reference: r.user for r in renamed.renaming.actions}["pick-up"]
    hand = renamed.renaming.atom(("handempty",))[0]
    assert found.reason == (
        f"domain matches blocksworld-4ops except action {grab!r}: its delete list lacks ({hand})"
    )
    instance = from_text(domain, renamed.problems[0], "<problem>")
    assert instance.problem.domain == "strips" and instance.note.startswith(found.reason)
    with pytest.raises(PDDLError, match=f"lacks \\({hand}\\)"):
        choose_rules(domain, "blocksworld")


def test_an_extra_effect_is_a_near_miss_too():
    extra = BLOCKSWORLD.replace("(:action put-down", "(:action put-down", 1).replace(
        "(and (ontable ?x) (clear ?x) (handempty) (not (holding ?x)))",
        "(and (ontable ?x) (clear ?x) (handempty) (not (holding ?x)) (holding ?x))",
    )
    assert extra != BLOCKSWORLD
    found = match_domain(pddl_io.parse_domain(extra))
    assert isinstance(found, NearMiss)
    assert "action 'put-down': its add list has an extra (holding ?x)" in found.reason


def test_unused_extra_predicates_are_harmless():
    renamed = rename(BLOCKSWORLD, (EXAMPLE,), seed=6)
    text = renamed.domain.replace("(:predicates", "(:predicates (painted ?q)", 1)
    domain = pddl_io.parse_domain(text)
    assert isinstance(match_domain(domain), Match)
    problem = renamed.problems[0].replace(
        "(:init", "(:init (painted " + renamed.objects[0][1] + ")"
    )
    instance = from_text(domain, problem, "<problem>")
    assert instance.problem.domain == "blocksworld"
    unsolvable = problem.replace(
        "(:goal (and", "(:goal (and (painted " + renamed.objects[1][1] + ")"
    )
    with pytest.raises(PDDLError, match=r"unsolvable goal: .*painted"):
        from_text(domain, unsolvable, "<problem>")


def test_problem_errors_speak_the_users_names():
    renamed = rename(BLOCKSWORLD, (EXAMPLE,), seed=8)
    hand = renamed.renaming.atom(("handempty",))[0]
    broken = renamed.problems[0].replace(f"({hand})", "")
    with pytest.raises(PDDLError, match=f"lacks \\({hand}\\)") as err:
        from_text(pddl_io.parse_domain(renamed.domain), broken, "<problem>")
    assert "handempty" not in str(err.value)


def test_a_typed_blocksworld_with_one_type_matches():
    typed = BLOCKSWORLD.replace("(:requirements :strips)", "(:requirements :strips :typing)")
    typed = typed.replace("(:predicates", "(:types block)\n  (:predicates")
    typed = typed.replace(
        "(on ?x ?y) (ontable ?x) (clear ?x) (handempty) (holding ?x)",
        "(on ?x ?y - block) (ontable ?x - block) (clear ?x - block) (handempty)"
        " (holding ?x - block)",
    )
    typed = typed.replace("(?x)", "(?x - block)").replace("(?x ?y)", "(?x ?y - block)")
    domain = pddl_io.parse_domain(typed)
    found = match_domain(domain)
    assert isinstance(found, Match) and found.rules == "blocksworld"
    problem = EXAMPLE.replace("(:objects a b c d e)", "(:objects a b c d e - block)")
    assert from_text(domain, problem, "<problem>").problem.init == ("table", "a", "b", "table", "d")


def test_unrelated_domains_match_nothing():
    from task.domains.strips import GRIPPER

    assert match_domain(pddl_io.parse_domain(GRIPPER)) is None


def test_tamp_plan_says_why_a_near_miss_is_planned_by_the_lift(tmp_path, capsys):
    from tamp.cli import main

    renamed = rename(NEAR_MISS, (blocksworld_pddl(random_problem(2, 1)),), seed=4)
    domain, problem = tmp_path / "d.pddl", tmp_path / "p.pddl"
    domain.write_text(renamed.domain)
    problem.write_text(renamed.problems[0])
    reason = match_domain(pddl_io.parse_domain(renamed.domain)).reason
    main(["plan", str(domain), str(problem), "--time-limit", "2"])
    err = capsys.readouterr().err
    assert f"note: {reason}" in err


def test_a_benchmark_folder_is_renamed_file_for_file(tmp_path):
    from task.domains.match import rename_folder

    src = tmp_path / "set"
    (src / "instances" / "sub").mkdir(parents=True)
    (src / "domain.pddl").write_text(BLOCKSWORLD)
    (src / "instances" / "sub" / "instance-1.pddl").write_text(EXAMPLE)
    (src / "manifest.csv").write_text("name\ninstance-1\n")
    made = rename_folder(src, tmp_path / "out", seed=3)
    out = tmp_path / "out"
    assert (out / "manifest.csv").read_text() == "name\ninstance-1\n"
    domain = pddl_io.parse_domain((out / "domain.pddl").read_text())
    assert isinstance(match_domain(domain), Match)
    assert (out / "instances" / "sub" / "instance-1.pddl").read_text() == made.problems[0]
    assert "on" not in {p.name for p in domain.predicates}
    with pytest.raises(PDDLError, match=r"no domain\.pddl"):
        rename_folder(tmp_path / "nothing", out)
