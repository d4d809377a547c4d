"""The executability benchmark (``tamp bench executability``): plans of any source, executed
open-loop in the simulators.

`read_sources` reads the plans (a CSV per source, as in ../shared/data/planbench/llm_plans);
`run_given` checks each at task level (`check_given`) and executes it open-loop
(`tamp.loop.given`) in each simulator, our planner's plans as the reference row
(`our_plans`; with ``--motion-aware`` planned with the arm's cost of each move on the very
layout the episode starts from, their moves onto the table carrying the places chosen). Per
plan: our verdict and PlanBench's, the goal reached (ground truth), the first failure,
disturbed stacks, moves, time (`PlanRow`); `given_summary` per source. The instances are those
the plan files name (`named`); a source without a plan for one of them gets a ``no-plan`` row.
Runs sweep with `tamp.sweep.run_items`.
"""

from __future__ import annotations

import csv
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from motion.ik import IKSolver
from robots.panda import PANDA
from tamp.arm.arm import Arm
from tamp.bench.suites import Suite
from tamp.loop import LoopConfig
from tamp.loop.given import GivenPlanEpisode, StepReport, parse_given
from tamp.rerun_log import recorder_for
from tamp.scene import PlacedMove, layout
from tamp.slots import plan_on_places
from tamp.sweep import run_items, torch_threads
from task.config import PlannerConfig
from task.domains import get_domain
from task.errors import DataError, TampError
from task.instances import Instance
from task.planner import plan_batch
from task.symbolic.validate import validate

OURS = "ours"  # the reference row: our planner's plans, executed the same way
NO_PLAN = "no-plan"  # a source names no plan for an instance another source names
UNPARSEABLE = "unparseable"
Sources = dict[str, dict[str, tuple[str, bool | None]]]


@dataclass(frozen=True)
class PlanRow:
    """A plan of a source executed open-loop in one simulator (a ``plans.csv`` row)."""

    source: str
    sim: str
    problem: str
    task: str  # our validator's status, "unparseable" or "no-plan" (``error`` says why)
    planbench_valid: bool | None  # the source's own verdict (None: none given)
    reached_goal: bool
    first_failure: str  # "" when none (`first_failure`)
    failure_at: str  # the step's label
    disturbed: int  # steps after which another block had moved
    moves: int  # steps attempted physically
    wall_time_s: float
    error: str


def read_sources(path: str | Path) -> Sources:
    """``{source: {instance: (plan, PlanBench verdict)}}`` of a CSV (source: its stem) or folder
    of CSVs: ``file`` (``instances/<name>.pddl``), ``plan`` (``;``-joined), ``llm_correct``."""
    root = Path(path)
    files = sorted(root.glob("*.csv")) if root.is_dir() else [root] if root.exists() else []
    if not files:
        raise DataError(f"--plans {root}: no such CSV file, or no *.csv files in the folder")
    out = {}
    for f in files:
        try:
            with f.open(newline="", encoding="utf-8") as handle:
                out[f.stem if f.stem != OURS else f"{OURS} (csv)"] = _read_csv(f, handle)
        except UnicodeDecodeError:
            raise DataError(f"--plans {f}: not a text CSV file (not UTF-8)") from None
    return out


def _read_csv(f: Path, handle) -> dict[str, tuple[str, bool | None]]:
    reader = csv.DictReader(handle)
    missing = [c for c in ("file", "plan") if c not in (reader.fieldnames or ())]
    if missing:
        raise DataError(f"{f}: missing column(s) {', '.join(missing)} (file, plan)")
    plans = {}
    for row in reader:
        flag = (row.get("llm_correct") or "").strip()
        name = (row["file"] or "").strip().removeprefix("instances/").removesuffix(".pddl")
        plans[name] = (row["plan"] or "", None if not flag else flag == "1")
    return plans


def named(sources: Sources) -> tuple[str, ...]:
    """Every instance some source has a row for, in first-seen order."""
    return tuple(dict.fromkeys(name for got in sources.values() for name in got))


