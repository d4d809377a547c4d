"""Reachability grounding: equal to the reachable part of `ground_all`, static pruning, errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from task import data
from task.errors import PDDLError
from task.problem import Action
from task.symbolic import ground, pddl_io, strips

IPC = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "ipc"


@pytest.fixture
def ipc_dir() -> Path:
    """``../shared/data/ipc`` next to the repository; skips the test when it is absent."""
    if not (IPC / "gripper" / "domain.pddl").is_file():
        pytest.skip(f"IPC data not found at {IPC} (needs the ../shared checkout)")
    return IPC


def _reachable_subset(domain, problem):
    """The actions of `ground_all` whose preconditions the delete relaxation reaches."""
    everything = strips.ground_all(domain, problem)
    reached = set(strips.initial_state(problem))
    while True:
        adds = set().union(*(g.add for _, g in everything if g.pre_pos <= reached))
        if adds <= reached:
            break
        reached |= adds
    return tuple((a, g) for a, g in everything if g.pre_pos <= reached), reached


def _check_equal(domain, problem):
    expected, atoms = _reachable_subset(domain, problem)
    result = ground.reachable(domain, problem)
    assert result.actions == expected
    assert set(result.atoms) == atoms
    assert list(result.atoms) == sorted(atoms)


def _domain_text(path: Path) -> str:
    # miconic's domain declares types without :typing, which the `pddl` library rejects
    return pddl_io.read_text(path).replace(
        "(:requirements :strips)", "(:requirements :strips :typing)"
    )


def test_equal_on_embedded_blocksworld():
    domain = data.domain()
    problem = pddl_io.parse_problem(data.read_text(data.EXAMPLE_FILE), "example", domain)
    _check_equal(domain, problem)


@pytest.mark.parametrize(
    "rel",
    [
        "blocksworld/instances/generated_basic_3/instance-1.pddl",
        "blocksworld/instances/generated_basic/instance-1.pddl",
        "logistics/instances/instance-1.pddl",
        "logistics/instances/instance-2.pddl",
    ],
)
def test_equal_on_planbench(planbench_dir, rel):
    folder = "blocksworld" if rel.startswith("blocksworld") else "logistics"
    domain = (
        data.domain()
        if folder == "blocksworld"
        else pddl_io.load_domain(planbench_dir / folder / "domain.pddl")
    )
    _check_equal(domain, pddl_io.load_problem(planbench_dir / rel, domain))


@pytest.mark.parametrize(
    "rel",
    ["gripper/task01.pddl", "gripper/task02.pddl", "miconic/task01.pddl", "miconic/task02.pddl"],
)
def test_equal_on_ipc(ipc_dir, rel):
    folder = rel.split("/")[0]
    domain = pddl_io.parse_domain(_domain_text(ipc_dir / folder / "domain.pddl"), folder)
    _check_equal(domain, pddl_io.load_problem(ipc_dir / rel, domain))


ROADS = """
(define (domain roads)
  (:requirements :strips :typing :equality)
  (:types place - object city - place vehicle)
  (:constants depot - place)
  (:predicates (at ?v - vehicle ?p - place) (road ?a - place ?b - place) (visited ?p - place))
  (:action drive
    :parameters (?v - vehicle ?a - place ?b - (either city place))
    :precondition (and (at ?v ?a) (road ?a ?b) (not (= ?a ?b)))
    :effect (and (at ?v ?b) (not (at ?v ?a)) (visited ?b)))
  (:action mark
    :parameters (?v - vehicle ?p - city)
    :precondition (and (at ?v ?p) (road depot ?p))
    :effect (visited ?p)))
"""

ROADS_PROBLEM = """
(define (problem p) (:domain roads)
  (:objects truck - vehicle x y z w - city)
  (:init (at truck depot) (road depot x) (road x y) (road y y) (road z w) (road w z))
  (:goal (and (visited y))))
"""


def test_static_pruning_types_and_constants():
    domain = pddl_io.parse_domain(ROADS, "roads")
    result = ground.reachable(domain, pddl_io.parse_problem(ROADS_PROBLEM, "p", domain))
    # road is static: only its init facts bind ?a ?b; z and w are never reached; (= y y) pruned
    assert [a for a, _ in result.actions] == [
        Action("drive", ("truck", "depot", "x")),
        Action("drive", ("truck", "x", "y")),
        Action("mark", ("truck", "x")),
    ]
    drive = dict(result.actions)[Action("drive", ("truck", "x", "y"))]
    assert drive.pre_pos == {("at", "truck", "x"), ("road", "x", "y")}
    assert drive.add == {("at", "truck", "y"), ("visited", "y")}
    assert drive.delete == {("at", "truck", "x")}
    assert ("at", "truck", "z") not in result.atoms
    assert ("visited", "y") in result.atoms


def test_free_parameters_range_over_their_type():
    text = ROADS.replace("(and (at ?v ?p) (road depot ?p))", "(and)")
    domain = pddl_io.parse_domain(text, "roads")
    result = ground.reachable(domain, pddl_io.parse_problem(ROADS_PROBLEM, "p", domain))
    marks = [a.args for a, _ in result.actions if a.name == "mark"]
    assert marks == [("truck", c) for c in ("w", "x", "y", "z")]


@pytest.mark.parametrize(
    ("pre", "eff", "feature"),
    [
        ("(and (at ?v ?a) (not (road ?a ?b)))", "(at ?v ?b)", "negative precondition"),
        ("(or (at ?v ?a) (road ?a ?b))", "(at ?v ?b)", "disjunctive precondition"),
        ("(forall (?c - city) (road ?a ?c))", "(at ?v ?b)", "universal precondition (forall)"),
        ("(exists (?c - city) (road ?c ?b))", "(at ?v ?b)", "existential precondition (exists)"),
        ("(at ?v ?a)", "(when (road ?a ?b) (at ?v ?b))", "conditional effect (when)"),
        ("(at ?v ?a)", "(forall (?c - city) (visited ?c))", "universal effect (forall)"),
        ("(> (fuel ?v) 1)", "(at ?v ?b)", "numeric fluent"),
        ("(at ?v ?a)", "(increase (fuel ?v) 1)", "numeric fluent"),
    ],
)
def test_unsupported_features_raise_one_line(pre, eff, feature):
    text = (
        ROADS.replace(
            ":equality",
            ":equality :negative-preconditions :disjunctive-preconditions"
            " :quantified-preconditions :conditional-effects :numeric-fluents",
        )
        .replace("(:action drive", "(:functions (fuel ?v - vehicle))\n  (:action drive")
        .replace("(and (at ?v ?a) (road ?a ?b) (not (= ?a ?b)))", pre)
        .replace("(and (at ?v ?b) (not (at ?v ?a)) (visited ?b))", eff)
    )
    domain = pddl_io.parse_domain(text, "roads")
    with pytest.raises(PDDLError, match=r"^action drive: (precondition|effect): ") as exc:
        ground.reachable(domain, pddl_io.parse_problem(ROADS_PROBLEM, "p", domain))
    assert feature in str(exc.value)
    assert "\n" not in str(exc.value)


def test_derived_predicates_raise():
    text = ROADS.replace(":equality", ":equality :derived-predicates").replace(
        "(:action drive", "(:derived (visited ?p - place) (road depot ?p))\n  (:action drive"
    )
    domain = pddl_io.parse_domain(text, "roads")
    with pytest.raises(PDDLError, match=r"^domain roads: derived predicate .* is not supported$"):
        ground.reachable(domain, pddl_io.parse_problem(ROADS_PROBLEM, "p", domain))
