"""The motion benchmarks: how executable task plans are at motion level.

``tamp bench motion``: `run` plays closed-loop episodes (`tamp.loop`) on a suite in each
simulator; `summarise` gives per simulator plans valid, executed moves valid, moves, goals
reached (ground truth), failures by kind, replans, disturbed stacks, time per move, recovery.

"Valid" is a replay through `task.symbolic.validate` against the instance's PDDL problem
(`tamp.bench.planning.replay`), never the planner's own flag: "plans valid" replays the first
complete task plan (not applicable with the camera, whose first plan is one window), "executed
moves valid" the moves that executed ok, in order (every step applicable, the goal at the end).

``tamp bench executability``: `run_given` executes plans of any source (`read_sources`) open-
loop (`tamp.loop.given`) in each simulator, ours as the reference row: per plan our verdict and
PlanBench's, the goal reached (ground truth), the first failure, disturbed stacks, moves, time
(`PlanRow`); `given_summary` per source. Both sweep with `tamp.sweep.run_items`.
"""

from __future__ import annotations

import csv
import dataclasses
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from motion.ik import IKSolver, top_down_pose
from tamp.bench.planning import replay
from tamp.bench.suites import Suite
from tamp.loop import EpisodeReport, LoopConfig, run_episode
from tamp.loop.given import GivenPlanEpisode, StepReport, parse_given
from tamp.sweep import process_solver, run_items
from task.config import PlannerConfig
from task.domains import get_domain
from task.errors import DataError, TampError
from task.instances import Instance
from task.planner import plan_batch
from task.symbolic.validate import validate

EPISODE_COLUMNS = (
    "sim",
    "problem",
    "status",
    "reached_goal",
    "moves",
    "moves_ok",
    "replans",
    "faults",
    "disturbed",
    "touched",
    "sim_time_s",
    "wall_time_s",
    "plan_time_s",
    "first_plan_moves",
    "arm_path_rad",
    "failures",
)


@dataclass(frozen=True)
class MotionBench:
    """Every episode of one motion benchmark, its summary per simulator and the IK timing."""

    sims: tuple[str, ...]
    reports: tuple[EpisodeReport, ...]
    summary: dict[str, dict]
    ik: dict


def time_ik(solver: IKSolver, n: int = 100, seed: int = 0) -> dict:
    """Wall time of one batched IK call on ``n`` random top-down targets in the block area."""
    rng = np.random.default_rng(seed)
    targets = np.stack(
        [
            top_down_pose(
                (rng.uniform(0.35, 0.65), rng.uniform(-0.3, 0.3), rng.uniform(0.03, 0.3)),
                rng.uniform(-np.pi / 2, np.pi / 2),
            )
            for _ in range(n)
        ]
    )
    q0 = np.asarray(solver.spec.q_home)
    solver.solve(targets[:2], q0)  # warm-up
    t0 = time.perf_counter()
    result = solver.solve(targets, q0)
    return {"n": n, "time_s": time.perf_counter() - t0, "converged": int(result.ok.sum())}


def summarise(
    reports: Sequence[EpisodeReport], instances: Sequence[Instance], domain, camera: bool
) -> dict:
    """The figures of one simulator's episodes; ``instances[k]`` is episode k's instance and
    ``domain`` their PDDL domain. ``camera``: the first plan is one window, so "plans valid" is
    None (not applicable)."""
    moves = [m for r in reports for m in r.moves]
    failures = Counter(m.failure.value for m in moves if m.failure is not None)
    injected = [r for r in reports if r.faults]
    pairs = list(zip(reports, instances, strict=True))
    executed = [replay(domain, i, [m.move for m in r.moves if m.ok]).valid for r, i in pairs]
    first = [replay(domain, i, r.first_plan).valid for r, i in pairs]
    return {
        "episodes": len(reports),
        "plans_valid": None if camera else sum(first),
        "executed_valid": sum(executed),
        "moves": len(moves),
        "moves_ok": sum(m.ok for m in moves),
        "goal_reached": sum(r.reached_goal for r in reports),
        "failures": dict(failures),
        "replans": sum(r.replans for r in reports),
        "disturbed": sum(r.disturbed for r in reports),
        "statuses": dict(Counter(r.status.value for r in reports)),
        "with_faults": len(injected),
        "recovered": sum(r.reached_goal for r in injected),
        **{
            f"{k}_per_move_s": sum(getattr(m, f"{k}_time_s") for m in moves) / max(len(moves), 1)
            for k in ("wall", "sim", "ik", "check", "path")
        },
        "wall_s": sum(r.wall_time_s for r in reports),
        "collided": sum(r.collided for r in reports),  # episodes whose arm touched something
        "touched": dict(sum((Counter(r.touched) for r in reports), Counter())),
        "rerouted": sum(m.path_time_s > 0 for m in moves),  # moves the motion planner ran on
        "arm_path_rad": sum(m.path_rad for m in moves) / max(len(reports), 1),  # per episode
        "plan_per_episode_s": sum(r.plan_time_s for r in reports) / max(len(reports), 1),
    }


