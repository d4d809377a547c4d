"""One plan reader (`pddl_io.parse_plan_lines`) for ``tamp validate`` and ``tamp run --plan``:
both accept the same formats, and ``validate`` checks a move plan as the 4-op actions its moves
stand for; misuse names the plan file and the line."""

from __future__ import annotations

import pytest

from tamp.loop.given import parse_given
from task import data
from task.errors import PDDLError, ProblemError
from task.problem import TABLE, Action, Move, Problem
from task.symbolic import pddl_io
from task.symbolic.validate import ValidationStatus, validate_files

# b on a, c on the table; goal: the tower c-a-b
THREE = Problem(
    "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
)
PROBLEM = """(define (problem three) (:domain blocksworld-4ops) (:objects a b c)
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a c) (on b a))))
"""
MOVES = (Move("b", TABLE), Move("a", "c"), Move("b", "a"))
PLANS = {  # the same valid plan in every format the reader takes
    "actions": "(unstack b a)\n(put-down b)\n(pick-up a)\n(stack a c)\n(pick-up b)\n(stack b a)\n",
    "numbered": "0: (UNSTACK B A) [1]\n1: (put-down b)\n2. (pick-up a)\n3: (stack a c)\n"
    "; a comment\n\n4: (pick-up b)\n5: (stack b a)\n; cost = 6 (unit cost)\n",
    "moves": "move(b -> table)\nmove(a -> c)\nmove(b -> a)\n",
    "commas": "move(b, table)\nmove(a, c)\nmove(b, a)\n",
    "arrows": "b -> table\na -> c\nb -> a\n",
}


@pytest.fixture
def files(tmp_path, bw_domain_path):
    (tmp_path / "p.pddl").write_text(PROBLEM)
    return bw_domain_path, tmp_path / "p.pddl"


def _validate(files, tmp_path, text: str):
    (tmp_path / "plan.txt").write_text(text)
    return validate_files(*files, tmp_path / "plan.txt")


@pytest.mark.parametrize("kind", sorted(PLANS))
def test_validate_and_run_accept_the_same_formats(files, tmp_path, kind):
    result = _validate(files, tmp_path, PLANS[kind])
    assert result.status is ValidationStatus.VALID, result.reason
    assert [s.move for s in parse_given(PLANS[kind], "plan", THREE)] == list(MOVES)


def test_a_move_plan_fails_where_its_action_would(files, tmp_path):
    result = _validate(files, tmp_path, "move(a -> c)\nmove(b -> a)\n")  # b is on a
    assert result.status is ValidationStatus.INEXECUTABLE
    assert result.step == 1 and result.failed == ("(clear a)",)
    assert (
        result.reason == "step 1 move(a -> c) as (pick-up a): precondition (clear a) does not hold"
    )
    short = _validate(files, tmp_path, "b -> c\n")
    assert short.status is ValidationStatus.NON_GOAL_REACHING and short.length == 1


@pytest.mark.parametrize(
    ("text", "error", "message"),
    [
        ("; one\n\n(fly b)\n", ProblemError, "plan.txt: line 3: (fly b): unknown action 'fly'"),
        ("(unstack b a)\n(put-down b c)\n", ProblemError, "plan.txt: line 2: (put-down b c)"),
        ("b -> table\nmove(z -> a)\n", ProblemError, "plan.txt: line 2: move(z -> a): unknown"),
        ("(unstack b a)\nb -> c\n", PDDLError, "plan.txt: line 2: the plan mixes"),
        ("(unstack b a)\nunstack b a\n", PDDLError, "plan.txt: line 2: malformed plan line"),
    ],
)
def test_misuse_names_the_plan_file_and_line(files, tmp_path, text, error, message):
    with pytest.raises(error) as excinfo:
        _validate(files, tmp_path, text)
    assert message in str(excinfo.value) and "\n" not in str(excinfo.value)


def test_a_move_needs_the_blocksworld_actions(tmp_path):

    domain = data.read_text("logistics-strips.pddl")
    (tmp_path / "d.pddl").write_text(domain)
    name = pddl_io.parse_domain(domain).name
    problem = f"(define (problem p) (:domain {name}) (:objects a b c) (:init (obj a) (at a b)) "
    (tmp_path / "p.pddl").write_text(problem + "(:goal (at a c)))")  # read against the domain
    (tmp_path / "plan.txt").write_text("a -> c\n")
    with pytest.raises(ProblemError) as excinfo:
        validate_files(tmp_path / "d.pddl", tmp_path / "p.pddl", tmp_path / "plan.txt")
    assert "plan.txt: line 1: move(a -> c): a blocksworld move needs the 4-op" in str(excinfo.value)


def test_parse_plan_is_actions_only():
    assert pddl_io.parse_plan("0: (pick-up a) [2]\n") == (Action("pick-up", ("a",)),)
    with pytest.raises(PDDLError, match=r"plan\.txt: line 1: move\(a -> c\) is a move"):
        pddl_io.parse_plan("a -> c\n", "plan.txt")
