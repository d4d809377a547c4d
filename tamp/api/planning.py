"""Planning in `tamp.api`: `plan` (the soft-T_P planner, then the crisp validator), `validate`
(a plan from any source against a problem's PDDL) and `PlanReport`, a planned problem and its
verdict, made by `validated_report` (also the verdict of a plan from images)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from tamp.api.args import COSTS, INT, PLAN, PLANNER_CONFIG, SOURCE, checked
from tamp.api.problems import PROBLEM, PddlTask, PlanSource, Source, as_task
from task.config import PlannerConfig
from task.costs import CostSource
from task.domains import get_domain
from task.problem import Action, Move, PlanResult, PlanStatus, Problem
from task.symbolic import pddl_io
from task.symbolic.validate import Validation
from task.symbolic.validate import validate as _validate
from task.symbolic.validate import validate_lines as _validate_lines


@dataclass(frozen=True)
class PlanReport:
    """A planned problem and its verdict.

    ``result`` is the planner's `PlanResult` with ``validation`` filled in (what
    `task.planner.plan` leaves None): the plan's PDDL ``actions`` replayed by
    `task.symbolic.validate` against the task's own PDDL. A plan the planner did not finish
    (``NO_PLAN``, ``UNSOLVABLE``) validates as ``non_goal_reaching``. ``result.stats`` has
    ``time_s`` (wall seconds) and ``windows`` (receding windows planned)."""

    task: PddlTask
    result: PlanResult
    actions: tuple[Action, ...]

    @property
    def status(self) -> PlanStatus:
        return self.result.status

    @property
    def moves(self) -> tuple[Move, ...]:
        """The plan as the domain's moves (Blocksworld: ``move(a -> b)``)."""
        return self.result.plan.moves

    @property
    def validation(self) -> Validation:
        return self.result.validation

    @property
    def valid(self) -> bool:
        """The plan is executable and reaches the goal, by the crisp validator."""
        return self.result.validation.valid

    def text(self) -> str:
        """The plan file: one ``(action args)`` per line, then ``; cost = N (unit cost)``
        (the VAL / Fast Downward format ``tamp validate`` and ``tamp run --plan`` read)."""
        return pddl_io.format_plan(self.actions)


def validated_report(task: PddlTask, result: PlanResult) -> PlanReport:
    """``result`` with its validation against ``task``'s PDDL (illegal moves translated as
    they stand, so the validator names the first failing step)."""
    rules = get_domain(task.problem.domain)
    actions = tuple(rules.to_actions(task.problem, result.plan.moves, strict=False))
    verdict = _validate(task.domain, task.instance.pddl, actions)
    return PlanReport(task, replace(result, validation=verdict), actions)


@checked(
    problem=PROBLEM,
    domain=SOURCE.optional(),
    config=PLANNER_CONFIG.optional(),
    seed=INT,
    costs=COSTS.optional(),
)
def plan(
    problem: PddlTask | Problem | Source,
    domain: Source | None = None,
    *,
    config: PlannerConfig | None = None,
    seed: int = 0,
    costs: CostSource | None = None,
) -> PlanReport:
    """Plan one problem with the soft-T_P planner and validate the plan.

    ``problem``: a `PddlTask` (`load_problem`), a `Problem`, or PDDL text / a file of
    ``domain`` (see `load_problem`). ``config``: the planner's settings (None: the defaults
    with the domain's own, `PlannerConfig.for_domain`). ``costs``: move costs in the objective
    (a `CostSource`, e.g. `CostFunction`), weighted by ``config.lambda_motion`` (0.05 when
    ``costs`` is given and ``config`` is None). ``seed`` seeds the restarts' initial logits."""
    from task.planner import plan as soft_plan

    task = as_task(problem, domain)
    if config is None:
        weight = {"lambda_motion": 0.05} if costs is not None else {}
        config = PlannerConfig.for_domain(task.problem.domain, **weight)
    return validated_report(task, soft_plan(task.problem, config, seed, costs=costs))


@checked(problem=PROBLEM, plan=PLAN, domain=SOURCE.optional())
def validate(
    problem: PddlTask | Problem | Source, plan: PlanSource, domain: Source | None = None
) -> Validation:
    """Check a plan from any source against a problem's PDDL: valid, or the first failing step
    and why (``Validation.step``, 1-based; ``reason``; ``failed`` atoms). ``plan``: plan text
    (``str``), a plan file (`pathlib.Path`), or the steps (`Action` or Blocksworld `Move`, or
    their text: ``["(unstack c b)", "(put-down c)"]``)."""
    task = as_task(problem, domain)
    if not isinstance(plan, str | Path) and any(isinstance(step, str) for step in plan):
        plan = "\n".join(str(step) for step in plan)  # steps as strings: read as plan text
    if isinstance(plan, str | Path):
        text, label = (
            (pddl_io.read_text(plan), str(plan)) if isinstance(plan, Path) else (plan, "<plan>")
        )
        lines = pddl_io.parse_plan_lines(text, label)
        return _validate_lines(task.domain, task.instance.pddl, lines, label)
    return _validate(task.domain, task.instance.pddl, plan)
