"""``tamp bench motion``: how executable task plans are at motion level, per simulator.

Runs closed-loop episodes (`tamp.loop.episode`) on a spread of PlanBench instances in each simulator
and prints the executability table: task plans valid, moves executed, episodes reaching the
goal (simulator ground truth), failures by kind, replans, disturbed stacks, time per move; with
fault injection also the recovery rate. Writes ``episodes.csv`` and ``results.json``.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import os
import platform
import sys
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from motion.ik import IKSolver, top_down_pose
from tamp.bench import suites
from tamp.cli.run import loop_config
from tamp.loop.episode import EpisodeReport, run_episode
from task.errors import TampError


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


def summarise(reports: list[EpisodeReport]) -> dict:
    moves = [m for r in reports for m in r.moves]
    failures = Counter(m.failure.value for m in moves if m.failure is not None)
    injected = [r for r in reports if r.faults]
    return {
        "episodes": len(reports),
        "plans_valid": sum(r.initial_plan_solved for r in reports),
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


def table(rows: dict[str, dict], inject: str) -> str:
    head = (
        f"{'sim':9} {'episodes':>8} {'plans valid':>11} {'goal':>9} {'moves ok':>13} "
        f"{'replans':>7} "
        f"{'disturbed':>9} {'wall/move':>9} {'sim/move':>8} {'x real':>6}"
    )
    lines = [head]
    for sim, s in rows.items():
        e = s["episodes"]
        lines.append(
            f"{sim:9} {e:>8} {s['plans_valid']:>7}/{e:<3} {s['goal_reached']:>4}/{e:<4} "
            f"{s['moves_ok']:>6}/{s['moves']:<6} {s['replans']:>7} {s['disturbed']:>9} "
            f"{s['wall_per_move_s']:>8.2f}s {s['sim_per_move_s']:>7.2f}s "
            f"{s['sim_per_move_s'] / max(s['wall_per_move_s'], 1e-9):>6.1f}"
        )
    lines.append("")
    for sim, s in rows.items():
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(s["failures"].items())) or "none"
        lines.append(f"{sim}: failures by kind: {kinds}; episode outcomes: {s['statuses']}")
        if inject != "none":
            lines.append(
                f"{sim}: faults ({inject}) hit {s['with_faults']} episodes, "
                f"{s['recovered']} of them still reached the goal"
            )
    return "\n".join(lines)


def motion_command(args: argparse.Namespace) -> int:
    sims = tuple(dict.fromkeys(args.sim.split(",")))
    for name in sims:
        if name not in ("pybullet", "mujoco"):
            raise TampError(f"unknown simulator {name!r} (valid: pybullet, mujoco)")
    suite = suites.planbench(args.data, args.n)
    base = loop_config(args)
    solver = IKSolver()
    ik = time_ik(solver)
    rows, all_reports = {}, []
    for name in sims:
        config = replace(base, sim=name)
        reports = []
        bar = tqdm(suite.instances, desc=f"motion {name}", unit="episode", file=sys.stderr,
                   disable=not args.progress)  # fmt: skip
        for k, inst in enumerate(bar):
            # each episode its own layout and fault draws, reproducible from --seed
            report = run_episode(inst.problem, config, seed=args.seed * 100_003 + k, solver=solver)
            reports.append(dataclasses.replace(report, problem=inst.name))
            bar.set_postfix(goal=sum(r.reached_goal for r in reports))
        rows[name] = summarise(reports)
        all_reports += reports
    inject = str(base.inject)
    results = {
        "config": {"sims": sims, "n": len(suite.instances), "inject": inject,
                   "grasp": base.grasp, "seed": args.seed, "data": str(args.data),
                   "observe": base.observe, "perception": base.perception.mode,
                   "blur": base.perception.blur},
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                    "processor": platform.processor() or platform.machine()},
        "ik_batch": ik,
        "summary": rows,
    }  # fmt: skip
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(results, indent=2))
        with open(out / "episodes.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["sim", "problem", "status", "reached_goal", "moves", "moves_ok",
                        "replans", "faults", "disturbed", "sim_time_s", "wall_time_s"])  # fmt: skip
            for r in all_reports:
                row = [r.sim, r.problem, r.status.value, r.reached_goal, len(r.moves)]
                row += [sum(m.ok for m in r.moves), r.replans, " ".join(r.faults), r.disturbed]
                w.writerow([*row, round(r.sim_time_s, 2), round(r.wall_time_s, 2)])
    if args.json:
        print(json.dumps(results, indent=2))
        return 0
    seen = base.observe + (f" ({base.perception.mode} perception)" if base.observe == "camera"
                           else "")  # fmt: skip
    print(f"motion benchmark: {len(suite.instances)} PlanBench instances, grasp {base.grasp}, "
          f"observe {seen}, faults {inject}, seed {args.seed}")  # fmt: skip
    print(table(rows, inject))
    print(f"IK: one batched call on {ik['n']} targets took {ik['time_s']:.3f} s "
          f"({ik['converged']}/{ik['n']} converged)")  # fmt: skip
    if args.out:
        print(f"wrote results.json, episodes.csv to {args.out}")
    return 0
