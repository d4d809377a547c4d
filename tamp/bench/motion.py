"""The motion benchmark (``tamp bench motion``): how executable task plans are at motion level.

`run` plays closed-loop episodes (`tamp.loop`) on a suite in each simulator; `summarise` gives
the executability figures per simulator: task plans valid, executed moves valid, moves executed,
episodes reaching the goal (simulator ground truth), failures by kind, replans, disturbed stacks,
time per move, and with fault injection the recovery rate. `tamp.bench.tables.motion_table`
prints them.

"Valid" is a replay through `task.symbolic.validate` against the instance's PDDL problem
(`tamp.bench.planning.replay`), never the planner's own flag: "plans valid" replays the first
complete task plan (not applicable with the camera, whose first plan is one window), "executed
moves valid" the moves that executed ok, in order (every step applicable, the goal at the end).
"""

from __future__ import annotations

import dataclasses
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from motion.ik import IKSolver, top_down_pose
from tamp.bench.planning import replay
from tamp.bench.suites import Suite
from tamp.loop import EpisodeReport, LoopConfig, run_episode
from task.symbolic.instances import Instance

EPISODE_COLUMNS = (
    "sim", "problem", "status", "reached_goal", "moves", "moves_ok", "replans", "faults",
    "disturbed", "sim_time_s", "wall_time_s",
)  # fmt: skip


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
        "wall_per_move_s": sum(m.wall_time_s for m in moves) / max(len(moves), 1),
        "sim_per_move_s": sum(m.sim_time_s for m in moves) / max(len(moves), 1),
        "ik_per_move_s": sum(m.ik_time_s for m in moves) / max(len(moves), 1),
        "wall_s": sum(r.wall_time_s for r in reports),
    }


def run(
    suite: Suite,
    base: LoopConfig,
    sims: Sequence[str],
    seed: int,
    progress: Callable[[str, EpisodeReport], None] | None = None,
) -> MotionBench:
    """One closed-loop episode per instance in each simulator; ``progress(sim, report)`` after
    each. Episode ``k`` uses seed ``seed * 100_003 + k``: its own layout and fault draws,
    reproducible from ``seed``."""
    solver = IKSolver()
    ik = time_ik(solver)
    summary, every = {}, []
    for name in sims:
        config = replace(base, sim=name)
        reports = []
        for k, inst in enumerate(suite.instances):
            report = run_episode(inst.problem, config, seed=seed * 100_003 + k, solver=solver)
            reports.append(dataclasses.replace(report, problem=inst.name))
            if progress is not None:
                progress(name, reports[-1])
        camera = config.observe == "camera"
        summary[name] = summarise(reports, suite.instances, suite.domain, camera)
        every += reports
    return MotionBench(tuple(sims), tuple(every), summary, ik)


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
            "sim_time_s": round(r.sim_time_s, 2),
            "wall_time_s": round(r.wall_time_s, 2),
        }
        for r in reports
    ]
