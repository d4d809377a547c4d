"""Our validator agrees with unified-planning's independent SequentialPlanValidator.

Valid plans and deliberately broken ones (two actions swapped, one dropped, wrong arguments,
cut short) on generated problems (optimal plans and plans the soft planner produced) and, with
../shared, on PlanBench instances with their reference plans. Both must agree on valid/invalid,
on why, and on the failing step. unified-planning comes with the dev extras; without it the
whole file is skipped with a reason that says so.
"""

from __future__ import annotations

import json
import random

import pytest

from task.config import PlannerConfig
from task.domains import blocksworld as bw
from task.planner import plan_batch
from task.problem import Action
from task.symbolic import generate, pddl_io, search, validate
from task.symbolic.validate import ValidationStatus

up = pytest.importorskip(
    "unified_planning",
    reason="unified-planning is not installed (pip install -e '.[dev]'): "
    "no independent validator to compare ours with",
)
from unified_planning.engines import SequentialPlanValidator  # noqa: E402
from unified_planning.engines.results import FailedValidationReason  # noqa: E402
from unified_planning.io import PDDLReader  # noqa: E402
from unified_planning.shortcuts import get_environment  # noqa: E402


def _variants(plan: tuple[Action, ...], objects: tuple[str, ...], seed: int):
    """The plan itself and broken copies of it, each tagged with how it was broken."""
    rng = random.Random(seed)
    yield "valid", plan
    if len(plan) >= 2:
        i = rng.randrange(len(plan) - 1)
        yield "swap", (*plan[:i], plan[i + 1], plan[i], *plan[i + 2 :])
        j = rng.randrange(len(plan))
        yield "drop", plan[:j] + plan[j + 1 :]
    k = rng.randrange(len(plan))
    args = list(plan[k].args)
    args[-1] = rng.choice([o for o in objects if o != args[-1]])
    yield "args", (*plan[:k], Action(plan[k].name, tuple(args)), *plan[k + 1 :])
    yield "short", plan[:-1]


def _cross_check(
    domain_text: str, problem_text: str, plan: tuple[Action, ...], seed: int
) -> dict[str, bool]:
    """Validate ``plan`` and its broken variants with both validators; {kind: valid}."""
    domain = pddl_io.parse_domain(domain_text)
    problem = pddl_io.parse_problem(problem_text, domain=domain)
    up_problem = PDDLReader().parse_problem_string(domain_text, problem_text)
    objects = pddl_io.object_order(problem_text)
    engine = SequentialPlanValidator()
    outcomes = {}
    for kind, variant in _variants(plan, objects, seed):
        ours = validate.validate(domain, problem, variant)
        up_plan = PDDLReader().parse_plan_string(up_problem, pddl_io.format_plan(variant))
        theirs = engine.validate(up_problem, up_plan)
        context = f"{kind}: {ours.reason} vs {theirs.log_messages}"
        assert ours.valid == bool(theirs.status), context
        if ours.status is ValidationStatus.INEXECUTABLE:
            assert theirs.reason is FailedValidationReason.INAPPLICABLE_ACTION, context
            assert ours.step == len(theirs.trace), context  # the trace holds states before it
        elif ours.status is ValidationStatus.NON_GOAL_REACHING:
            assert theirs.reason is FailedValidationReason.UNSATISFIED_GOALS, context
        outcomes[kind] = ours.valid
    assert outcomes["valid"] and not all(outcomes.values())
    return outcomes


@pytest.fixture(autouse=True)
def _quiet_up():
    env = get_environment()
    previous = env.credits_stream
    env.credits_stream = None
    yield
    env.credits_stream = previous


@pytest.mark.parametrize(("n_blocks", "seed"), [(3, 0), (4, 1), (4, 2), (5, 3), (6, 4), (7, 5)])
def test_agrees_on_generated_problems(bw_domain_path, n_blocks, seed):
    problem = generate.random_problem(n_blocks, seed)
    plan = bw.moves_to_actions(problem, search.optimal_moves(problem))
    _cross_check(bw_domain_path.read_text(), bw.to_pddl(problem), plan, seed)


PLANNED = ((3, 11), (4, 12), (5, 13))  # (blocks, seed) of problems the soft planner solves


@pytest.fixture(scope="module")
def planned():
    """Problems and the soft planner's results for them (one batched call)."""
    problems = [generate.random_problem(n, seed) for n, seed in PLANNED]
    return problems, plan_batch(problems, PlannerConfig(restarts=4, iters=40), seed=0)


@pytest.mark.parametrize("index", range(len(PLANNED)))
def test_agrees_on_plans_the_soft_planner_produced(bw_domain_path, planned, index):
    problem, result = planned[0][index], planned[1][index]
    assert result.solved and len(result.plan) >= 2, result.status
    plan = bw.moves_to_actions(problem, result.plan.moves)
    outcomes = _cross_check(bw_domain_path.read_text(), bw.to_pddl(problem), plan, index)
    # the plan itself is valid; a swapped pair, a dropped step and a cut-short plan are not
    assert outcomes["valid"] and not any(outcomes[k] for k in ("swap", "drop", "short"))


@pytest.mark.shared
def test_agrees_on_planbench_reference_plans(planbench_dir):
    root = planbench_dir / "blocksworld"
    info = json.loads((root / "info.json").read_text())
    domain_text = (root / "domain.pddl").read_text()
    names = sorted(info, key=lambda n: int(n.split("-")[1].split(".")[0]))
    for seed, name in enumerate(names[::25][:20]):
        problem_text = (root / "instances" / "generated_basic" / name).read_text()
        plan = pddl_io.parse_plan(info[name]["plan"], name)
        _cross_check(domain_text, problem_text, plan, seed)
