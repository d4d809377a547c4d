"""A given move that is refused before the block is lifted says nothing about a carried block
(``tamp run --plan``): the report's ``carried_to`` is empty and the step line has no
"carried block" part, where it used to print "carried block: on table"."""

from __future__ import annotations

import json

import pytest

from tamp.cli import main

# b on a, c on the table: the hand cannot reach a under b, so move(a -> c) is refused at descent
PROBLEM = """(define (problem three) (:domain blocksworld-4ops) (:objects a b c)
(:init (handempty) (ontable a) (on b a) (ontable c) (clear b) (clear c))
(:goal (and (on a c) (on b a))))
"""


@pytest.mark.sim
def test_a_move_refused_before_the_lift_reports_no_carried_block(tmp_path, capsys):
    (tmp_path / "p.pddl").write_text(PROBLEM)
    (tmp_path / "plan.txt").write_text("a -> c\n")
    argv = ["run", str(tmp_path / "p.pddl"), "--plan", str(tmp_path / "plan.txt"), "--no-video"]
    code = main([*argv, "--out", str(tmp_path / "out")])
    printed = capsys.readouterr()
    (step,) = json.loads((tmp_path / "out" / "report.json").read_text())["steps"]
    assert code == 1 and step["attempted"] and step["outcome"] != "executed"
    assert step["carried_to"] == ""
    assert "1 move(a -> c)" in printed.err + printed.out
    assert "carried block" not in printed.err + printed.out
