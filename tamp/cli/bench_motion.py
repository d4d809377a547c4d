"""``tamp bench motion|executability``: options in, `tamp.bench.motion` runs, tables out.

Both sweep many independent episodes: ``--workers N`` runs them in N processes of this machine,
``--ray ADDRESS`` as Ray tasks on a cluster (`tamp.sweep.run_items`); each episode has its own
seed, so the rows are the same either way. `tamp.cli.bench` dispatches here."""

from __future__ import annotations

import argparse
import json
import sys
import time
from functools import partial

from tqdm import tqdm

from tamp.bench import results, suites, tables
from tamp.cli.options import data_option, planner_config, positive, positive_list, sim_list


def sweep_options(p: argparse.ArgumentParser) -> None:
    """``--workers`` and ``--ray``: where the episodes run."""
    p.add_argument(
        "--workers",
        type=positive,
        default=1,
        metavar="N",
        help="run the episodes in N processes at once, one torch thread each (1: in "
        "this process); the rows do not depend on N",
    )
    p.add_argument(
        "--ray",
        metavar="ADDRESS",
        help="run the episodes as Ray tasks instead (overrides --workers): auto (the "
        "cluster this machine joined with 'ray start'), local (a Ray instance on this "
        "machine only) or HOST:6379; needs pip install 'soft-tamp[ray]'",
    )


def suite_options(p: argparse.ArgumentParser) -> None:
    """What ``bench motion`` runs: a spread of PlanBench, or random problems (``--blocks``)."""
    data_option(p)
    p.add_argument(
        "--n",
        type=positive,
        default=100,
        help="instances, spread over sizes; with --blocks, per block count (100)",
    )
    p.add_argument(
        "--blocks",
        type=positive_list,
        metavar="B[,B...]",
        help="random problems of these block counts instead of PlanBench, seeded by --seed, "
        "those whose towers fit --scene (episodes.csv lists them)",
    )


def motion_command(args: argparse.Namespace) -> int:
    """Closed-loop episodes on a ``--n`` spread of PlanBench (or random ``--blocks``
    problems) in each ``--sim``."""
    from tamp.bench import motion
    from tamp.cli.run import loop_config
    from tamp.slots import fits

    sims, base = sim_list(args.sim), loop_config(args)
    if args.blocks:
        suite = suites.generated(
            args.blocks, args.n, args.seed, keep=partial(fits, scene=base.scene)
        )
    else:
        suite = suites.planbench(args.data, args.n)
    goals = dict.fromkeys(sims, 0)
    with tqdm(
        total=len(sims) * len(suite.instances),
        desc="motion",
        unit="episode",
        file=sys.stderr,
        disable=not args.progress,
    ) as bar:

        def progress(sim: str, report) -> None:
            goals[sim] += report.reached_goal
            bar.set_postfix(sim=sim, goal=goals[sim], refresh=False)
            bar.update(1)

        result = motion.run(suite, base, sims, args.seed, progress, args.workers, args.ray)
    inject = str(base.inject)
    body = {
        "config": {
            "sims": sims,
            "n": len(suite.instances),
            "inject": inject,
            "grasp": base.grasp,
            "seed": args.seed,
            "data": str(args.data),
            "observe": base.observe,
            "perception": base.perception.mode,
            "blur": base.perception.blur,
            "crisp": base.crisp,
            "scene": base.scene.name,
            "collision": base.execution.collision,
            "lambda_motion": base.planner.lambda_motion,
            "workers": args.workers,
            "ray": args.ray,
            "blocks": args.blocks,
            "source": suite.source,
        },
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


def executability_command(args: argparse.Namespace) -> int:
    """Each ``--plans`` source's plans and ours, executed open-loop in each ``--sim``."""
    import torch

    from tamp.bench import motion
    from tamp.cli.run import given_config

    sims, sources = sim_list(args.sim), motion.read_sources(args.plans)
    suite, out = suites.planbench(args.data, args.n), args.out and results.out_folder(args.out)
    torch.set_num_threads(args.threads)
    ours, wall0 = planner_config(args, "blocksworld") if args.ours else None, time.perf_counter()
    with tqdm(
        total=len(sims) * len(suite.instances) * (len(sources) + bool(ours)),
        desc="executability",
        unit="plan",
        file=sys.stderr,
        disable=not args.progress,
    ) as bar:
        rows = motion.run_given(
            suite,
            sources,
            given_config(args),
            sims,
            args.seed,
            ours,
            lambda sim, row: bar.update(1),
            args.workers,
            args.ray,
        )
    summary, wall = motion.given_summary(rows, sims), time.perf_counter() - wall0
    body = {
        "config": {
            "plans": str(args.plans),
            "sims": sims,
            "instances": [i.name for i in suite.instances],
            "seed": args.seed,
            "grasp": args.grasp,
            "ours": args.ours,
            "data": str(args.data),
            "scene": args.scene,
            "collision": args.collision,
            "workers": args.workers,
            "ray": args.ray,
        },
        "machine": results.machine(args.argv),
        "wall_s": wall,
        "summary": summary,
    }
    if out:
        results.write_json(out / "results.json", body)
        results.write_csv(out / "plans.csv", rows, digits=2)
    if args.json:
        print(json.dumps(body, indent=2))
        return 0
    print(
        f"executability: {len(suite.instances)} PlanBench instances, open-loop, grasp "
        f"{args.grasp}, seed {args.seed}; goal: ground truth; {wall:.0f} s wall",
        tables.executability_table(summary, sims),
        sep="\n",
    )
    if out:
        print(f"wrote results.json, plans.csv to {out}")
    return 0
