"""Score your own plan at motion level: task-level validity beside what the arm physically does.

A plan from any source (a language model, another planner, a hand-written file) is checked by
the crisp validator, then executed open-loop by the simulated Panda (``tamp run --plan``). Each
step reports its task-level verdict, the motion outcome, the blocks that moved as a side effect
and where the carried block came to rest. Here the second step stacks onto a block that is not
clear; the collision check refuses it before the arm moves. Run:
``python examples/score_my_plan.py [pybullet|mujoco]`` (about 10 s, headless).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from tamp import api

PROBLEM = """
(define (problem mine)
  (:domain blocksworld-4ops)
  (:objects a b c)
  (:init (handempty) (ontable a) (on b a) (clear b) (ontable c) (clear c))
  (:goal (and (on c a) (on a b))))
"""
# what a planner that forgets (clear a) might write: (stack c a) while b is still on a
MY_PLAN = """
(pick-up c)
(stack c a)
(unstack b a)
(put-down b)
"""


def main(sim: str = "pybullet") -> None:
    task = api.load_problem(PROBLEM)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "my.plan"
        path.write_text(MY_PLAN)
        verdict = api.validate(task, path)  # a file: pathlib.Path
        print(f"task level: {verdict.status.value}: {verdict.reason}")
        report = api.execute_plan(task, path, sim=sim, seed=0)
    for step in report.steps:
        print(f"  {step.line()}")
    print(f"{sim}: {report.status.value}; goal reached (ground truth): {report.reached_goal}")
    print(f"disturbed stacks: {report.disturbed}; collisions: {report.touched or 'none'}")
    ours = api.plan(task)  # what our planner makes of the same problem, for comparison
    print(f"ours: {ours.validation.reason}: {', '.join(str(m) for m in ours.moves)}")
    print("execute it the same way: api.execute_plan(task, ours.actions, sim=sim)")
    assert not verdict.valid and not report.reached_goal and ours.valid


if __name__ == "__main__":
    main(*sys.argv[1:2])
