"""PDDL as other tools write it: Tarski's writer, pyperplan's benchmark folder, the IPC's files.

The fixtures (tests/task/fixtures/pddl_styles/) are small files in each tool's layout: the
Tarski and IPC-logistics pairs and every problem file are written for these tests; the two
pyperplan domain files are the IPC's own (each file's header says where it comes from). Each
parses, and `tamp plan` plans it to a plan that validates; what the planners cannot plan stays a
one-line error naming the feature and the line.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tamp.cli import main
from task.errors import PDDLError
from task.symbolic import pddl_io, strips
from tests.cli_check import one_line_error

STYLES = Path(__file__).resolve().parents[1] / "fixtures" / "pddl_styles"
NAMES = ("tarski", "pyperplan-blocks", "pyperplan-gripper", "ipc-logistics")
QUICK = ["--restarts", "4", "--iters", "30", "--max-windows", "20"]


def _files(name: str) -> tuple[Path, Path]:
    return STYLES / f"{name}-domain.pddl", STYLES / f"{name}-problem.pddl"


@pytest.mark.parametrize("name", NAMES)
def test_each_style_parses_as_meant(name):
    domain_path, problem_path = _files(name)
    domain = pddl_io.load_domain(domain_path)
    problem = pddl_io.load_problem(problem_path, domain)
    assert strips.goal_atoms(problem)  # lowercased atoms, whatever case the file used
    assert all(a == tuple(x.lower() for x in a) for a in strips.goal_atoms(problem))
    assert len(domain.actions) >= 3


@pytest.mark.parametrize("name", NAMES)
def test_each_style_plans_to_a_valid_plan(name, capsys, tmp_path):
    domain_path, problem_path = _files(name)
    out = tmp_path / "plan.txt"
    assert main(["plan", str(domain_path), str(problem_path), *QUICK, "--out", str(out)]) == 0
    assert capsys.readouterr().out.splitlines()[-1].startswith("VALID: valid plan of ")
    assert main(["validate", str(domain_path), str(problem_path), str(out)]) == 0


def test_the_tarski_writers_empty_sections_parse():
    """The reported case: ``(:types)``, ``(:constants)``, ``(:functions)`` left empty and
    ``:requirements :equality`` with no equality used ("unexpected ')'" before)."""
    text = (STYLES / "tarski-domain.pddl").read_text()
    assert "(:functions\n        \n    )" in text
    domain = pddl_io.parse_domain(text, "tarski")
    assert {str(p.name) for p in domain.predicates} == {
        "on",
        "ontable",
        "clear",
        "handempty",
        "holding",
    }


BASE = """(define (domain d) {header}
 (:predicates (p ?x) (q ?x))
 (:action a :parameters (?x) :precondition (and (p ?x)) :effect (and (q ?x) (not (p ?x)))))"""


@pytest.mark.parametrize(
    "header",
    [
        "(:requirements)",
        "(:requirements :strips) (:types) (:constants) (:functions)",
        "(:requirements :strips :equality :negative-preconditions :adl)",
        "(:requirements :typing)",
        "(:REQUIREMENTS :STRIPS :Typing)",
        "(:requirements :strips :durative-actions)",  # declared, never used: dropped
    ],
)
def test_harmless_headers_are_accepted(header):
    domain = pddl_io.parse_domain(BASE.format(header=header), "d")
    assert [str(a.name) for a in domain.actions] == ["a"]


@pytest.mark.parametrize(
    "text",
    [
        # = used without :equality (Fast Downward and VAL read it)
        "(define (domain d) (:requirements :strips) (:predicates (p ?x))"
        " (:action a :parameters (?x ?y) :precondition (and (p ?x) (not (= ?x ?y)))"
        " :effect (not (p ?x))))",
        # ?x - object with no (:types) at all
        "(define (domain d) (:predicates (p ?x - object))"
        " (:action a :parameters (?x - object) :precondition (p ?x) :effect (not (p ?x))))",
        # sections out of the grammar's order
        "(define (domain d) (:predicates (p ?x)) (:constants c)"
        " (:action a :parameters () :precondition (p c) :effect (not (p c))))",
        # an action without a :precondition
        "(define (domain d) (:predicates (p ?x)) (:action a :parameters (?x) :effect (p ?x)))",
        # an empty :predicates
        "(define (domain d) (:predicates) (:action a :parameters () :precondition () :effect ()))",
    ],
)
def test_valid_pddl_that_the_grammar_alone_rejects_parses(text):
    assert len(pddl_io.parse_domain(text, "d").actions) == 1


def test_parse_errors_keep_the_files_lines_after_dropped_sections():
    text = "(define (domain d)\n  (:types\n  )\n  (:predicates (p ?x)\n  (:action a))"
    with pytest.raises(PDDLError, match=r"^d: parse error at line 5, column 4"):
        pddl_io.parse_domain(text, "d")


def test_the_problem_side_reads_any_case_and_empty_requirements():
    domain = pddl_io.parse_domain(BASE.format(header=""), "d")
    problem = pddl_io.parse_problem(
        "(DEFINE (PROBLEM x) (:DOMAIN D) (:requirements) (:OBJECTS O1)"
        " (:INIT (P O1)) (:GOAL (AND (Q O1))))",
        "x",
        domain,
    )
    assert strips.goal_atoms(problem) == (("q", "o1"),)


UNSUPPORTED = """(define (domain d)
  (:requirements :strips :adl :numeric-fluents :derived-predicates)
  (:predicates (p ?x) (q ?x))
  (:functions (total-cost))
  (:action a
    :parameters (?x)
    :precondition {pre}
    :effect {eff}))"""


@pytest.mark.parametrize(
    ("pre", "eff", "line", "feature"),
    [
        ("(p ?x)", "(when (p ?x) (q ?x))", 8, "conditional effect (when)"),
        ("(p ?x)", "(forall (?y) (q ?y))", 8, "universal effect (forall)"),
        ("(p ?x)", "(and (q ?x) (increase (total-cost) 1))", 8, "numeric fluent (increase)"),
        ("(exists (?y) (p ?y))", "(q ?x)", 7, "existential precondition (exists)"),
        ("(or (p ?x) (q ?x))", "(q ?x)", 7, "disjunctive precondition (or)"),
        ("(and (p ?x) (not (q ?x)))", "(q ?x)", 7, "negative precondition (not)"),
    ],
)
def test_unsupported_features_name_the_feature_and_the_line(pre, eff, line, feature):
    text = UNSUPPORTED.format(pre=pre, eff=eff)
    pddl_io.parse_domain(text, "d")  # valid PDDL: it parses (tamp validate reads it)
    with pytest.raises(PDDLError) as info:
        pddl_io.check_strips(text, "d.pddl")
    message = str(info.value)
    assert message.startswith(f"d.pddl: line {line}: {feature} ")
    assert "\n" not in message


def test_derived_predicates_and_negative_goals_name_their_line():
    text = UNSUPPORTED.format(pre="(p ?x)", eff="(q ?x)").replace(
        "  (:action a", "  (:derived (q ?x) (p ?x))\n  (:action a"
    )
    with pytest.raises(PDDLError, match=r"^d: line 5: derived predicate"):
        pddl_io.check_strips(text, "d")
    goal = "(define (problem x) (:domain d) (:objects o)\n (:init (p o))\n (:goal (not (q o))))"
    with pytest.raises(PDDLError, match=r"^x: line 3: negative goal \(not\)"):
        pddl_io.check_strips(goal, "x")


def test_tamp_plan_refuses_an_unsupported_feature_in_one_line(capsys, tmp_path):
    domain = tmp_path / "d.pddl"
    domain.write_text(UNSUPPORTED.format(pre="(p ?x)", eff="(when (p ?x) (q ?x))"))
    problem = tmp_path / "x.pddl"
    problem.write_text("(define (problem x) (:domain d) (:objects o) (:init (p o)) (:goal (q o)))")
    assert main(["plan", str(domain), str(problem)]) == 2
    assert f"{domain}: line 8: conditional effect (when)" in one_line_error(capsys)


def test_tamp_validate_refuses_derived_predicates_in_one_line(capsys, tmp_path):
    """The validator has no axioms: a goal over a derived predicate was judged
    NON_GOAL_REACHING in silence; it is refused in one line, as tamp plan refuses it."""
    domain = tmp_path / "d.pddl"
    domain.write_text(
        "(define (domain d) (:requirements :strips :derived-predicates)"
        " (:predicates (p ?x) (q ?x))"
        " (:derived (q ?x) (p ?x))"
        " (:action a :parameters (?x) :precondition (and) :effect (p ?x)))"
    )
    problem = tmp_path / "x.pddl"
    problem.write_text("(define (problem x) (:domain d) (:objects o) (:init) (:goal (q o)))")
    plan = tmp_path / "x.plan"
    plan.write_text("(a o)\n")
    assert main(["validate", str(domain), str(problem), str(plan)]) == 2
    line = one_line_error(capsys)
    assert "derived predicate (q ?x) is not supported" in line


def test_object_annotations_keep_every_name_its_type():
    """``- object`` that ends a typed list is dropped (an untyped name is an object); the
    names before another type keep that type."""
    domain = pddl_io.parse_domain(
        "(define (domain d) (:requirements :typing) (:types block)"
        " (:predicates (p ?y - block ?x - object))"
        " (:action a :parameters (?y - block ?x ?z - object) :precondition (p ?y ?x)"
        " :effect (not (p ?y ?z))))",
        "d",
    )
    params = {str(p.name): set(p.type_tags) for p in next(iter(domain.actions)).parameters}
    assert params == {"y": {"block"}, "x": set(), "z": set()}
    problem = pddl_io.parse_problem(
        "(define (problem x) (:domain d) (:objects b - block a c - object)"
        " (:init (p b a)) (:goal (and (p b c))))",
        "x",
        domain,
    )
    assert {str(o.name): set(o.type_tags) for o in problem.objects} == {
        "b": {"block"},
        "a": set(),
        "c": set(),
    }
