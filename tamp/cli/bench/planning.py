"""``tamp bench planbench|pddl|random``: the planning benchmarks on PDDL sets and seeded random
Blocksworld problems, optionally with LAMA beside."""

from __future__ import annotations

import argparse
import json
import sys
from contextlib import contextmanager
from dataclasses import asdict, replace

from tqdm import tqdm

from tamp.bench import planning, results, suites, tables
from tamp.bench.peers import side_by_side
from tamp.cli.bench import bar, interrupted
from tamp.cli.options import planner_config
from tamp.cli.recorded import out_folder as output_folder
from tamp.cli.recorded import (
    planning_config,
)
from task.errors import TampError


def _run(suite: suites.Suite, args: argparse.Namespace, lengths: bool = False) -> int:
    """Plan ``suite`` as ``args`` say; ``lengths``: also print the plan-length table (and run
    LAMA beside with ``args.lama``, Slaney & Thiebaux's baselines with ``args.baselines``)."""
    import torch

    torch.set_num_threads(args.threads)
    rules = {i.problem.domain for i in suite.instances}
    domain = rules.pop() if len(rules) == 1 else None
    recorded = planning_config(args, domain)
    config = planner_config(args, domain)
    peers = getattr(args, "peers", None)
    if getattr(args, "one_at_a_time", False) or peers:
        config = replace(config, batched=False)
    horizons, seeds = args.horizons or (config.horizon,), tuple(range(args.seeds))
    total = planning.total(len(suite.instances), len(seeds), len(horizons), args.sequential)
    runs: list[planning.Run] = []
    done: list[planning.Row] = []  # every row final so far, of complete runs and the current
    with bar(total, f"{suite.name} ({len(suite.instances)} instances)", args.progress) as update:
        try:
            result = planning.run(
                suite, config, seeds, horizons, args.sequential, update, runs.append, done.append
            )
        except KeyboardInterrupt:
            if args.out is not None:
                out = results.out_folder(args.out)
                partial = {
                    "done": len(done),
                    "of": len(suite.instances) * len(seeds) * len(horizons),
                    "complete_runs": len(runs),  # a batched run's rows come a shape at a time
                    "interrupted": True,
                }
                body = {
                    "config": recorded,
                    "partial": partial,
                    "machine": results.machine(args.argv, getattr(args, "device", None)),
                }
                results.write_json(out / "results.json", body)
                rows = [planning.beside_best(row) for row in done]
                results.write_csv(out / "instances.csv", rows, planning.INSTANCE_COLUMNS)
            return interrupted(args.out, len(done), total, "plans")
    if getattr(args, "lama", False):
        result = _lama(suite, result, config.time_limit_s or 60.0, args.progress)
    if getattr(args, "baselines", None):
        names = ", ".join(args.baselines)
        with bar(len(suite.instances), f"baselines ({names})", args.progress, "instance") as update:
            result = planning.with_baselines(result, suite, args.baselines, update)
    body = results.results(result, args.argv)
    body["config"] = {**body["config"], **recorded}
    lines = None
    if peers:
        lines, rows = _peers(suite, result, peers, config.time_limit_s, args.progress)
        body["peers"] = {
            "time_limit_s": config.time_limit_s,
            "summary": [asdict(line) for line in lines],
            "instances": [asdict(row) for row in rows],
        }
    if args.out is not None:
        paths = results.write(result, args.out, body)
        if lines is not None:
            results.write_csv(results.out_folder(args.out) / "peers.csv", rows)
            paths = [*paths, results.out_folder(args.out) / "peers.csv"]
    if args.json:
        print(json.dumps(body, indent=2))
    else:
        print(tables.planning_report(result))
        if lines is not None:
            print(f"\nside by side, {config.time_limit_s:g} s per instance:")
            print(side_by_side.table(lines))
        if lengths:
            print(f"\nplan lengths by {result.size_name} (mean over seeds):")
            print(tables.lengths_table(result))
        if args.out is not None:
            print(f"\nwrote {', '.join(p.name for p in paths)} to {args.out}")
    return 0


def _peers(
    suite: suites.Suite,
    bench: planning.Bench,
    peers: tuple[str, ...],
    limit: float,
    progress: bool,
) -> tuple[list[side_by_side.Line], tuple[side_by_side.PeerRow, ...]]:
    """The peers on the suite's PDDL files, and the summary lines beside ours (the first
    horizon and seed)."""
    names = [i.name for i in suite.instances]
    instances = side_by_side.files(suite.source, names)
    total = len(peers) * len(instances)
    with bar(total, f"peers ({', '.join(peers)})", progress, "instance") as update:
        rows = side_by_side.run(instances, peers, limit, update)
    ours = [
        (r.instance, r.length if r.status == "valid" else None, r.time_s)
        for r in bench.runs[0].rows
    ]
    return side_by_side.summarise(suite.name, ours, rows), rows


def _lama(suite: suites.Suite, bench: planning.Bench, limit: float, progress: bool):
    """``bench`` with LAMA's lengths and times; unchanged, and one line on stderr, when the
    ``bench`` extra (Fast Downward) is not installed."""
    from tamp.bench import fast_downward

    if not fast_downward.available():
        print(
            f"LAMA skipped: Fast Downward is not installed (pip install 'soft-tamp[bench]', "
            f"the package {fast_downward.PACKAGE})",
            file=sys.stderr,
        )
        return bench
    with bar(len(suite.instances), "LAMA (lama-first)", progress, "instance") as update:
        return planning.with_lama(bench, suite, limit, update)


def planbench_command(args: argparse.Namespace) -> int:
    """An official PlanBench set of ``--domain`` (or a ``--limit`` spread of it)."""
    planning_config(args)  # refused combinations: before any work
    output_folder(args.out)
    data = args.data if args.data is not None else suites.default_data(args.domain)
    with _searching(args.progress) as update:
        suite = suites.planbench(data, args.limit, args.out, args.domain, update, args.domain_rules)
    return _run(suite, args, lengths=bool(args.baselines))  # the baselines' lengths beside ours


def pddl_command(args: argparse.Namespace) -> int:
    """Every problem of a folder of PDDL (``--limit``: a spread of them)."""
    planning_config(args)
    output_folder(args.out)
    if args.peers:
        side_by_side.require(args.peers)  # before any work: a missing package in one line
    with _searching(args.progress) as update:
        suite = suites.pddl_folder(args.data, args.limit, args.out, args.domain_rules, update)
    return _run(suite, args)


@contextmanager
def _searching(enabled: bool):
    """A bar for optimal lengths the data lack, opened at the first one searched (if any)."""
    bars = []

    def update(k: int) -> None:
        if not bars:
            bars.append(
                tqdm(
                    desc="optimal lengths the data lack",
                    unit="problem",
                    file=sys.stderr,
                    disable=not enabled,
                )
            )
        bars[0].update(k)

    try:
        yield update
    finally:
        for bar in bars:
            bar.close()


def random_command(args: argparse.Namespace) -> int:
    """``--n`` generated instances per ``--blocks`` count, optima from A* within a budget."""
    if min(args.blocks) < 2:
        raise TampError(f"--blocks: random problems need at least 2 blocks, got {min(args.blocks)}")
    planning_config(args)
    output_folder(args.out)
    total = len(args.blocks) * args.n
    with bar(total, "instances, A* optima", args.progress, "instance") as update:
        suite = suites.generated(args.blocks, args.n, args.seed, args.max_nodes, update)
    return _run(suite, args, lengths=True)
