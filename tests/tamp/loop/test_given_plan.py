"""Given plans (`tamp.loop.given`, ``tamp run --plan``): plan files read into steps with
one-line errors, then executed open-loop in PyBullet: a valid plan reaches the goal; a plan that
stacks onto a block that is not clear is reported at its first invalid step, attempted
physically, and not attempted with ``--stop-at-invalid`` (the experimenter's ground-truth grant,
named as such)."""

from __future__ import annotations

import json

import pytest

from tamp.cli import main
from tamp.loop import EpisodeStatus, LoopConfig
from tamp.loop.given import GivenPlanEpisode, parse_given
from task.errors import TampError
from task.problem import TABLE, Move, Problem

# b on a, c on the table; goal: the tower c-a-b
THREE = Problem(
    "three", "blocksworld", ("a", "b", "c"), (TABLE, "a", TABLE), (("a", "c"), ("b", "a"))
)
PROBLEM = """(define (problem three) (:domain blocksworld-4ops) (:objects a b c)
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a c) (on b a))))
"""
VALID = (
    "; a valid plan\n(unstack b a)\n(put-down b)\n0: (pick-up a)\n1: (stack a c)\n"
    "(pick-up b)\n(stack b a)\n; cost = 6 (unit cost)\n"
)
ONTO_NOT_CLEAR = "(pick-up c)\n(stack c a)\n"  # b is on a


def test_actions_pair_into_moves_and_moves_are_read_as_written():
    steps = parse_given(VALID, "plan", THREE)
    assert [s.move for s in steps] == [Move("b", TABLE), Move("a", "c"), Move("b", "a")]
    assert [s.number for s in steps] == [1, 3, 5]
    moves = parse_given("move(b -> table)\nmove(a, c)\nb -> a\n", "plan", THREE)
    assert [s.move for s in moves] == [s.move for s in steps]


def test_actions_that_do_not_pair_end_the_plan_with_the_reason():
    steps = parse_given("(pick-up c)\n(pick-up b)\n(put-down b)\n", "plan", THREE)
    assert len(steps) == 1 and steps[0].move is None
    assert "the hand holds c" in steps[0].reason


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("; nothing\n\n", "plan: the plan is empty"),
        ("(pick-up a)\n(stack a c\n", "plan: line 2: malformed plan line '(stack a c'"),
        ("(grab a)\n", "plan: line 1: unknown action 'grab' (valid: pick-up, unstack, put-down"),
        ("(pick-up d)\n(stack d e)\n", "names blocks not in problem three: d, e (its blocks: a"),
        ("move(a -> z)\n", "names blocks not in problem three: z"),
        ("(pick-up a b)\n", "plan: line 1: (pick-up a b): pick-up takes 1 arguments"),
        ("(pick-up a)\na -> c\n", "plan: line 2: the plan mixes 4-op actions and moves"),
    ],
)
def test_bad_plan_text_gives_one_line_errors(text, message):
    with pytest.raises(TampError) as err:
        parse_given(text, "plan", THREE)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_a_missing_plan_file_is_a_one_line_usage_error(tmp_path, capsys):
    (tmp_path / "p.pddl").write_text(PROBLEM)
    code = main(["run", str(tmp_path / "p.pddl"), "--plan", str(tmp_path / "nope.txt")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "nope.txt: no such file" in err


def _run(tmp_path, plan: str, *options: str) -> tuple[int, dict]:
    (tmp_path / "p.pddl").write_text(PROBLEM)
    (tmp_path / "plan.txt").write_text(plan)
    argv = ["run", str(tmp_path / "p.pddl"), "--plan", str(tmp_path / "plan.txt"), "--no-video"]
    code = main([*argv, "--json", "--out", str(tmp_path / "out"), *options])
    return code, json.loads((tmp_path / "out" / "report.json").read_text())


@pytest.mark.sim
def test_a_valid_given_plan_executes_and_reaches_the_goal(tmp_path):
    code, report = _run(tmp_path, VALID)
    assert code == 0 and report["reached_goal"] and report["status"] == "goal_reached"
    assert [s["valid"] for s in report["steps"]] == [True, True, True]
    assert [s["outcome"] for s in report["steps"]] == ["executed"] * 3
    assert [s["carried_to"] for s in report["steps"]] == [TABLE, "c", "a"]
    assert report["replans"] == 0 and report["config"]["plan"].endswith("plan.txt")


@pytest.mark.sim
def test_stacking_onto_a_block_that_is_not_clear_is_reported_and_still_attempted(tmp_path):
    code, report = _run(tmp_path, ONTO_NOT_CLEAR)
    (step,) = report["steps"]
    assert code == 1 and not report["reached_goal"]
    assert step["number"] == 1 and step["valid"] is False and step["failed"] == ["(clear a)"]
    assert step["reason"] == "step 2 (stack c a): precondition (clear a) does not hold"
    assert step["attempted"] and len(report["moves"]) == 1
    assert report["status"] == EpisodeStatus.PLAN_ENDED.value


@pytest.mark.sim
def test_stop_at_invalid_does_not_attempt_the_invalid_step(tmp_path):
    code, report = _run(tmp_path, ONTO_NOT_CLEAR, "--stop-at-invalid")
    (step,) = report["steps"]
    assert code == 1 and report["status"] == EpisodeStatus.INVALID_PLAN.value
    assert step["failed"] == ["(clear a)"] and not step["attempted"]
    assert step["outcome"] == "not attempted" and report["moves"] == []


@pytest.mark.sim
@pytest.mark.parametrize("stop", [True, False])
def test_stop_at_invalid_is_the_experimenters_grant_not_a_scoring_read(stop):
    """Whether the robot attempts a step is decided from the true state only under the
    experimenter's grant, and only with ``stop_at_invalid``; the report names who decided and
    counts the reads by grant."""
    steps = parse_given(ONTO_NOT_CLEAR, "plan", THREE)
    episode = GivenPlanEpisode(THREE, steps, LoopConfig(), seed=0, stop_at_invalid=stop)
    report = episode.run()
    deciders = {c for g, c in episode.sim.truth.reads if g == "experimenter"}
    (step,) = report.steps
    if stop:
        assert deciders == {"tamp.loop.given.GivenPlanEpisode._experimenter_skips"}
        assert step.skipped_by == "experimenter" and not step.attempted
        assert "experimenter grant --stop-at-invalid" in step.line()
        assert "experimenter" in report.reason and report.truth_reads["experimenter"] == 1
    else:
        assert deciders == set() and step.attempted and step.skipped_by == ""
        assert "experimenter" not in report.truth_reads


@pytest.mark.sim
@pytest.mark.parametrize(
    "plan",
    ["(unstack b a)\n(pick-up c)\n", "b -> c\na -> b\n"],  # actions that do not pair; a wrong plan
)
def test_with_replan_the_planner_takes_over_and_reaches_the_goal(tmp_path, plan):
    code, report = _run(tmp_path, plan, "--replan")
    assert code == 0 and report["reached_goal"] and report["replans"] == 1
    assert len(report["plans"]) == 2  # the given plan, then the planner's