def run(
    suite: Suite,
    base: LoopConfig,
    sims: Sequence[str],
    seed: int,
    progress: Callable[[str, EpisodeReport], None] | None = None,
    workers: int = 1,
    ray_address: str | None = None,
) -> MotionBench:
    """One closed-loop episode per instance in each simulator; ``progress(sim, report)`` as
    each ends. Episode ``k`` uses seed ``seed * 100_003 + k``: its own layout and fault draws,
    reproducible from ``seed`` whatever ``workers``/``ray_address`` (`tamp.sweep.run_items`)."""
    ik = time_ik(process_solver())
    items = [
        (inst.problem, replace(base, sim=name), seed * 100_003 + k, inst.name)
        for name in sims
        for k, inst in enumerate(suite.instances)
    ]
    done = None if progress is None else lambda k, report: progress(report.sim, report)
    every, n = run_items(_episode, items, workers, ray_address, done), len(suite.instances)
    summary = {
        s: summarise(
            every[j * n : (j + 1) * n], suite.instances, suite.domain, base.observe == "camera"
        )
        for j, s in enumerate(sims)
    }
    return MotionBench(tuple(sims), tuple(every), summary, ik)


def _episode(item: tuple) -> EpisodeReport:
    """`run`'s episode ``(problem, config, seed, name)``, in the process that runs it."""
    report = run_episode(*item[:3], solver=process_solver())
    return dataclasses.replace(report, problem=item[3])


def episode_rows(reports: Sequence[EpisodeReport]) -> list[dict]:
    """One ``episodes.csv`` row per episode (columns `EPISODE_COLUMNS`)."""
    return [
        {
            "sim": r.sim,
            "problem": r.problem,
            "status": r.status.value,
            "reached_goal": r.reached_goal,
            "moves": len(r.moves),
            "moves_ok": sum(m.ok for m in r.moves),
            "replans": r.replans,
            "faults": " ".join(r.faults),
            "disturbed": r.disturbed,
            "touched": " ".join(f"{k}:{v}" for k, v in sorted(r.touched.items())),
            "sim_time_s": round(r.sim_time_s, 2),
            "wall_time_s": round(r.wall_time_s, 2),
            "plan_time_s": round(r.plan_time_s, 3),
            "first_plan_moves": len(r.first_plan),
            "arm_path_rad": round(sum(m.path_rad for m in r.moves), 3),
            "failures": " ".join(m.failure.value for m in r.moves if m.failure is not None),
        }
        for r in reports
    ]


# --- executability of given plans (``tamp bench executability``) ---------------------------
OURS = "ours"  # the reference row: our planner's plans, executed the same way


@dataclass(frozen=True)
class PlanRow:
    """A plan of a source executed open-loop in one simulator (a ``plans.csv`` row)."""

    source: str
    sim: str
    problem: str
    task: str  # our validator's status, or "unparseable" (``error`` says why not valid)
    planbench_valid: bool | None  # the source's own verdict (None: none given)
    reached_goal: bool
    first_failure: str  # "" when none (`first_failure`)
    failure_at: str  # the step's label
    disturbed: int  # steps after which another block had moved
    moves: int  # steps attempted physically
    wall_time_s: float
    error: str


def read_sources(path: str | Path) -> dict[str, dict[str, tuple[str, bool | None]]]:
    """``{source: {instance: (plan, PlanBench verdict)}}`` of a CSV (source: its stem) or folder
    of CSVs: ``file`` (``instances/<name>.pddl``), ``plan`` (``;``-joined), ``llm_correct``."""
    root = Path(path)
    files = sorted(root.glob("*.csv")) if root.is_dir() else [root] if root.exists() else []
    if not files:
        raise DataError(f"--plans {root}: no such CSV file, or no *.csv files in the folder")
    out = {}
    for f in files:
        with f.open(newline="", encoding="utf-8") as handle:
            reader = csv.DictReader(handle)
            missing = [c for c in ("file", "plan") if c not in (reader.fieldnames or ())]
            if missing:
                raise DataError(f"{f}: missing column(s) {', '.join(missing)} (file, plan)")
            plans = {}
            for row in reader:
                flag = (row.get("llm_correct") or "").strip()
                name = (row["file"] or "").strip().removeprefix("instances/").removesuffix(".pddl")
                plans[name] = (row["plan"] or "", None if not flag else flag == "1")
        out[f.stem if f.stem != OURS else f"{OURS} (csv)"] = plans
    return out


