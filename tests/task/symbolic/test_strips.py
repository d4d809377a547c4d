"""Generic STRIPS semantics: grounding, errors that list valid names, delete-then-add."""

from __future__ import annotations

import pytest

from task.errors import PDDLError, ProblemError
from task.problem import Action
from task.symbolic import pddl_io, search, strips

TOY_DOMAIN = """
(define (domain toy)
  (:requirements :strips :typing :negative-preconditions)
  (:types room key)
  (:predicates (at ?r - room) (door ?a - room ?b - room) (locked ?r - room) (has ?k - key))
  (:action go
    :parameters (?a - room ?b - room)
    :precondition (and (at ?a) (door ?a ?b) (not (locked ?b)))
    :effect (and (at ?b) (not (at ?a))))
  (:action unlock
    :parameters (?k - key ?r - room)
    :precondition (has ?k)
    :effect (not (locked ?r))))
"""

TOY_PROBLEM = """
(define (problem p1) (:domain toy)
  (:objects r1 r2 r3 - room k - key)
  (:init (at r1) (door r1 r2) (door r2 r3) (door r1 r1) (locked r3) (has k))
  (:goal (and (at r3))))
"""


@pytest.fixture
def toy():
    domain = pddl_io.parse_domain(TOY_DOMAIN, "toy-domain")
    return domain, pddl_io.parse_problem(TOY_PROBLEM, "toy-problem", domain)


def test_ground_typed_action(toy):
    pre_pos, pre_neg, add, delete = strips.ground(*toy, Action("go", ("r1", "r2")))
    assert pre_pos == {("at", "r1"), ("door", "r1", "r2")}
    assert pre_neg == {("locked", "r2")}
    assert add == {("at", "r2")}
    assert delete == {("at", "r1")}


def test_initial_state_and_goal(toy):
    _, problem = toy
    state = strips.initial_state(problem)
    assert ("locked", "r3") in state and ("has", "k") in state
    assert strips.goal_atoms(problem) == (("at", "r3"),)


def test_negative_precondition_and_apply(toy):
    state = strips.initial_state(toy[1])
    go = strips.ground(*toy, Action("go", ("r2", "r3")))
    state = strips.apply(state, strips.ground(*toy, Action("go", ("r1", "r2"))))
    assert not strips.applicable(state, go)
    assert strips.unmet(state, go) == ("(not (locked r3))",)
    state = strips.apply(state, strips.ground(*toy, Action("unlock", ("k", "r3"))))
    assert strips.applicable(state, go)
    assert strips.holds(strips.apply(state, go), strips.goal_atoms(toy[1]))


def test_apply_deletes_before_adding(toy):
    state = strips.initial_state(toy[1])
    stay = strips.ground(*toy, Action("go", ("r1", "r1")))  # adds and deletes (at r1)
    assert strips.applicable(state, stay)
    assert strips.apply(state, stay) == state


@pytest.mark.parametrize(
    ("action", "parts"),
    [
        (Action("fly", ("r1",)), ["unknown action 'fly'", "valid: go, unlock"]),
        (Action("go", ("r1",)), ["go takes 2 arguments", "got 1"]),
        (Action("go", ("r1", "r9")), ["unknown object 'r9'", "valid: k, r1, r2, r3"]),
        (Action("go", ("k", "r2")), ["k is not of type room"]),
    ],
)
def test_ground_errors_list_valid_options(toy, action, parts):
    with pytest.raises(ProblemError) as excinfo:
        strips.ground(*toy, action)
    message = str(excinfo.value)
    assert "\n" not in message
    for part in parts:
        assert part in message


def test_case_insensitive_names(toy):
    assert strips.ground(*toy, Action("GO", ("R1", "R2"))).add == {("at", "r2")}


def test_non_strips_goal_and_precondition_rejected(toy):
    domain, _ = toy
    negative = TOY_PROBLEM.replace("(and (at r3))", "(and (at r3) (not (has k)))")
    problem = pddl_io.parse_problem(negative, "neg", domain)
    with pytest.raises(PDDLError, match="goal literal"):
        strips.goal_atoms(problem)
    disjunctive = TOY_DOMAIN.replace(":negative-preconditions", ":disjunctive-preconditions")
    disjunctive = disjunctive.replace("(not (locked ?b))", "(or (at ?b) (at ?a))")
    domain = pddl_io.parse_domain(disjunctive, "or-domain")
    with pytest.raises(PDDLError, match="is not STRIPS"):
        strips.ground(domain, toy[1], Action("go", ("r1", "r2")))


def test_ground_all_respects_types(toy):
    names = {(str(a.name), a.args) for a, _ in strips.ground_all(*toy)}
    assert ("unlock", ("k", "r3")) in names
    assert all(a[0] != "k" for n, a in names if n == "go")
    assert len(names) == 3 * 3 + 1 * 3


def test_bfs_on_typed_domain(toy):
    assert search.optimal_length_strips(*toy) == 3
    assert search.optimal_length_strips(*toy, max_nodes=1) is None


@pytest.mark.shared
def test_untyped_logistics(planbench_dir):
    domain = pddl_io.load_domain(planbench_dir / "logistics" / "domain.pddl")
    problem = pddl_io.load_problem(planbench_dir / "logistics/instances/instance-2.pddl", domain)
    assert strips.goal_atoms(problem)
    assert search.optimal_length_strips(domain, problem) == 3  # PlanBench ground truth: 3


@pytest.mark.shared
def test_typed_sokoban(planbench_dir):
    domain = pddl_io.load_domain(planbench_dir / "sokoban" / "domain.pddl")
    problem = pddl_io.load_problem(planbench_dir / "sokoban/instances/instance-1.pddl", domain)
    assert strips.goal_atoms(problem) == (("at", "box0", "f6-6f"),)
    state = strips.initial_state(problem)
    move = strips.ground(domain, problem, Action("move", ("f6-0f", "f5-0f", "up")))
    assert strips.applicable(state, move)
    assert ("at-robot", "f5-0f") in strips.apply(state, move)
    with pytest.raises(ProblemError, match="box0 is not of type loc"):
        strips.ground(domain, problem, Action("move", ("f6-0f", "box0", "up")))
