"""``tamp bench checker``: the sphere collision checker's speed on one core, its verdicts against
the mesh model near obstacles, and the moves the motion planner reroutes with it."""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict

from tamp.cli.options import SCENES
from tamp.cli.recorded import out_folder
from task.errors import TampError, one_of


def checker_config(args: argparse.Namespace) -> dict:
    """The benchmark's settings (`tamp.bench.collision.run.CheckerBenchConfig`) from the
    options; an unknown scene is refused in one line."""
    scenes = tuple(dict.fromkeys(s.strip() for s in args.scenes.split(",") if s.strip()))
    if not scenes:
        raise TampError(f"--scenes names no scene (valid: {', '.join(SCENES)})")
    for name in scenes:
        if name not in SCENES:
            raise TampError(f"--scenes: unknown scene {one_of(name, SCENES)}")
    return {
        "scenes": scenes,
        "batches": tuple(args.batch),
        "repeats": args.repeats,
        "near": args.near,
        "moves": args.moves,
        "baseline": args.baseline,
        "seed": args.seed,
    }


def checker_command(args: argparse.Namespace) -> int:
    """Every ``--scenes`` scene: throughput, validation and rerouted moves; prints the tables,
    writes results.json, throughput.csv and moves.csv to ``--out``."""
    from tamp.bench import results
    from tamp.bench.collision import run as bench
    from tamp.bench.collision.table import checker_table

    recorded = checker_config(args)
    out_folder(args.out)
    config = bench.CheckerBenchConfig(**recorded)

    def progress(text: str) -> None:
        if args.progress:
            print(f"checker: {text} done", file=sys.stderr)

    result = bench.run(config, progress)
    body = {
        "config": asdict(config),
        "machine": results.machine(args.argv),
        "cpu": result["cpu"],
        "scenes": result["scenes"],
    }
    if args.out:
        folder = results.out_folder(args.out)
        results.write_json(folder / "results.json", body)
        results.write_csv(
            folder / "throughput.csv", bench.throughput_rows(result), bench.THROUGHPUT_COLUMNS
        )
        results.write_csv(folder / "moves.csv", result["moves"], bench.MOVE_COLUMNS, digits=3)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    print(checker_table(result))
    if args.out:
        print(f"wrote results.json, throughput.csv, moves.csv to {args.out}")
    return 0
