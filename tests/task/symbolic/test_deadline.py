"""One deadline for a whole command (`task.deadline`): grounding and the unsolvability proofs
stop when it has passed, saying so, and ``tamp plan`` reports its whole work's wall time."""

from __future__ import annotations

import json
import time
from types import SimpleNamespace

import pytest

from task.deadline import Deadline, TimeLimitReached
from task.symbolic import ground, pddl_io
from task.symbolic.proofs import prove_unsolvable

DOMAIN = """(define (domain hop)
  (:requirements :strips)
  (:predicates (at ?x) (seen ?x))
  (:action hop :parameters (?x ?y) :precondition (at ?x) :effect (and (at ?y) (seen ?y))))
"""
PASSED = Deadline(0.0, 5.0)  # a 5 s limit that ran out long ago


def hop_problem(n: int, steps: int = 5) -> str:
    """A one-action STRIPS problem of ``n`` objects (n^2 ground actions) whose plan hops
    ``steps`` times."""
    objects = " ".join(f"o{k}" for k in range(n))
    goal = " ".join(f"(seen o{k})" for k in range(1, steps + 1))
    return (
        f"(define (problem hop-{n}) (:domain hop) (:objects {objects}) (:init (at o0)) "
        f"(:goal (and {goal})))"
    )


@pytest.fixture
def files(tmp_path):
    (tmp_path / "domain.pddl").write_text(DOMAIN)
    (tmp_path / "problem.pddl").write_text(hop_problem(300))
    return str(tmp_path / "domain.pddl"), str(tmp_path / "problem.pddl")


def test_grounding_stops_when_the_deadline_has_passed(files):
    domain = pddl_io.load_domain(files[0])
    problem = pddl_io.parse_problem(hop_problem(300), "p", domain)
    looks = []

    class Counted(Deadline):
        def check(self, phase: str) -> None:
            looks.append(phase)
            super().check(phase)

    with pytest.raises(TimeLimitReached, match=r"time limit \(5 s\) reached while grounding"):
        ground.reachable(domain, problem, Counted(0.0, 5.0))
    assert looks == ["grounding"]  # it looked at once, and stopped there
    assert len(ground.reachable(pddl_io.load_domain(files[0]), parse_small()).actions) == 9


def parse_small():
    domain = pddl_io.parse_domain(DOMAIN, "d")
    return pddl_io.parse_problem(hop_problem(3, 2), "p", domain)


def test_the_proofs_stop_at_a_passed_deadline_with_a_time_limit_reason(files):
    domain = pddl_io.load_domain(files[0])
    problem = pddl_io.parse_problem(hop_problem(300), "p", domain)
    proof = prove_unsolvable(domain, problem, exhaustive=True, deadline=PASSED)
    assert not proof.unsolvable
    assert proof.reason == ("not proved unsolvable; time limit (5 s) reached while grounding")


def test_tamp_plan_stops_every_phase_at_its_time_limit_and_reports_the_wall_time(
    files, capsys, monkeypatch
):
    import tamp.cli.plan as plan_cli
    from tamp.cli import main

    real = time.perf_counter()
    clock = iter([real - 10.0, real + 32.0])  # the command's start (its 5 s long gone), end
    monkeypatch.setattr(plan_cli, "time", SimpleNamespace(perf_counter=lambda: next(clock)))
    argv = ["plan", *files, "--time-limit", "5", "--json"]
    assert main(argv) == 1
    body = json.loads(capsys.readouterr().out)
    assert body["status"] == "no_plan"
    assert body["stats"]["time_s"] == pytest.approx(42.0)  # the whole command's wall time
    assert body["stats"]["time_limit"].startswith("stopped at the 5 s time limit")
    assert "time limit (5 s) reached while grounding" in body["proof"]["reason"]


def test_the_lift_grounds_again_within_the_deadline(files):
    """The generic lift grounds the problem again for the planner (`from_files` ->
    `strips.from_pddl`): that grounding stops at the command's deadline too."""
    from task.instances import from_files

    with pytest.raises(TimeLimitReached, match=r"time limit \(5 s\) reached while grounding"):
        from_files(*files, "strips", PASSED)


def test_tamp_plan_stops_at_the_time_limit_in_the_planners_grounding(files, capsys, monkeypatch):
    """With the limit passed, the planner's grounding (not only the proofs') stops at once,
    and the output names the limit and the phase."""
    import tamp.cli.plan as plan_cli
    from tamp.cli import main

    real = time.perf_counter()
    clock = iter([real - 10.0, real + 1.0])  # the command's start (its 5 s long gone), end
    monkeypatch.setattr(plan_cli, "time", SimpleNamespace(perf_counter=lambda: next(clock)))
    assert main(["plan", *files, "--time-limit", "5"]) == 1
    out = capsys.readouterr().out
    assert out.startswith("no plan found within the time limit: stopped at the 5 s time limit")
    assert "before planning" in out and "reached while grounding" in out
