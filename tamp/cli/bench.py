"""``tamp bench planbench`` and ``tamp bench random``: run `tamp.bench.planning` with progress bars.

Both print the paper-style tables (or the ``results.json`` content with ``--json``) and, with
``--out DIR``, write ``instances.csv``, ``results.json`` and ``steps.png`` there. A benchmark
that ran exits 0 whatever its scores; bad options or missing data exit 2.
"""

from __future__ import annotations

import argparse
import json
import sys
from contextlib import contextmanager

from tqdm import tqdm

from tamp.bench import planning as bench
from tamp.bench import results as bench_io
from tamp.bench import suites
from tamp.bench.suites import Suite
from tamp.cli import report
from tamp.cli.plan import planner_config
from task.errors import TampError


@contextmanager
def _bar(total: int, desc: str, enabled: bool, unit: str = "plan"):
    """A tqdm bar on stderr; yields ``update(k)``, the `plan_batch` progress callback."""
    with tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=not enabled) as bar:
        yield bar.update


def _run(suite: Suite, args: argparse.Namespace) -> int:
    config = planner_config(args)
    horizons = args.horizons or (config.horizon,)
    seeds = tuple(range(args.seeds))
    total = bench.total(len(suite.instances), len(seeds), len(horizons), args.sequential)
    with _bar(total, f"{suite.name} ({len(suite.instances)} instances)", args.progress) as update:
        result = bench.run(suite, config, seeds, horizons, args.sequential, update)
    results = bench_io.results(result)
    if args.out is not None:
        paths = bench_io.write(result, args.out, results)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        print(report.bench_report(result))
        if args.out is not None:
            print(f"\nwrote {', '.join(p.name for p in paths)} to {args.out}")
    return 0


def planbench_command(args: argparse.Namespace) -> int:
    """The official PlanBench Blocksworld-600 (or a ``--limit`` spread of it)."""
    return _run(suites.planbench(args.data, args.limit), args)


def random_command(args: argparse.Namespace) -> int:
    """``--n`` generated instances per ``--blocks`` count, optima from A* within a budget."""
    if min(args.blocks) < 2:
        raise TampError(f"--blocks: random problems need at least 2 blocks, got {min(args.blocks)}")
    total = len(args.blocks) * args.n
    with _bar(total, "instances, A* optima", args.progress, "instance") as update:
        suite = suites.generated(args.blocks, args.n, args.seed, args.max_nodes, update)
    return _run(suite, args)
