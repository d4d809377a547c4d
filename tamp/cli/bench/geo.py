"""``tamp bench tamp``: the canonical TAMP problems, planners side by side in each simulator."""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict

from tqdm import tqdm

from tamp.bench import results, tables
from tamp.cli.bench import interrupted
from tamp.cli.recorded import out_folder, tamp_bench_config
from tamp.cli.types import sim_list
from tamp.modes import Observation


def tamp_command(args: argparse.Namespace) -> int:
    """Every ``--planner`` on ``--n`` seeded variants of each ``--problems`` in each ``--sim``;
    prints the table, writes results.json and episodes.csv (and videos) to ``--out``."""
    from tamp.bench.geo import run as bench

    recorded = tamp_bench_config(args)  # refused combinations: before any work
    recorded["limits"] = asdict(bench.LIMITS)
    out_folder(args.out)
    sims = sim_list(args.sim)
    videos = None
    if args.video:
        videos = results.out_folder(args.out) / "videos"
        videos.mkdir(exist_ok=True)
    todo = bench.items(args.problems, args.n, args.planners, sims, args.seed, videos, args.observe)
    done: list[dict] = []
    wall0 = time.perf_counter()
    with tqdm(
        total=len(todo), desc="tamp", unit="episode", file=sys.stderr, disable=not args.progress
    ) as bar:

        def progress(index: int, row: dict) -> None:
            done.append(row)
            bar.set_postfix(problem=row["problem"], planner=row["planner"], refresh=False)
            bar.update(1)

        try:
            rows = bench.run(todo, args.workers, args.ray, progress)
        except KeyboardInterrupt:
            if args.out:
                _write(args, recorded, done, bench.summarise(done), None, len(todo))
            return interrupted(args.out, len(done), len(todo), "episodes")
    summary = bench.summarise(rows)
    wall = time.perf_counter() - wall0
    body = _write(args, recorded, rows, summary, wall, None)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    print(
        f"TAMP benchmark: {args.n} variant{'s' if args.n != 1 else ''} of "
        f"{', '.join(args.problems)} from seed {args.seed}; observe {args.observe}; "
        f"goal: ground truth; {wall:.0f} s wall",
        tables.tamp_table(summary, sims),
        sep="\n",
    )
    if args.observe == Observation.CAMERA:
        print(_camera_line(bench.camera_summary(rows)))
    if args.out:
        print(f"wrote results.json, episodes.csv to {args.out}")
    return 0


def _camera_line(errors: dict) -> str:
    """The camera's pose errors against ground truth, in one line."""
    if not errors:
        return "camera pose error: no look was scored"
    yaw = "-" if errors["yaw_deg_max"] is None else f"{errors['yaw_deg_max']:.1f}"
    return (
        f"camera pose error (every look, against ground truth): position mean "
        f"{errors['pose_mm_mean']:.1f} mm, max {errors['pose_mm_max']:.1f} mm; yaw max {yaw} "
        f"deg; {errors['unseen_looks']} looks kept an unseen object's previous estimate"
    )


def _write(args, recorded: dict, rows, summary, wall: float | None, total: int | None) -> dict:
    """results.json (marked partial with ``total``) and episodes.csv under ``--out``; the body."""
    from tamp.bench.geo.run import ROW_COLUMNS, camera_summary

    body = {"config": recorded, "machine": results.machine(args.argv), "summary": summary}
    if args.observe == Observation.CAMERA:
        body["camera"] = camera_summary(rows)
    if wall is not None:
        body["wall_s"] = wall
    if total is not None:
        body["partial"] = {"done": len(rows), "of": total}
    if args.out:
        folder = results.out_folder(args.out)
        results.write_json(folder / "results.json", body)
        results.write_csv(folder / "episodes.csv", rows, ROW_COLUMNS, digits=3)
    return body
