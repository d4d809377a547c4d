"""``tamp bench perception|latplan|poses|segmentation``: the benchmarks of seeing
(`tamp.bench.vision`)."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

from tqdm import tqdm

from tamp.bench import results, suites, tables
from tamp.cli.bench import bar, interrupted
from tamp.cli.options import planner_config
from tamp.cli.recorded import (
    checkpoint,
    latplan_config,
    perception_bench_config,
    poses_config,
    segmentation_config,
)
from tamp.cli.recorded import out_folder as output_folder
from tamp.cli.types import sim_list
from tamp.modes import Crisp, Perception


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
    config = planner_config(args)
    perceiver = Perceiver.load(args.checkpoint, "cubes", config.device)  # PlanBench renders
    horizons = args.horizons or (config.horizon,)
    modes = [  # ground truth (no images) once, as crisp "true"
        PerceptionMode(
            m,
            kl_weight=args.kl_weight,
            blur=r,
            adapt=args.adapt,
            crisp=Crisp.TRUE if m == Perception.STATE else c,
        )
        for r in args.blur
        for m in names
        for c in crisps
        if not (m == Perception.STATE and (r != args.blur[0] or c != crisps[0]))
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
        "machine": results.machine(args.argv, getattr(args, "device", None)),
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
    modes = choices(args.modes, [m.value for m in Perception], "--modes", "mode")
    if any(m != Perception.STATE for m in modes):
        checkpoint(args.checkpoint)
    data = latplan.load(args.data, args.limit)
    images = any(m != Perception.STATE for m in modes)
    config = planner_config(args, "blocksworld")
    perceiver = latplan.load_perceiver(args.checkpoint, config.device) if images else None
    torch.set_num_threads(args.threads)
    seeds = tuple(range(args.seeds))
    total = latplan.total(len(data.instances), len(res), modes, len(seeds))
    with bar(total, f"latplan ({len(data.instances)} instances)", args.progress) as update:
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
    body = latplan.report(
        data, rows, summary, options, results.machine(args.argv, getattr(args, "device", None))
    )
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
        "machine": results.machine(args.argv, getattr(args, "device", None)),
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
    model = model.to(args.device)
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
    with bar(total, f"segmentation ({len(datasets)} files)", args.progress, "image") as update:
        try:
            for path, data in datasets.items():
                files[path] = segmentation.check(data, model, input_hw, update)
        except KeyboardInterrupt:
            if args.out is not None:
                body = {
                    **head,
                    "partial": {"done": len(files), "of": len(datasets)},
                    "machine": results.machine(args.argv, getattr(args, "device", None)),
                    "files": files,
                }
                results.write_json(results.out_folder(args.out) / "results.json", body)
            return interrupted(args.out, len(files), len(datasets), "files")
    body = {
        **head,
        "machine": results.machine(args.argv, getattr(args, "device", None)),
        "files": files,
    }
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
