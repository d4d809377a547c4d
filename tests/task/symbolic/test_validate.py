"""The crisp validator: valid plans, the first failing step and atom, unreached goal atoms."""

from __future__ import annotations

import pytest

from task.errors import ProblemError
from task.problem import Action
from task.symbolic import pddl_io, validate
from task.symbolic.validate import ValidationStatus

# b on a; c on the table; goal: a on b on c.
PROBLEM = """(define (problem v) (:domain blocksworld-4ops)
(:objects a b c)
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a b) (on b c))))
"""
PLAN = (
    Action("unstack", ("b", "a")),
    Action("stack", ("b", "c")),
    Action("pick-up", ("a",)),
    Action("stack", ("a", "b")),
)


@pytest.fixture
def pair(bw_domain_path):
    domain = pddl_io.load_domain(bw_domain_path)
    return domain, pddl_io.parse_problem(PROBLEM, "v.pddl", domain)


def test_valid_plan(pair):
    result = validate.validate(*pair, PLAN)
    assert result.valid
    assert result.status is ValidationStatus.VALID
    assert (result.step, result.failed, result.length) == (None, (), 4)


def test_unmet_precondition_names_step_and_atom(pair):
    plan = (PLAN[0], Action("stack", ("b", "c")), Action("stack", ("a", "b")))
    result = validate.validate(*pair, plan)
    assert result.status is ValidationStatus.INEXECUTABLE
    assert not result.valid
    assert result.step == 3
    assert result.failed == ("(holding a)",)
    assert result.reason == "step 3 (stack a b): precondition (holding a) does not hold"


def test_several_unmet_preconditions(pair):
    result = validate.validate(*pair, (PLAN[0], Action("unstack", ("c", "a"))))
    assert (result.step, result.failed) == (2, ("(handempty)", "(on c a)"))
    assert result.reason == "step 2 (unstack c a): preconditions (handempty), (on c a) do not hold"


def test_plan_that_stops_early(pair):
    result = validate.validate(*pair, PLAN[:2])
    assert result.status is ValidationStatus.NON_GOAL_REACHING
    assert result.step is None
    assert result.failed == ("(on a b)",)
    assert result.reason == "goal atoms not reached: (on a b)"
    empty = validate.validate(*pair, ())
    assert empty.failed == ("(on a b)", "(on b c)") and empty.length == 0


def test_unknown_block_in_plan_raises(pair):
    with pytest.raises(ProblemError) as excinfo:
        validate.validate(*pair, (*PLAN, Action("pick-up", ("z",))))
    message = str(excinfo.value)
    assert "\n" not in message
    assert "unknown object 'z' (valid: a, b, c)" in message


def test_validate_files(bw_domain_path, tmp_path):
    problem = tmp_path / "p.pddl"
    problem.write_text(PROBLEM)
    plan = pddl_io.write_plan(PLAN, tmp_path / "plan.txt")
    assert validate.validate_files(bw_domain_path, problem, plan).valid
    pddl_io.write_plan(PLAN[1:], plan)
    result = validate.validate_files(bw_domain_path, problem, plan)
    assert (result.status, result.step) == (ValidationStatus.INEXECUTABLE, 1)