def our_plans(suite: Suite, config: PlannerConfig, seed: int) -> dict[str, tuple[str, None]]:
    """Our planner's plan of every instance as 4-op action lines (empty: no plan found)."""
    results = plan_batch([i.problem for i in suite.instances], config, seed)
    out = {}
    for inst, result in zip(suite.instances, results, strict=True):
        moves = result.plan.moves if result.solved else ()
        actions = get_domain(inst.problem.domain).to_actions(inst.problem, moves, strict=False)
        out[inst.name] = ("\n".join(map(str, actions)), None)
    return out


def check_given(text: str | None, instance: Instance, domain, source: str):
    """``(steps, task status, error)``; ``(None, "unparseable", error)`` for a missing, empty or
    malformed plan (actions after an unpaired pick/put are dropped: invalid before anyway)."""
    if text is None:
        return None, "unparseable", f"{source}: no plan for {instance.name}"
    try:
        steps = parse_given(text.replace(";", "\n"), f"{source} {instance.name}", instance.problem)
        moves, rules = [s.move for s in steps], get_domain(instance.problem.domain)
        actions = [a for s in steps for a in s.actions] or rules.to_actions(
            instance.problem, moves, strict=False
        )
        verdict = validate(domain, instance.pddl, actions)
    except TampError as exc:
        return None, "unparseable", str(exc)
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


def run_given(
    suite: Suite,
    sources: dict,
    base: LoopConfig,
    sims: Sequence[str],
    seed: int,
    ours: PlannerConfig | None,
    progress: Callable | None = None,
    workers: int = 1,
    ray_address: str | None = None,
) -> list:
    """`PlanRow` of every source's plan of every instance in each simulator. Instance ``k`` uses
    episode seed ``seed * 100_003 + k`` (its layout) for every source; a plan met before on the
    same instance and simulator is run once (the rows share its outcome, time included): the
    distinct runs are the sweep's items. ``progress(sim, row)`` as each row's run ends."""
    plans = {**sources, **({OURS: our_plans(suite, ours, seed)} if ours is not None else {})}
    checked = {
        (src, i.name): check_given(got.get(i.name, (None,))[0], i, suite.domain, src)
        for src, got in plans.items()
        for i in suite.instances
    }
    specs, runs, waiting = [], {}, {}  # rows' given columns; key -> run's item; key -> rows
    for sim in sims:
        config = replace(base, sim=sim)
        for k, inst in enumerate(suite.instances):
            for src, got in plans.items():
                steps, task, error = checked[src, inst.name]
                key = (sim, k, steps and tuple(s.label for s in steps))
                if key[2] is not None:
                    runs.setdefault(key, (inst.problem, steps, config, seed * 100_003 + k))
                waiting.setdefault(key, []).append(len(specs))
                specs.append((src, sim, inst.name, task, got.get(inst.name, ("", None))[1], error))
    rows, keys = [None] * len(specs), list(runs)

    def finish(key: tuple, outcome: tuple) -> None:
        for j in waiting[key]:
            *head, error = specs[j]
            rows[j] = PlanRow(*head, *outcome, error)
            if progress is not None:
                progress(head[1], rows[j])

    for key in [key for key in waiting if key[2] is None]:
        finish(key, (False, "unparseable", "", 0, 0, 0.0))
    run_items(_given, runs.values(), workers, ray_address, lambda j, r: finish(keys[j], r))
    return rows


def _given(item: tuple) -> tuple:
    """`run_given`'s run ``(problem, steps, config, seed)``: its row's outcome columns."""
    r = GivenPlanEpisode(*item, solver=process_solver()).run()
    return (
        r.reached_goal,
        *first_failure(r.steps, r.reached_goal),
        sum(bool(s.disturbed) for s in r.steps),
        sum(s.attempted for s in r.steps),
        r.wall_time_s,
    )


def given_summary(rows: Sequence[PlanRow], sims: Sequence[str]) -> list[dict]:
    """Per source: plans, task-valid, PlanBench-valid, agreement (None: no verdicts); per sim the
    goals reached, top 3 first failures, disturbed stacks, s/plan (mean over parsed plans)."""
    out = []
    for src in dict.fromkeys(r.source for r in rows):
        mine = [r for r in rows if r.source == src]
        first = [r for r in mine if r.sim == sims[0]]
        pb = [r for r in first if r.planbench_valid is not None]
        by = {s: [r for r in mine if r.sim == s] for s in sims}
        ran = {s: [r for r in b if r.task != "unparseable"] for s, b in by.items()}
        out.append(
            {
                "source": src,
                "plans": len(first),
                "task_valid": sum(r.task == "valid" for r in first),
                "unparseable": sum(r.task == "unparseable" for r in first),
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
