"""Run the checker benchmark: throughput, agreement with the mesh model, rerouted moves.

Per scene (`tamp.bench.collision.scenes`):

- **throughput**: `SphereCollision.valid_batch` on batches of each size, ``repeats`` calls per
  batch, on one core (`tamp.bench.collision.threads.one_core`: every thread of the process on
  one CPU, OpenBLAS's and torch's pools at one thread); configurations per second of the median
  call, by the wall clock and by the process's CPU time (its own work, which other
  processes on a loaded machine do not inflate as much), on the ``uniform`` sample and on the
  ``near`` one (tiled to the batch size), and how many threads worked during the timed calls;
- **validation**: the sphere model's verdicts on the ``near`` sample against the mesh model's
  (`robots.collision.PandaCollision.valid`, PyBullet's closest points, the guard's final word),
  both at the loop's margin: false "free" (must be 0), false "collision", the mesh model's cost
  per configuration, and, where the spheres refuse what the meshes accept, how much farther
  than its threshold the meshes' closest pair is (probed up to ``PROBE`` m beyond it);
- **rerouted moves**: `motion.rrt.plan_path` as the guard calls it (`motion.guard`: its
  settings, the margin widened by ``plan_pad``, the sphere model's ``valid_batch`` to search
  and the mesh model to verify) on seeded moves the straight path cannot make; beside it
  (``baseline``) the same moves by OMPL's RRT-Connect on the mesh model alone, as before the
  sphere model existed. Each move's planning time by the wall clock and in process CPU time.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from tamp.bench.collision import scenes
from tamp.bench.collision.threads import busy_threads, one_core, thread_times

PROBE = 0.05  # m beyond the margin up to which a false collision's mesh clearance is measured
MOVE_COLUMNS = (
    "scene",
    "move",
    "planner",
    "ok",
    "search",
    "time_ms",
    "cpu_ms",
    "batch_ms",
    "verify_ms",
    "batch_configs",
    "batch_calls",
    "mesh_checks",
    "waypoints",
    "failure",
)
THROUGHPUT_COLUMNS = (
    "scene",
    "sample",
    "batch",
    "calls",
    "median_s",
    "configs_per_s",
    "median_cpu_s",
    "configs_per_cpu_s",
    "threads",
)


@dataclass(frozen=True)
class CheckerBenchConfig:
    """What `run` measures; the defaults are ``tamp bench checker``'s."""

    scenes: tuple[str, ...] = ("shelf", "clutter", "cramped")
    batches: tuple[int, ...] = (1_000, 10_000, 100_000)  # configurations per call
    repeats: int = 5  # calls per batch size and sample
    near: int = 2_000  # configurations near obstacles per scene, checked by both models
    moves: int = 20  # rerouted moves per scene
    baseline: bool = True  # also plan each move with OMPL on the mesh model alone
    seed: int = 0
    margin: float = 0.01  # m, the loop's (`tamp.loop.execute.ExecutionConfig.margin`)


def throughput(spheres, samples: dict[str, np.ndarray], batches: Sequence[int], repeats: int):
    """Rows (sample, batch, calls, median_s, configs_per_s, median_cpu_s, configs_per_cpu_s,
    threads): ``repeats`` timed calls of ``spheres.valid_batch`` on the first ``batch``
    configurations of each sample (tiled when it is shorter), after one untimed call;
    ``threads``: how many of the process's threads worked during them (`busy_threads`, None
    without ``/proc``)."""
    rows = []
    for name, q in samples.items():
        for batch in batches:
            qs = np.resize(q, (batch, q.shape[1]))  # (batch, J)
            spheres.valid_batch(qs)
            wall, cpu = [], []
            before = thread_times()
            for _ in range(repeats):
                t0, c0 = time.perf_counter(), time.process_time()
                spheres.valid_batch(qs)
                wall.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
            threads = busy_threads(before, thread_times())
            median, median_cpu = float(np.median(wall)), float(np.median(cpu))
            rows.append(
                {
                    "sample": name,
                    "batch": batch,
                    "calls": repeats,
                    "median_s": median,
                    "configs_per_s": batch / median,
                    "median_cpu_s": median_cpu,
                    "configs_per_cpu_s": batch / max(median_cpu, 1e-9),
                    "threads": threads,
                }
            )
    return rows


