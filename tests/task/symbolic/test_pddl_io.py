"""PDDL reading and writing: one-line errors that name the file, and the VAL plan format."""

from __future__ import annotations

from pathlib import Path

import pytest

from task.errors import PDDLError, TampError
from task.problem import Action
from task.symbolic import pddl_io

PROBLEM = """; a comment before the problem
(define (problem tiny)
(:domain blocksworld-4ops)
(:objects c a b )
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a b)))
)
"""


def _error(excinfo: pytest.ExceptionInfo, *parts: str) -> str:
    message = str(excinfo.value)
    assert "\n" not in message
    for part in parts:
        assert part in message
    return message


def test_load_domain_and_problem(bw_domain_path, tmp_path):
    domain = pddl_io.load_domain(bw_domain_path)
    path = tmp_path / "p.pddl"
    path.write_text(PROBLEM)
    problem = pddl_io.load_problem(path, domain)
    assert str(problem.name) == "tiny"
    assert pddl_io.load_object_order(path) == ("c", "a", "b")


def test_missing_file_names_the_file(tmp_path):
    missing = tmp_path / "nope.pddl"
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.load_domain(missing)
    _error(excinfo, str(missing), "no such file")
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.read_plan(tmp_path)
    _error(excinfo, str(tmp_path), "cannot read")


@pytest.mark.parametrize(
    ("text", "where"),
    [
        (PROBLEM.replace("(on b a)", "(on b a]"), "line 5, column"),
        (PROBLEM[:-3], "end of file"),
        ("(define (problem x) (:domain d) (:init) (:goal (and (on a b)))", "end of file"),
        ("(defin (problem x))", "line 1, column 2"),
    ],
)
def test_malformed_problem_is_one_line_with_position(tmp_path, text, where):
    path = tmp_path / "broken.pddl"
    path.write_text(text)
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.load_problem(path)
    _error(excinfo, str(path), "parse error", where)


def test_malformed_domain(bw_domain_path, tmp_path):
    text = bw_domain_path.read_text().replace(":effect", ":efect", 1)
    path = tmp_path / "domain.pddl"
    path.write_text(text)
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.load_domain(path)
    _error(excinfo, str(path), "parse error at line", "unexpected")


def test_library_validation_error_is_one_line(bw_domain_path):
    text = bw_domain_path.read_text().replace("(?x ?y)", "(?x - block ?y)", 1)
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.parse_domain(text, "typed.pddl")
    _error(excinfo, "typed.pddl", "typing")


def test_problem_for_another_domain(bw_domain_path):
    domain = pddl_io.load_domain(bw_domain_path)
    text = PROBLEM.replace("blocksworld-4ops", "logistics-strips")
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.parse_problem(text, "other.pddl", domain)
    _error(excinfo, "other.pddl", "'logistics-strips'", "'blocksworld-4ops'")


def test_errors_are_one_family():
    assert issubclass(PDDLError, TampError)


def test_plan_round_trip(tmp_path):
    plan = (Action("unstack", ("b", "a")), Action("put-down", ("b",)), Action("pick-up", ("a",)))
    text = pddl_io.format_plan(plan)
    assert text == "(unstack b a)\n(put-down b)\n(pick-up a)\n; cost = 3 (unit cost)\n"
    path = pddl_io.write_plan(plan, tmp_path / "sub" / "plan.txt")
    assert pddl_io.read_plan(path) == plan
    assert pddl_io.format_plan(()) == "; cost = 0 (unit cost)\n"


def test_plan_reader_skips_comments_and_lowercases():
    text = "; header\n\n  (UNSTACK B A)  ; inline\n(put-down   b)\n\n; cost = 2 (unit cost)\n"
    assert pddl_io.parse_plan(text) == (Action("unstack", ("b", "a")), Action("put-down", ("b",)))


@pytest.mark.parametrize("line", ["stack a b", "(stack a (b))", "(stack a b", "()", "(a) (b)"])
def test_malformed_plan_line(line):
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.parse_plan(f"(pick-up a)\n; ok\n{line}\n", "plan.txt")
    _error(excinfo, "plan.txt", "line 3", "malformed plan line")


def test_object_order_with_types_and_comments():
    text = "(define (problem p) (:domain d) (:objects ; x y\n up down - DIR b0 - BOX f1 f0 - LOC)"
    assert pddl_io.object_order(text) == ("up", "down", "b0", "f1", "f0")
    assert pddl_io.object_order("(define (problem p) (:domain d) (:init))") == ()


@pytest.mark.shared
@pytest.mark.parametrize("name", ["blocksworld", "logistics", "sokoban"])
def test_planbench_domains_parse(planbench_dir, name):
    domain = pddl_io.load_domain(planbench_dir / name / "domain.pddl")
    instances = sorted((planbench_dir / name / "instances").rglob("*.pddl"))[:5]
    for path in instances:
        problem = pddl_io.load_problem(path, domain)
        assert {str(o.name).lower() for o in problem.objects} == set(
            pddl_io.load_object_order(path)
        )