def our_plans(
    suite: Suite, config: PlannerConfig, seed: int, base: LoopConfig = LoopConfig()
) -> dict[str, tuple[str, tuple]]:
    """Our planner's plan of every instance: ``{instance: (4-op action lines, moves)}`` (empty:
    no plan found). With ``config.lambda_motion`` > 0 each instance is planned with the arm's
    cost of each move (`tamp.slots.plan_on_places`) on the layout its episode starts from
    (``base.scene``, episode seed ``seed * 100_003 + k``, the arm at home), continuous
    placements within ``base.placements`` m: its moves onto the table carry their places.
    Without, the suite is planned in one batch, task only."""
    problems = [i.problem for i in suite.instances]
    if config.lambda_motion > 0:
        solver, scene = IKSolver(), base.scene  # one for every instance
        results = []
        for k, problem in enumerate(problems):
            poses = layout(problem.entities, problem.init, scene, seed * 100_003 + k)
            results.append(
                plan_on_places(
                    problem,
                    poses,
                    scene,
                    Arm(solver, PANDA.q_home),
                    config,
                    seed,
                    reach=base.placements,
                )
            )
    else:
        results = plan_batch(problems, config, seed)
    out = {}
    for inst, result in zip(suite.instances, results, strict=True):
        moves = result.plan.moves if result.solved else ()
        actions = get_domain(inst.problem.domain).to_actions(inst.problem, moves, strict=False)
        out[inst.name] = ("\n".join(map(str, actions)), tuple(moves))
    return out


def check_given(text: str | None, instance: Instance, domain, source: str):
    """``(steps, task status, error)``; ``(None, "no-plan", why)`` when ``source`` has no row for
    the instance, ``(None, "unparseable", error)`` for an empty or malformed plan (actions
    after an unpaired pick/put are dropped: invalid before anyway)."""
    if text is None:
        return None, NO_PLAN, f"{source}: no plan for {instance.name}"
    try:
        steps = parse_given(text.replace(";", "\n"), f"{source} {instance.name}", instance.problem)
        moves, rules = [s.move for s in steps], get_domain(instance.problem.domain)
        actions = [a for s in steps for a in s.actions] or rules.to_actions(
            instance.problem, moves, strict=False
        )
        verdict = validate(domain, instance.pddl, actions)
    except TampError as exc:
        return None, UNPARSEABLE, str(exc)
    return steps, verdict.status.value, "" if verdict.valid else verdict.reason


def first_failure(steps: Sequence[StepReport], reached: bool) -> tuple[str, str]:
    """``(kind, label)`` of the first step invalid at task level ("invalid-then-<outcome>"), not
    attempted ("unpaired-actions") or failed (its kind); else "goal-not-reached" or none."""
    for s in steps:
        if not s.attempted:
            return "unpaired-actions", s.label
        if s.valid is False:
            return f"invalid-then-{s.outcome}", s.label
        if s.outcome != "executed":
            return s.outcome, s.label
    return ("", "") if reached else ("goal-not-reached", "end")


def _placed(steps: tuple | None, moves: Sequence) -> tuple | None:
    """Our plan's parsed steps with the planned moves (their table places) put back."""
    if steps is None or not moves:
        return steps
    planned = iter(moves)
    return tuple(s if s.move is None else replace(s, move=next(planned)) for s in steps)


