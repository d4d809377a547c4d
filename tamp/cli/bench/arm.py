"""``tamp bench motion|executability``: the arm benchmarks, many independent episodes.

``--workers N`` runs them in N processes, ``--ray ADDRESS`` as Ray tasks
(`tamp.sweep.run_items`); each episode has its own seed, so the rows are the same either way."""

from __future__ import annotations

import argparse
import json
import sys
import time
from functools import partial

from tqdm import tqdm

from tamp.bench import results, suites, tables
from tamp.cli.bench import interrupted
from tamp.cli.recorded import checkpoint, executability_config, given_config
from tamp.cli.recorded import out_folder as output_folder
from tamp.cli.settings.motion import MotionSettings, motion_record
from tamp.cli.types import sim_list
from tamp.modes import Observation
from tamp.rerun_log import require_rerun
from task.errors import TampError

DEFAULT_N = 20  # bench executability: instances when --n is not given (fewer if fewer named)


def motion_command(settings: MotionSettings) -> int:
    """Closed-loop episodes on a ``--n`` spread of PlanBench (or random ``--blocks``
    problems) in each ``--sim`` (``settings``: `tamp.cli.settings.motion.motion_settings`)."""
    from tamp.bench import motion
    from tamp.slots import fits

    recorded = motion_record(settings)
    output = settings.output
    output_folder(output.out)
    if output.record:
        require_rerun()  # the optional extra: a one-line error naming it
    sims, base = settings.sims, settings.loop
    if base.observe == Observation.CAMERA:
        checkpoint(base.checkpoint)
    if settings.blocks:
        suite = suites.generated(
            settings.blocks, settings.n, settings.seed, keep=partial(fits, scene=base.scene)
        )
    else:
        suite = suites.planbench(settings.data, settings.n)
    recorded |= {"n": len(suite.instances), "source": suite.source}
    goals, done = dict.fromkeys(sims, 0), []
    total = len(sims) * len(suite.instances)
    with tqdm(
        total=total, desc="motion", unit="episode", file=sys.stderr, disable=not output.progress
    ) as bar:

        def progress(sim: str, report) -> None:
            done.append(report)
            goals[sim] += report.reached_goal
            bar.set_postfix(sim=sim, goal=goals[sim], refresh=False)
            bar.update(1)

        try:
            record = output.out if output.record else None  # OUT/recordings/SIM-INSTANCE.rrd
            result = motion.run(
                suite, base, sims, settings.seed, progress, settings.workers, settings.ray, record
            )
        except KeyboardInterrupt:
            if output.out:
                _motion_partial(output.out, recorded, suite, done, sims, base, total)
            return interrupted(output.out, len(done), total, "episodes")
    inject = str(base.inject)
    body = {
        "config": recorded,
        "machine": results.machine(output.argv, output.device),
        "ik_batch": result.ik,
        "summary": result.summary,
    }
    if output.out:
        out = results.out_folder(output.out)
        results.write_json(out / "results.json", body)
        rows = motion.episode_rows(result.reports)
        results.write_csv(out / "episodes.csv", rows, motion.EPISODE_COLUMNS)
    if output.json:
        print(json.dumps(body, indent=2))
        return 0
    seen = base.observe + (
        f" ({base.perception.mode} perception)" if base.observe == Observation.CAMERA else ""
    )
    kind = "PlanBench" if not settings.blocks else f"random ({base.scene.name} scene)"
    print(
        f"motion benchmark: {len(suite.instances)} {kind} instances, grasp {base.grasp}, "
        f"observe {seen}, crisp {base.crisp}, faults {inject}, seed {settings.seed}"
    )
    print(tables.motion_table(result.summary, inject))
    ik = result.ik
    print(
        f"IK: one batched call on {ik['n']} targets took {ik['time_s']:.3f} s "
        f"({ik['converged']}/{ik['n']} converged); a move's six waypoints in one call: "
        f"median {1000 * ik['waypoints_median_s']:.1f} ms over {ik['moves']} random moves "
        f"({ik['moves_solved']} solved)"
    )
    for sim, s in result.summary.items():
        print(
            f"{sim} per move: wall {s['wall_per_move_s']:.3f} s, simulated "
            f"{s['sim_per_move_s']:.2f} s, IK and timing {s['ik_per_move_s']:.3f} s, "
            f"collision checks {s['check_per_move_s']:.3f} s, motion planner "
            f"{s['path_per_move_s']:.3f} s"
        )
    if output.out:
        also = ", recordings/" if output.record else ""
        print(f"wrote results.json, episodes.csv{also} to {output.out}")
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
            camera = base.observe == Observation.CAMERA
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
    if args.record:
        require_rerun()  # the optional extra: a one-line error naming it
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
            record = args.out if args.record else None  # OUT/recordings/SIM-INSTANCE-SOURCE.rrd
            rows = bench.run_given(
                suite,
                sources,
                base,
                sims,
                args.seed,
                ours,
                progress,
                args.workers,
                args.ray,
                record,
            )
        except KeyboardInterrupt:
            if args.out:
                folder = results.out_folder(args.out)
                body = {
                    "config": recorded,
                    "partial": {"done": len(done), "of": total},
                    "machine": results.machine(args.argv, getattr(args, "device", None)),
                    "summary": bench.given_summary(done, sims) if done else [],
                }
                results.write_json(folder / "results.json", body)
                results.write_csv(folder / "plans.csv", done, digits=2)
            return interrupted(args.out, len(done), total, "plans")
    summary, wall = bench.given_summary(rows, sims), time.perf_counter() - wall0
    body = {
        "config": recorded,
        "machine": results.machine(args.argv, getattr(args, "device", None)),
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
        also = ", recordings/" if args.record else ""
        print(f"wrote results.json, plans.csv{also} to {args.out}")
    return 0