def validate(mesh, spheres, boxes, q: np.ndarray, margin: float) -> dict:
    """Both models' verdicts on ``q`` (N, J) at ``margin`` (the scene's ``boxes`` set in both):
    counts, each model's cost per configuration, and where the spheres refuse a configuration
    the meshes accept, how much farther than its threshold the meshes' closest pair is
    (`_excess`)."""
    mesh.margin = spheres.margin = margin
    t0 = time.perf_counter()
    fast = spheres.valid_batch(q)  # (N,)
    sphere_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    exact = np.array([mesh.valid(x) for x in q])  # (N,)
    mesh_s = time.perf_counter() - t0
    refused = np.flatnonzero(~fast & exact)
    excess = _excess(mesh, boxes, q[refused], margin)  # (F,) m, NaN: beyond the probe
    measured = excess[np.isfinite(excess)]
    return {
        "n": len(q),
        "mesh_free": int(exact.sum()),
        "sphere_free": int(fast.sum()),
        "false_free": int((fast & ~exact).sum()),
        "false_collision": int(refused.size),
        "false_collision_of_free": refused.size / max(int(exact.sum()), 1),
        "false_collision_excess_median_m": float(np.median(measured)) if measured.size else None,
        "false_collision_excess_max_m": float(measured.max()) if measured.size else None,
        "false_collision_beyond_probe": int(refused.size - measured.size),
        "mesh_us_per_config": 1e6 * mesh_s / len(q),
        "sphere_us_per_config": 1e6 * sphere_s / len(q),
    }


def _excess(mesh, boxes, q: np.ndarray, margin: float) -> np.ndarray:
    """How much farther than its threshold (``margin`` to a box or the table, the mesh model's
    self margin to another link) the meshes' closest pair is at each configuration of ``q``
    (F, J), (F,) m, probed up to ``PROBE`` beyond it (NaN: farther). A second mesh model with
    the thresholds widened by ``PROBE`` and the scene's ``boxes`` answers (a mesh model fixes
    its self threshold when it is built)."""
    from robots.collision import PandaCollision

    link = set(mesh.parts)
    out = np.full(len(q), np.nan)
    if not len(q):
        return out
    with PandaCollision(margin + PROBE, self_margin=mesh.self_margin + PROBE) as probe:
        probe.set_boxes(boxes)
        for k, x in enumerate(q):
            hits = probe.contacts(x)
            if hits:
                out[k] = min(
                    c.distance - (mesh.self_margin if c.other in link else margin) for c in hits
                )
    return out


def reroute(mesh, spheres, starts, goals, margin: float, seed: int, baseline: bool) -> list[dict]:
    """Each move planned as the guard plans a blocked free-space phase (`motion.guard`), and by
    OMPL on the mesh model alone (``baseline``): one row per move and planner."""
    from motion.guard import GuardConfig
    from motion.rrt import PathPlannerConfig, plan_path

    guard = GuardConfig()
    # motion.guard._guard_phase's planner settings: checked every ~0.02 rad
    rrt = replace(guard.rrt or PathPlannerConfig(resolution=0.0015, simplify_time=5.0), seed=seed)
    mesh.margin = spheres.margin = margin + guard.plan_pad
    planners: list[tuple[str, Callable | None]] = [("spheres", spheres.valid_batch)]
    if baseline:
        planners.append(("ompl_mesh", None))
    rows = []
    try:
        for k, (a, b) in enumerate(zip(starts, goals, strict=True)):
            for name, batch in planners:
                c0 = time.process_time()
                r = plan_path(a, b, mesh.valid, config=rrt, valid_batch=batch)
                cpu_ms = 1e3 * (time.process_time() - c0)
                ev = r.evidence
                batch_s = ev.get("batch_s")
                rows.append(
                    {
                        "move": k,
                        "planner": name,
                        "ok": r.ok,
                        "search": ev.get("search", "ompl"),
                        "time_ms": 1e3 * r.time_s,
                        "cpu_ms": cpu_ms,
                        "batch_ms": None if batch_s is None else 1e3 * batch_s,
                        "verify_ms": None if batch_s is None else 1e3 * (r.time_s - batch_s),
                        "batch_configs": ev.get("batch_configs"),
                        "batch_calls": ev.get("batch_calls"),
                        "mesh_checks": r.checks,
                        "waypoints": None if r.path is None else len(r.path),
                        "failure": r.failure or "",
                    }
                )
    finally:
        mesh.margin = spheres.margin = margin
    return rows


