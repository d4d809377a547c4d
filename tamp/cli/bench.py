"""``tamp bench planbench|pddl|random|motion|executability|perception|latplan|poses|segmentation``:
options in, `tamp.bench` runs, tables out.

Each handler turns options into configs, runs its benchmark from `tamp.bench` with a progress
bar on stderr, prints its table (``--json``: ``results.json``'s content), and with ``--out DIR``
writes its artefacts (`tamp.bench.results`). Exit 0 whatever the scores; 2 on bad input.
``motion`` and ``executability`` sweep many independent episodes: ``--workers N`` runs them in N
processes of this machine, ``--ray ADDRESS`` as Ray tasks on a cluster (`tamp.sweep.run_items`);
each episode has its own seed, so the rows are the same either way. Ctrl-C in a benchmark keeps
what is done: results.json marked ``partial`` (how many of how many) and the rows so far."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from contextlib import contextmanager
from dataclasses import replace
from functools import partial

from tqdm import tqdm

from tamp.bench import planning, results, suites, tables
from tamp.cli.options import planner_config, sim_list
from tamp.cli.recorded import (
    checkpoint,
    executability_config,
    given_config,
    latplan_config,
    loop_config,
    motion_config,
    perception_bench_config,
    planning_config,
    poses_config,
    segmentation_config,
)
from tamp.cli.recorded import out_folder as output_folder
from task.errors import TampError

__all__ = [  # the handlers `tamp.cli.parser` dispatches to
    "executability_command",
    "latplan_command",
    "motion_command",
    "pddl_command",
    "perception_command",
    "planbench_command",
    "poses_command",
    "random_command",
    "segmentation_command",
]


@contextmanager
def _bar(total: int, desc: str, enabled: bool, unit: str = "plan"):
    """A tqdm bar on stderr; yields ``update(k)``, the `plan_batch` progress callback."""
    with tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=not enabled) as bar:
        yield bar.update


def _run(suite: suites.Suite, args: argparse.Namespace, lengths: bool = False) -> int:
    """Plan ``suite`` as ``args`` say; ``lengths``: also print the plan-length table (and run
    LAMA beside with ``args.lama``)."""
    import torch

    torch.set_num_threads(args.threads)
    rules = {i.problem.domain for i in suite.instances}
    domain = rules.pop() if len(rules) == 1 else None
    recorded = planning_config(args, domain)
    config = planner_config(args, domain)
    if getattr(args, "one_at_a_time", False):
        config = replace(config, batched=False)
    horizons, seeds = args.horizons or (config.horizon,), tuple(range(args.seeds))
    total = planning.total(len(suite.instances), len(seeds), len(horizons), args.sequential)
    runs: list[planning.Run] = []
    with _bar(total, f"{suite.name} ({len(suite.instances)} instances)", args.progress) as update:
        try:
            result = planning.run(
                suite, config, seeds, horizons, args.sequential, update, runs.append
            )
        except KeyboardInterrupt:
            done = [row for run in runs for row in run.rows]
            if args.out is not None:
                out = results.out_folder(args.out)
                partial = {
                    "done": len(done),
                    "of": len(suite.instances) * len(seeds) * len(horizons),
                    "complete_runs": len(runs),  # a batched run keeps nothing until complete
                }
                body = {
                    "config": recorded,
                    "partial": partial,
                    "machine": results.machine(args.argv),
                }
                results.write_json(out / "results.json", body)
                results.write_csv(out / "instances.csv", done)
            return interrupted(args.out, len(done), total, "plans (complete horizon-seed runs)")
    if getattr(args, "lama", False):
        result = _lama(suite, result, config.time_limit_s or 60.0, args.progress)
    body = results.results(result, args.argv)
    body["config"] = {**body["config"], **recorded}
    if args.out is not None:
        paths = results.write(result, args.out, body)
    if args.json:
        print(json.dumps(body, indent=2))
    else:
        print(tables.planning_report(result))
        if lengths:
            print(f"\nplan lengths by {result.size_name} (mean over seeds):")
            print(tables.lengths_table(result))
        if args.out is not None:
            print(f"\nwrote {', '.join(p.name for p in paths)} to {args.out}")
    return 0


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
    with _bar(len(suite.instances), "LAMA (lama-first)", progress, "instance") as update:
        return planning.with_lama(bench, suite, limit, update)


def planbench_command(args: argparse.Namespace) -> int:
    """An official PlanBench set of ``--domain`` (or a ``--limit`` spread of it)."""
    planning_config(args)  # refused combinations: before any work
    output_folder(args.out)
    data = args.data if args.data is not None else suites.default_data(args.domain)
    with _searching(args.progress) as update:
        suite = suites.planbench(data, args.limit, args.out, args.domain, update, args.domain_rules)
    return _run(suite, args)


def pddl_command(args: argparse.Namespace) -> int:
    """Every problem of a folder of PDDL (``--limit``: a spread of them)."""
    planning_config(args)
    output_folder(args.out)
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
    with _bar(total, "instances, A* optima", args.progress, "instance") as update:
        suite = suites.generated(args.blocks, args.n, args.seed, args.max_nodes, update)
    return _run(suite, args, lengths=True)


def perception_command(args: argparse.Namespace) -> int:
    """Planning a ``--n`` spread of PlanBench from rendered images, per blur, mode and horizon."""
    import cv2
    import torch

    from perception.perceive import Perceiver
    from tamp.bench.vision import perception as bench
    from tamp.camera.from_images import PerceptionMode

    recorded = perception_bench_config(args)
    output_folder(args.out)
    names, crisps = bench.parse_modes(args.modes), bench.parse_crisp(args.crisp)
    corruption = bench.parse_corruption(args.corrupt)
    checkpoint(args.checkpoint)
    torch.set_num_threads(args.threads)
    suite = suites.planbench(args.data, args.n)
    chosen = list(suite.instances)
    perceiver = Perceiver.load(args.checkpoint, scene="cubes")  # PlanBench renders
    config = planner_config(args)
    horizons = args.horizons or (config.horizon,)
    modes = [  # ground truth (no images) once, as crisp "true"
        PerceptionMode(
            m,
            kl_weight=args.kl_weight,
            blur=r,
            adapt=args.adapt,
            crisp="true" if m == "state" else c,
        )
        for r in args.blur
        for m in names
        for c in crisps
        if not (m == "state" and (r != args.blur[0] or c != crisps[0]))
    ]
    with tqdm(
        total=len(modes) * len(horizons),
        desc="perception bench",
        unit="row",
        file=sys.stderr,
        disable=not args.progress,
    ) as bar:

        def progress(mode, horizon) -> None:
            bar.set_postfix(mode=mode.mode, blur=mode.blur, T=horizon, refresh=False)
            bar.update(1)

        result = bench.run(
            suite,
            modes,
            horizons,
            config,
            args.seed,
            perceiver,
            args.sim,
            example_blur=args.blur[-1],
            progress=progress,
            corruption=corruption,
        )
    split = {str(b): sum(i.blocks == b for i in chosen) for b in bench.sizes(chosen)}
    body = {
        "suite": suite.name,
        "source": suite.source,
        "n": len(chosen),
        "instances": [i.name for i in chosen],
        "split": split,
        "sim": args.sim,
        "checkpoint": str(args.checkpoint),
        "seed": args.seed,
        "threads": args.threads,
        "cores": os.cpu_count(),
        "machine": results.machine(args.argv),
        "date": time.strftime("%Y-%m-%d"),
        "redrawn_renders": result.redrawn,
        "corruption": corruption.name,
        "rows": list(result.summaries),
        "config": recorded,
    }
    if args.out:
        out = results.out_folder(args.out)
        results.write_json(out / "results.json", body)
        results.write_csv(out / "instances.csv", result.rows)
        cv2.imwrite(str(out / "example.png"), result.example[..., ::-1])
    if args.json:
        print(json.dumps(body, indent=2))
    else:
        print(
            f"{suite.name}: {len(chosen)} instances ({'/'.join(map(str, split.values()))} by "
            f"block count), sim {args.sim}, images: {corruption.name}"
        )
        print(tables.perception_table(list(result.summaries)))
        if result.redrawn:
            print(f"{result.redrawn} renders redrawn because a block was hidden")
    return 0


def latplan_command(args: argparse.Namespace) -> int:
    """LatPlan-40 planned from its true states and from its images, per resolution and mode."""
    from dataclasses import asdict

    import torch

    from tamp.bench.vision import latplan
    from tamp.bench.vision.perception import choices

    recorded = latplan_config(args)
    output_folder(args.out)
    res = choices(args.res, tuple(latplan.FILES), "--res", "resolution")
    modes = choices(args.modes, latplan.MODES, "--modes", "mode")
    if any(m != "state" for m in modes):
        checkpoint(args.checkpoint)
    data = latplan.load(args.data, args.limit)
    images = any(m != "state" for m in modes)
    perceiver = latplan.load_perceiver(args.checkpoint) if images else None
    torch.set_num_threads(args.threads)
    config = planner_config(args, "blocksworld")
    seeds = tuple(range(args.seeds))
    total = latplan.total(len(data.instances), len(res), modes, len(seeds))
    with _bar(total, f"latplan ({len(data.instances)} instances)", args.progress) as update:
        rows = latplan.run(data, perceiver, res, modes, seeds, config, update)
    summary = latplan.summaries(rows)
    options = {
        "checkpoint": str(args.checkpoint) if images else None,
        "resolutions": list(res),
        "modes": list(modes),
        "seeds": list(seeds),
        "threads": args.threads,
        "config": asdict(config),
        "recorded": recorded,
    }
    body = latplan.report(data, rows, summary, options, results.machine(args.argv))
    if args.out is not None:
        out = results.out_folder(args.out)
        results.write_json(out / "results.json", body)
        results.write_csv(out / "instances.csv", rows, digits=3)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    print(
        f"LatPlan-40: {len(data.instances)} instances from {data.root}, seeds 0..{seeds[-1]}; "
        "valid and optimal judged against each instance's PDDL (full-state goals)"
    )
    print(tables.latplan_table(summary))
    if args.out is not None:
        print(f"\nwrote results.json, instances.csv to {args.out}")
    return 0


def poses_command(args: argparse.Namespace) -> int:
    """Block poses from RGB-D images of ``--n`` random scenes in each ``--sim``, against truth."""
    from tamp.bench.vision import poses

    recorded = poses_config(args)
    output_folder(args.out)
    sims = sim_list(args.sim)
    with tqdm(
        total=args.n * len(sims),
        desc="poses",
        unit="scene",
        file=sys.stderr,
        disable=not args.progress,
    ) as bar:
        result = poses.run(
            sims,
            args.n,
            args.seed,
            args.min_blocks,
            args.max_blocks,
            args.jitter,
            lambda sim: bar.update(1),
        )
    body = {
        "config": recorded,
        "machine": results.machine(args.argv),
        "summary": result.summary,
    }
    if args.out:
        out = results.out_folder(args.out)
        results.write_json(out / "results.json", body)
        results.write_csv(out / "blocks.csv", poses.block_rows(result), digits=3)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    view = "random camera and light" if args.jitter else "default camera and light"
    print(
        f"pose benchmark: {args.n} scenes of {args.min_blocks}-{args.max_blocks} blocks per "
        f"simulator, {view}, seed {args.seed}; errors against the true poses"
    )
    print(tables.poses_table(result.summary))
    times = ", ".join(
        f"{sim} {s['estimate_ms_per_image']:.0f} ms" for sim, s in result.summary.items()
    )
    print(
        f"estimation per image: {times}; yaw modulo 90 degrees; top free: nothing rests on "
        f"the block; covered: its top face is under another block"
    )
    if args.out:
        print(f"wrote results.json, blocks.csv to {args.out}")
    return 0


def segmentation_command(args: argparse.Namespace) -> int:
    """The colour segmentation's thresholds on each dataset file, read as ``--checkpoint``
    reads images: blocks found per colour, scenes read right, margins of the dark class."""
    from perception import data as pdata
    from perception.train import load_checkpoint
    from tamp.bench.vision import segmentation

    recorded = segmentation_config(args)  # missing files: before any work
    output_folder(args.out)
    checkpoint(args.checkpoint)
    model, meta = load_checkpoint(args.checkpoint)
    datasets = {str(path): pdata.load(path) for path in args.data}
    for path, data in datasets.items():
        segmentation.check_scene(path, data.meta, meta)
    input_hw = meta.get("input_hw")
    head = {
        "benchmark": "segmentation",
        "config": recorded,
        "input_hw": list(input_hw) if input_hw is not None else None,
        "thresholds": segmentation.thresholds(),
    }
    files: dict[str, dict] = {}
    total = sum(len(d) for d in datasets.values())
    with _bar(total, f"segmentation ({len(datasets)} files)", args.progress, "image") as update:
        try:
            for path, data in datasets.items():
                files[path] = segmentation.check(data, model, input_hw, update)
        except KeyboardInterrupt:
            if args.out is not None:
                body = {
                    **head,
                    "partial": {"done": len(files), "of": len(datasets)},
                    "machine": results.machine(args.argv),
                    "files": files,
                }
                results.write_json(results.out_folder(args.out) / "results.json", body)
            return interrupted(args.out, len(files), len(datasets), "files")
    body = {**head, "machine": results.machine(args.argv), "files": files}
    if args.out is not None:
        results.write_json(results.out_folder(args.out) / "results.json", body)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    size = "" if input_hw is None else f", images resized to {input_hw[1]}x{input_hw[0]}"
    guards = ", ".join(f"{k} {v}" for k, v in head["thresholds"]["unguarded"].items())
    print(
        f"segmentation check: {len(files)} file(s), {total} images, read by {args.checkpoint}"
        f"{size}; blocks found under the current thresholds and unguarded ({guards})"
    )
    print(tables.segmentation_table(files))
    if any("dark_margins" in f for f in files.values()):
        print("\ndark-class margins of the found black regions (per image: median over its pixels)")
        print(tables.dark_margins_table(files))
    if args.out is not None:
        print(f"\nwrote results.json to {args.out}")
    return 0


DEFAULT_N = 20  # bench executability: instances when --n is not given (fewer if fewer named)


def interrupted(out, done: int, total: int, what: str) -> int:
    """After Ctrl-C in a benchmark: say what was kept (exit 130)."""
    kept = (
        f"wrote the {done} done to {out}, marked partial" if out else "nothing written (no --out)"
    )
    print(f"tamp: interrupted after {done} of {total} {what}; {kept}", file=sys.stderr)
    return 130


def motion_command(args: argparse.Namespace) -> int:
    """Closed-loop episodes on a ``--n`` spread of PlanBench (or random ``--blocks``
    problems) in each ``--sim``."""
    from tamp.bench import motion
    from tamp.slots import fits

    recorded = motion_config(args)  # refused combinations: before any work
    output_folder(args.out)
    if args.observe == "camera":
        checkpoint(args.checkpoint)
    sims, base = sim_list(args.sim), loop_config(args)
    if args.blocks:
        suite = suites.generated(
            args.blocks, args.n, args.seed, keep=partial(fits, scene=base.scene)
        )
    else:
        suite = suites.planbench(args.data, args.n)
    recorded |= {"n": len(suite.instances), "source": suite.source}
    goals, done = dict.fromkeys(sims, 0), []
    total = len(sims) * len(suite.instances)
    with tqdm(
        total=total, desc="motion", unit="episode", file=sys.stderr, disable=not args.progress
    ) as bar:

        def progress(sim: str, report) -> None:
            done.append(report)
            goals[sim] += report.reached_goal
            bar.set_postfix(sim=sim, goal=goals[sim], refresh=False)
            bar.update(1)

        try:
            result = motion.run(suite, base, sims, args.seed, progress, args.workers, args.ray)
        except KeyboardInterrupt:
            if args.out:
                _motion_partial(args.out, recorded, suite, done, sims, base, total)
            return interrupted(args.out, len(done), total, "episodes")
    inject = str(base.inject)
    body = {
        "config": recorded,
        "machine": results.machine(args.argv),
        "ik_batch": result.ik,
        "summary": result.summary,
    }
    if args.out:
        out = results.out_folder(args.out)
        results.write_json(out / "results.json", body)
        rows = motion.episode_rows(result.reports)
        results.write_csv(out / "episodes.csv", rows, motion.EPISODE_COLUMNS)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    seen = base.observe + (
        f" ({base.perception.mode} perception)" if base.observe == "camera" else ""
    )
    kind = "PlanBench" if not args.blocks else f"random ({base.scene.name} scene)"
    print(
        f"motion benchmark: {len(suite.instances)} {kind} instances, grasp {base.grasp}, "
        f"observe {seen}, crisp {base.crisp}, faults {inject}, seed {args.seed}"
    )
    print(tables.motion_table(result.summary, inject))
    ik = result.ik
    print(
        f"IK: one batched call on {ik['n']} targets took {ik['time_s']:.3f} s "
        f"({ik['converged']}/{ik['n']} converged)"
    )
    if args.out:
        print(f"wrote results.json, episodes.csv to {args.out}")
    return 0


def _motion_partial(out, recorded: dict, suite, done: list, sims, base, total: int) -> None:
    """The episodes done before Ctrl-C: episodes.csv and a results.json marked partial."""
    from tamp.bench import motion

    named = {i.name: i for i in suite.instances}
    summary = {}
    for sim in sims:
        mine = [r for r in done if r.sim == sim]
        if mine:
            instances = [named[r.problem] for r in mine]
            camera = base.observe == "camera"
            summary[sim] = motion.summarise(mine, instances, suite.domain, camera)
    folder = results.out_folder(out)
    body = {
        "config": recorded,
        "partial": {"done": len(done), "of": total},
        "machine": results.machine(),
        "summary": summary,
    }
    results.write_json(folder / "results.json", body)
    results.write_csv(folder / "episodes.csv", motion.episode_rows(done), motion.EPISODE_COLUMNS)


def executability_command(args: argparse.Namespace) -> int:
    """Each ``--plans`` source's plans and ours, executed open-loop in each ``--sim``, on the
    instances the plan files name (``--n``: a spread of at most N of them)."""
    import torch

    from tamp.bench import executability as bench

    recorded = executability_config(args)  # refused combinations: before any work
    output_folder(args.out)
    sims, sources = sim_list(args.sim), bench.read_sources(args.plans)
    names = bench.named(sources)
    if args.n is not None and args.n > len(names):
        raise TampError(
            f"--n {args.n}: the plan files name {len(names)} instance"
            f"{'' if len(names) == 1 else 's'}; give at most that many (or leave --n out)"
        )
    limit = args.n if args.n is not None else min(DEFAULT_N, len(names))
    suite = suites.planbench(args.data, limit, names=names)
    torch.set_num_threads(args.threads)
    base = given_config(args)
    ours, wall0 = base.planner if args.ours else None, time.perf_counter()
    recorded["instances"] = [i.name for i in suite.instances]
    total = len(sims) * len(suite.instances) * (len(sources) + bool(ours))
    done = []
    with tqdm(
        total=total, desc="executability", unit="plan", file=sys.stderr, disable=not args.progress
    ) as bar:

        def progress(sim: str, row) -> None:
            done.append(row)
            bar.update(1)

        try:
            rows = bench.run_given(
                suite, sources, base, sims, args.seed, ours, progress, args.workers, args.ray
            )
        except KeyboardInterrupt:
            if args.out:
                folder = results.out_folder(args.out)
                body = {
                    "config": recorded,
                    "partial": {"done": len(done), "of": total},
                    "machine": results.machine(args.argv),
                    "summary": bench.given_summary(done, sims) if done else [],
                }
                results.write_json(folder / "results.json", body)
                results.write_csv(folder / "plans.csv", done, digits=2)
            return interrupted(args.out, len(done), total, "plans")
    summary, wall = bench.given_summary(rows, sims), time.perf_counter() - wall0
    body = {
        "config": recorded,
        "machine": results.machine(args.argv),
        "wall_s": wall,
        "summary": summary,
    }
    if args.out:
        out = results.out_folder(args.out)
        results.write_json(out / "results.json", body)
        results.write_csv(out / "plans.csv", rows, digits=2)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    print(
        f"executability: {len(suite.instances)} PlanBench instances named by --plans, "
        f"open-loop, grasp {args.grasp}, seed {args.seed}; goal: ground truth; {wall:.0f} s wall",
        tables.executability_table(summary, sims),
        sep="\n",
    )
    if args.out:
        print(f"wrote results.json, plans.csv to {args.out}")
    return 0
