"""The motion benchmark (``tamp bench motion``): closed-loop episodes at motion level.

``tamp bench motion``: `run` plays closed-loop episodes (`tamp.loop`) on a suite in each
simulator; `summarise` gives per simulator plans valid, executed moves valid, moves, goals
reached (ground truth), failures by kind, replans, disturbed stacks, time per move, recovery.

"Valid" is a replay through `task.symbolic.validate` against the instance's PDDL problem
(`tamp.bench.planning.replay`), never the planner's own flag: "plans valid" replays the first
complete task plan (not applicable with the camera, whose first plan is one window), "executed
moves valid" the moves that executed ok, in order (every step applicable, the goal at the end).

``tamp bench executability`` lives in `tamp.bench.executability`. Episodes sweep with
`tamp.sweep.run_items`.
"""

from __future__ import annotations

import dataclasses
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from motion.ik import IKSolver, pose_yaw, top_down_pose
from motion.pick_place import PickPlaceRequest, waypoint_targets
from tamp.bench.planning import replay
from tamp.bench.suites import Suite
from tamp.loop import EpisodeReport, LoopConfig, run_episode
from tamp.modes import Observation
from tamp.rerun_log import recorder_for
from tamp.sweep import run_items, torch_threads
from task.instances import Instance

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
    "unreadable",
    "touched",
    "sim_time_s",
    "wall_time_s",
    "plan_time_s",
    "first_plan_moves",
    "arm_path_rad",
    "failures",
    "geo_moves",
    "posture_moves",
)


@dataclass(frozen=True)
class MotionBench:
    """Every episode of one motion benchmark, its summary per simulator and the IK timing."""

    sims: tuple[str, ...]
    reports: tuple[EpisodeReport, ...]
    summary: dict[str, dict]
    ik: dict


def time_ik(solver: IKSolver, n: int = 100, seed: int = 0, moves: int = 20) -> dict:
    """Wall time of one batched IK call on ``n`` random top-down targets in the block area, and
    of one move's six waypoints (`motion.pick_place.waypoint_targets`) in one batched call:
    the median over ``moves`` random pick-and-places from the home pose (each call timed alone
    after one warm-up)."""
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
    out = {"n": n, "time_s": time.perf_counter() - t0, "converged": int(result.ok.sum())}
    times, solved = [], 0
    for _ in range(moves):
        pick = (rng.uniform(0.35, 0.65), rng.uniform(-0.3, 0.3), 0.025)
        place = (rng.uniform(0.35, 0.65), rng.uniform(-0.3, 0.3), rng.choice([0.025, 0.075]))
        request = PickPlaceRequest(pick, rng.uniform(-1.5, 1.5), place, 0.0, 0.1)
        six = waypoint_targets(request, pose_yaw(solver.fk(q0)[0]))  # (6, 4, 4)
        t0 = time.perf_counter()
        solved += int(solver.solve(six, q0).ok.all())
        times.append(time.perf_counter() - t0)
    out |= {"moves": moves, "waypoints_median_s": float(np.median(times)), "moves_solved": solved}
    return out


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
        "disturbed": sum(r.disturbed for r in reports),  # moves not scored clean
        "unreadable": sum(r.unreadable for r in reports),  # ... the true state unreadable
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
        "rerouted": sum(bool(m.rerouted) for m in moves),  # moves run on a planner's detour
        # moves the geometric fallback made (`tamp.loop.geo_fallback`), and of those, in another
        # posture of the arm than the nearest (`tamp.geo.postures`)
        "geo_moves": sum(_geo(m) for m in moves),
        "posture_moves": sum(_posture(m) for m in moves),
        "planner_failures": sum(m.planner_failures for m in moves),  # runs that found no way
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
    record: str | None = None,
) -> MotionBench:
    """One closed-loop episode per instance in each simulator; ``progress(sim, report)`` as
    each ends. Episode ``k`` uses seed ``seed * 100_003 + k``: its own layout and fault draws,
    reproducible from ``seed`` whatever ``workers``/``ray_address`` (`tamp.sweep.run_items`).
    ``record``: a folder, each episode a Rerun recording under it (`tamp.rerun_log`)."""
    ik = time_ik(IKSolver())
    items = [
        (inst.problem, replace(base, sim=name), seed * 100_003 + k, inst.name, record)
        for name in sims
        for k, inst in enumerate(suite.instances)
    ]
    done = None if progress is None else lambda k, report: progress(report.sim, report)
    every, n = run_items(_episode, items, workers, ray_address, done), len(suite.instances)
    summary = {
        s: summarise(
            every[j * n : (j + 1) * n],
            suite.instances,
            suite.domain,
            base.observe == Observation.CAMERA,
        )
        for j, s in enumerate(sims)
    }
    return MotionBench(tuple(sims), tuple(every), summary, ik)


def _episode(item: tuple) -> EpisodeReport:
    """`run`'s episode ``(problem, config, seed, name, record)``, in the process that runs it."""
    problem, config, seed, name, record = item
    recorder = recorder_for(record, config.sim, name)
    with torch_threads(1):  # one small problem: thread hand-offs cost more than they give
        report = run_episode(problem, config, seed, recorder=recorder)
    return dataclasses.replace(report, problem=name)


def _geo(move) -> bool:
    """Whether the geometric fallback made ``move`` (an `ExecutionResult`)."""
    return move.ok and move.evidence.get("geo") == "ok"


def _posture(move) -> bool:
    """Whether ``move`` was made in another posture of the arm than the nearest one."""
    return _geo(move) and bool(move.evidence.get("posture"))


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
            "unreadable": r.unreadable,
            "touched": " ".join(f"{k}:{v}" for k, v in sorted(r.touched.items())),
            "sim_time_s": round(r.sim_time_s, 2),
            "wall_time_s": round(r.wall_time_s, 2),
            "plan_time_s": round(r.plan_time_s, 3),
            "first_plan_moves": len(r.first_plan),
            "arm_path_rad": round(sum(m.path_rad for m in r.moves), 3),
            "failures": " ".join(m.failure.value for m in r.moves if m.failure is not None),
            "geo_moves": sum(_geo(m) for m in r.moves),
            "posture_moves": sum(_posture(m) for m in r.moves),
        }
        for r in reports
    ]
