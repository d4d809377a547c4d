"""Plan a PlanBench-style Blocksworld problem from Python and check the plan.

PlanBench's Blocksworld instances are PDDL problems over the 4-operator domain (pick-up,
put-down, stack, unstack). The soft-T_P planner optimises action logits, decodes a plan, and
`tamp.api.plan` replays it through the crisp validator, so ``planned.valid`` is the official
verdict. Run: ``python examples/plan_pddl.py`` (about 2 s).
"""

from __future__ import annotations

from tamp import api

# A PlanBench-style instance (generated_basic style): 4 blocks, a partial goal.
PROBLEM = """
(define (problem bw-4)
  (:domain blocksworld-4ops)
  (:objects a b c d)
  (:init (handempty) (ontable a) (on b a) (clear b) (ontable c) (on d c) (clear d))
  (:goal (and (on a d) (on c b))))
"""


def main() -> None:
    task = api.load_problem(PROBLEM)  # PDDL text; api.load_problem(Path(...)) reads a file
    print(f"{task.name}: {task.problem.n} blocks, domain rules {task.problem.domain!r}")
    planned = api.plan(task, seed=0)
    print(planned.text(), end="")
    print(f"{planned.status.value}: {planned.validation.reason}")
    print(f"{len(planned.moves)} moves: {', '.join(str(m) for m in planned.moves)}")
    print(f"planning took {planned.result.stats['time_s']:.2f} s")

    # any plan, from anywhere, against the same PDDL: the first failing step and why
    bad = "(unstack b a)\n(stack b c)\n"
    verdict = api.validate(task, bad)
    print(f"a hand-written plan: {verdict.status.value}: {verdict.reason}")
    assert planned.valid and not verdict.valid


if __name__ == "__main__":
    main()