def run_given(
    suite: Suite,
    sources: Sources,
    base: LoopConfig,
    sims: Sequence[str],
    seed: int,
    ours: PlannerConfig | None,
    progress: Callable | None = None,
    workers: int = 1,
    ray_address: str | None = None,
    record: str | None = None,
) -> list:
    """`PlanRow` of every source's plan of every instance in each simulator. Instance ``k`` uses
    episode seed ``seed * 100_003 + k`` (its layout) for every source; a plan met before on the
    same instance and simulator (the same steps, table places included) is run once (the rows
    share its outcome, time included): the distinct runs are the sweep's items. ``ours``: our
    planner's row (`our_plans`, with ``base``'s scene and placements). ``progress(sim, row)``
    as each row is done. ``record``: a folder, each run a Rerun recording under it named by
    the instance and the first source that has the plan (`tamp.rerun_log.recorder_for`)."""
    mine = {} if ours is None else our_plans(suite, ours, seed, base)
    plans: dict[str, Mapping] = {**sources, **({OURS: mine} if ours is not None else {})}
    checked = {}
    for src, got in plans.items():
        for i in suite.instances:
            steps, task, error = check_given(got.get(i.name, (None,))[0], i, suite.domain, src)
            if src == OURS and ours is not None:
                steps = _placed(steps, mine[i.name][1])
            checked[src, i.name] = steps, task, error
    specs, runs, waiting, unrun = [], {}, {}, []  # rows' given columns; runs
    for sim in sims:
        config = replace(base, sim=sim)
        for k, inst in enumerate(suite.instances):
            for src, got in plans.items():
                steps, task, error = checked[src, inst.name]
                verdict = got.get(inst.name, ("", None))[1] if src != OURS else None
                if steps is None:  # nothing to execute: its row is written at once
                    unrun.append(len(specs))
                else:
                    key = (sim, k, tuple((s.label, _at(s.move)) for s in steps))
                    named = (record, f"{inst.name}-{src}")
                    runs.setdefault(key, (inst.problem, steps, config, seed * 100_003 + k, named))
                    waiting.setdefault(key, []).append(len(specs))
                specs.append((src, sim, inst.name, task, verdict, error))
    rows, keys = [None] * len(specs), list(runs)

    def fill(j: int, outcome: tuple) -> None:
        *head, error = specs[j]
        rows[j] = PlanRow(*head, *outcome, error)
        if progress is not None:
            progress(head[1], rows[j])

    for j in unrun:
        fill(j, (False, specs[j][3], "", 0, 0, 0.0))
    run_items(
        _given,
        runs.values(),
        workers,
        ray_address,
        lambda i, outcome: [fill(j, outcome) for j in waiting[keys[i]]],
    )
    return rows


def _given(item: tuple) -> tuple:
    """`run_given`'s run ``(problem, steps, config, seed, (record, name))``: its row's outcome
    columns."""
    *episode, (record, name) = item
    recorder = recorder_for(record, episode[2].sim, name)
    with torch_threads(1):  # one small problem: thread hand-offs cost more than they give
        r = GivenPlanEpisode(*episode, recorder=recorder).run()
    return (
        r.reached_goal,
        *first_failure(r.steps, r.reached_goal),
        sum(bool(s.disturbed) for s in r.steps),
        sum(s.attempted for s in r.steps),
        r.wall_time_s,
    )


def given_summary(rows: Sequence[PlanRow], sims: Sequence[str]) -> list[dict]:
    """Per source: plans, task-valid, unparseable, no plan, PlanBench-valid, agreement (None: no
    verdicts); per sim the goals reached, top 3 first failures, disturbed stacks, s/plan (mean
    over the plans executed)."""
    out = []
    for src in dict.fromkeys(r.source for r in rows):
        mine = [r for r in rows if r.source == src]
        first = [r for r in mine if r.sim == sims[0]]
        pb = [r for r in first if r.planbench_valid is not None]
        by = {s: [r for r in mine if r.sim == s] for s in sims}
        ran = {s: [r for r in b if r.task not in (UNPARSEABLE, NO_PLAN)] for s, b in by.items()}
        out.append(
            {
                "source": src,
                "plans": len(first),
                "task_valid": sum(r.task == "valid" for r in first),
                "unparseable": sum(r.task == UNPARSEABLE for r in first),
                "no_plan": sum(r.task == NO_PLAN for r in first),
                "planbench_valid": sum(r.planbench_valid for r in pb) if pb else None,
                "agree": sum((r.task == "valid") == r.planbench_valid for r in pb) if pb else None,
                "reached": {s: sum(r.reached_goal for r in b) for s, b in by.items()},
                "failures": {
                    s: dict(Counter(r.first_failure for r in b if r.first_failure).most_common(3))
                    for s, b in by.items()
                },
                "disturbed": {s: sum(r.disturbed for r in b) for s, b in by.items()},
                "s_per_plan": {
                    s: sum(r.wall_time_s for r in b) / max(len(b), 1) for s, b in ran.items()
                },
            }
        )
    return out


def _at(move) -> tuple[float, float] | None:
    """The table position a move names (`PlacedMove.at`), None for a plain move."""
    return move.at if isinstance(move, PlacedMove) else None