def _moves_summary(rows: list[dict]) -> dict:
    """Per planner: moves, solved, median and p90 planning time (ms) and how they were found."""
    out = {}
    for name in dict.fromkeys(r["planner"] for r in rows):
        mine = [r for r in rows if r["planner"] == name]
        times = np.array([r["time_ms"] for r in mine])
        cpu = np.array([r["cpu_ms"] for r in mine])
        out[name] = {
            "moves": len(mine),
            "solved": sum(r["ok"] for r in mine),
            "median_ms": float(np.median(times)) if mine else None,
            "p90_ms": float(np.percentile(times, 90)) if mine else None,
            "median_cpu_ms": float(np.median(cpu)) if mine else None,
            "p90_cpu_ms": float(np.percentile(cpu, 90)) if mine else None,
            "searches": dict(Counter(r["search"] for r in mine)),
            "mesh_checks_median": float(np.median([r["mesh_checks"] for r in mine])),
        }
    return out


def run_scene(name: str, config: CheckerBenchConfig, progress=None) -> tuple[dict, list[dict]]:
    """One scene's throughput rows, validation, rerouted moves and their summary."""
    from motion.sphere_check import SphereCollision
    from robots.collision import PandaCollision

    boxes = scenes.scene_boxes(name, config.seed)
    spheres = SphereCollision(margin=config.margin)
    spheres.set_boxes(boxes)
    near = scenes.near(boxes, config.near, config.seed + 1, config.margin)
    samples = {"uniform": scenes.uniform(max(config.batches), config.seed + 2), "near": near}
    rates = throughput(spheres, samples, config.batches, config.repeats)
    if progress:
        progress(f"{name}: throughput")
    with PandaCollision(margin=config.margin) as mesh:
        mesh.set_boxes(boxes)
        check = validate(mesh, spheres, boxes, near, config.margin)
        if progress:
            progress(f"{name}: validation")
        starts, goals = scenes.blocked_moves(mesh, spheres, config.moves, config.seed + 3)
        rows = reroute(mesh, spheres, starts, goals, config.margin, config.seed, config.baseline)
        if progress:
            progress(f"{name}: rerouted moves")
    summary = {
        "scene": name,
        "boxes": len(boxes),
        "throughput": rates,
        "validation": check,
        "moves": _moves_summary(rows),
    }
    return summary, [{"scene": name, **r} for r in rows]


def run(config: CheckerBenchConfig, progress=None) -> dict:
    """Every scene of ``config``, the process on one core (`one_core`): {"cpu", "scenes":
    [summary], "moves": [row]}; ``progress(text)`` after each stage of each scene."""
    summaries, moves = [], []
    with one_core() as cpu:
        for name in config.scenes:
            summary, rows = run_scene(name, config, progress)
            summaries.append(summary)
            moves += rows
    return {"cpu": cpu, "scenes": summaries, "moves": moves}


def throughput_rows(result: dict) -> list[dict]:
    """throughput.csv: one row per (scene, sample, batch size)."""
    return [{"scene": s["scene"], **r} for s in result["scenes"] for r in s["throughput"]]