def test_types_without_the_typing_requirement_are_read_as_typed():
    """IPC domains such as miconic declare (:types ...) under (:requirements :strips) only."""
    text = """(define (domain lift) (:requirements :strips) (:types floor - object)
      (:predicates (at ?f - floor))
      (:action go :parameters (?f - floor) :precondition (and) :effect (at ?f)))"""
    domain = pddl_io.parse_domain(text)
    assert str(domain.name) == "lift" and "floor" in {str(t) for t in domain.types}
    bare = "(define (domain d) (:types t) (:predicates (p ?x - t)))"
    assert "t" in {str(t) for t in pddl_io.parse_domain(bare).types}


@pytest.mark.parametrize("loader", ["load_domain", "load_problem", "read_plan", "read_plan_lines"])
def test_a_binary_file_is_one_line_naming_it(tmp_path, loader):
    path = tmp_path / "picture.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe\x9d")
    with pytest.raises(PDDLError) as excinfo:
        getattr(pddl_io, loader)(path)
    _error(excinfo, str(path), "not a text file")


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be", "utf-8-sig"])
def test_a_file_saved_as_utf16_or_with_a_bom_reads_as_its_utf8_text(
    bw_domain_path, tmp_path, encoding
):
    """As some Windows editors save PDDL: UTF-16 with its byte-order mark, CRLF line ends."""
    text = Path(bw_domain_path).read_text(encoding="utf-8")
    path = tmp_path / "domain.pddl"
    bom = {"utf-16-le": "\ufeff", "utf-16-be": "\ufeff"}.get(encoding, "")
    path.write_bytes((bom + text.replace("\n", "\r\n")).encode(encoding))
    assert pddl_io.read_text(path) == text
    assert pddl_io.load_domain(path) == pddl_io.load_domain(bw_domain_path)


def test_utf16_without_a_byte_order_mark_is_not_text(tmp_path):
    path = tmp_path / "domain.pddl"
    path.write_bytes("(define (domain d))".encode("utf-16-le"))
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.read_text(path)
    _error(excinfo, str(path), "not a text file")


def test_parsing_writes_nothing_to_the_users_home(bw_domain_path, tmp_path):
    """The compiled grammar is kept in memory only: a fresh process that parses a domain and
    a problem, its home and cache folders pointed at an empty folder, leaves that folder
    empty (library code writes only the files it is told to)."""
    import os
    import subprocess
    import sys

    code = (
        "import sys; from task.symbolic import pddl_io; "
        "d = pddl_io.parse_domain(open(sys.argv[1]).read(), 'd'); "
        "print(pddl_io.parse_problem(sys.argv[2], 'p', d).name)"
    )
    env = {**os.environ, "HOME": str(tmp_path), "XDG_CACHE_HOME": str(tmp_path / "cache")}
    env.pop("SOFT_TAMP_NO_CACHE", None)
    root = Path(__file__).resolve().parents[3]
    out = subprocess.run(
        [sys.executable, "-c", code, str(bw_domain_path), PROBLEM],
        capture_output=True,
        text=True,
        env=env,
        cwd=root,
        check=True,
    )
    assert out.stdout.strip()
    assert list(tmp_path.rglob("*")) == []


@pytest.mark.parametrize(
    ("edit", "parts"),
    [
        (("(on a b)", "(shiny a)"), ("goal atom (shiny a): unknown predicate 'shiny'", "ontable")),
        (
            ("(on a b)", "(on a e)"),
            ("goal atom (on a e) names unknown object 'e'", "(valid: c, a, b)"),
        ),
        (("(on a b)", "(on a)"), ("goal atom (on a): on takes 2 argument(s), not 1",)),
        (("(handempty)", "(handempty) (shiny c)"), ("init atom (shiny c): unknown predicate",)),
        (("(and (on a b))", "(and (on a b) (not (shiny a)))"), ("goal atom (shiny a)",)),
    ],
)
def test_a_typo_in_the_goal_or_init_is_bad_input_naming_it(bw_domain_path, edit, parts):
    """A goal typo was read as an unsolvable problem (exit 1); the reader refuses it as it
    refuses the same typo in :init, listing the valid predicates or objects."""
    domain = pddl_io.load_domain(bw_domain_path)
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.parse_problem(PROBLEM.replace(*edit), "typo.pddl", domain)
    _error(excinfo, "typo.pddl: ", *parts)
    assert pddl_io.parse_problem(PROBLEM, "ok.pddl", domain).name == "tiny"


@pytest.mark.parametrize(
    "text",
    ["(unstack c b); (put-down c)", "0: (unstack c b) ; 1: (put-down c)", "a -> b; move(b -> c)"],
)
def test_steps_joined_by_semicolons_on_one_line_are_refused(text):
    """The one-line form `bench executability` reads was read as its first step, the rest a
    comment."""
    with pytest.raises(PDDLError) as excinfo:
        pddl_io.parse_plan_lines(f"(pick-up a)\n{text}\n", "one.plan")
    _error(excinfo, "one.plan: line 2: several actions on one line joined by ';'", "one action")


def test_a_comment_after_a_step_that_is_no_step_is_still_a_comment():
    text = "(unstack c b) ; clears b\n(put-down c) ; cost = 2 (unit cost)\n; (stack c a)\n"
    steps = [line.step for line in pddl_io.parse_plan_lines(text)]
    assert steps == [Action("unstack", ("c", "b")), Action("put-down", ("c",))]
