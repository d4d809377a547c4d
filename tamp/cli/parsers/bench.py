"""The ``tamp bench`` command group's parsers: one function per benchmark (or family of
benchmarks), each binding its handler from `tamp.cli.bench`; `bench_commands` adds them all.
"""

from __future__ import annotations

import argparse

from perception import CHECKPOINT
from tamp.bench.official import DEFAULT_DATA
from tamp.cli.bench.options import (
    executability_options,
    perception_bench_options,
    suite_options,
    sweep_options,
    tamp_bench_options,
)
from tamp.cli.options import (
    SCENES,
    data_option,
    device_option,
    episode_options,
    output_options,
    peers_option,
    progress_option,
    rules_option,
)
from tamp.cli.parsers.handlers import at_edge, lazy
from tamp.cli.types import (
    MAX_BLOCKS,
    PLAN_THREADS,
    baseline_list,
    block_counts,
    bounded,
    nonnegative,
    positive,
    positive_list,
    seed,
    threads,
)
from tamp.sim.base import SIMULATORS

_MOTION_EDGE = "tamp.cli.settings.motion.motion_settings"


def bench_commands(
    sub, plan_opts: argparse.ArgumentParser, bench_opts: argparse.ArgumentParser
) -> None:
    """``bench SUITE``: every benchmark, ``bench record`` last."""
    bench = sub.add_parser("bench", help="planning benchmarks").add_subparsers(
        dest="suite", required=True, metavar="SUITE"
    )
    _planning_benchmarks(bench, bench_opts)
    _motion_benchmark(bench, plan_opts)
    _executability_benchmark(bench, plan_opts)
    _tamp_benchmark(bench)
    _checker_benchmark(bench)
    _perception_benchmark(bench, bench_opts)
    _latplan_benchmark(bench, plan_opts)
    _poses_benchmark(bench)
    _segmentation_benchmark(bench)
    _record_command(bench)


def _planning_benchmarks(bench, bench_opts: argparse.ArgumentParser) -> None:
    """``bench planbench``, ``bench pddl`` and ``bench random``."""
    for name, what in (
        ("planbench", "PlanBench Blocksworld-600, Logistics-200 or Sokoban-55"),
        ("pddl", "a folder of a PDDL domain and its problems (e.g. IPC gripper)"),
        ("random", "random blocksworld problems"),
    ):
        p = bench.add_parser(name, parents=[bench_opts], help=f"benchmark on {what}")
        p.add_argument(
            "--seeds", type=positive, default=1, metavar="S", help="planner seeds 0..S-1 (1)"
        )
        p.add_argument(
            "--sequential",
            type=nonnegative,
            default=0,
            metavar="N",
            help="also time batched vs sequential planning on the first N instances",
        )
        p.add_argument(
            "--no-crisp-check",
            dest="crisp_check",
            action="store_false",
            help="keep a window's strongest move even when it is illegal (the plan is then "
            "inexecutable); measures the soft planner without the decoder's legality filter",
        )
        p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
        progress_option(p)
        output_options(p, "write instances.csv, results.json and steps.png into this folder")
    planbench, random_ = bench.choices["planbench"], bench.choices["random"]
    data_option(planbench, domains=True)
    rules_option(planbench)
    folder = bench.choices["pddl"]
    folder.add_argument(
        "--data", required=True, metavar="DIR", help="folder with domain.pddl and problem files"
    )
    rules_option(folder)
    peers_option(folder)
    for p in (planbench, folder):
        p.add_argument(
            "--limit",
            type=positive,
            metavar="N",
            help="a spread of N instances over the sizes (all)",
        )
    planbench.set_defaults(
        func=lazy("tamp.cli.bench.planning", "planbench_command"),
        recorded=lazy("tamp.cli.recorded", "planning_config"),
    )
    folder.set_defaults(
        func=lazy("tamp.cli.bench.planning", "pddl_command"),
        recorded=lazy("tamp.cli.recorded", "planning_config"),
    )
    random_.add_argument(
        "--blocks",
        type=block_counts,
        default=(6, 8, 10, 15, 20),
        metavar="B[,B...]",
        help="block counts (6,8,10,15,20)",
    )
    random_.add_argument("--n", type=positive, default=50, help="instances per block count (50)")
    random_.add_argument("--seed", type=seed, default=0, help="instance generator seed (0)")
    random_.add_argument(
        "--max-nodes",
        type=positive,
        default=20_000,
        metavar="N",
        help="A* expansion budget for the optimal lengths (20000)",
    )
    random_.add_argument(
        "--one-at-a-time",
        action="store_true",
        help="plan one instance at a time, each within its own --time-limit "
        "(default: batched, a batch shares the limit)",
    )
    random_.add_argument(
        "--lama",
        action="store_true",
        help="also run Fast Downward's LAMA (first plan, --time-limit or "
        "60 s) on every instance: its length and time beside ours (needs the "
        "bench extra)",
    )
    for p in (planbench, random_):
        p.add_argument(
            "--baselines",
            type=baseline_list,
            metavar="B[,B]",
            help="also plan every instance with Slaney & Thiebaux's near-optimal Blocksworld "
            "algorithms us (unstack-stack) and/or gn1 (Gupta & Nau's, constructive moves "
            "first): their validated lengths and times beside ours (none; Blocksworld only)",
        )
    random_.set_defaults(
        func=lazy("tamp.cli.bench.planning", "random_command"),
        recorded=lazy("tamp.cli.recorded", "planning_config"),
    )


def _motion_benchmark(bench, plan_opts: argparse.ArgumentParser) -> None:
    p = bench.add_parser(
        "motion", parents=[plan_opts], help="motion-level executability in the simulators"
    )
    episode_options(p, multi_sim=True)
    suite_options(p)
    p.add_argument("--seed", type=seed, default=0, help="scene, planner and fault seed (0)")
    sweep_options(p)
    progress_option(p)
    output_options(p, "write results.json and episodes.csv into this folder")
    p.set_defaults(
        func=at_edge(_MOTION_EDGE, "tamp.cli.bench.arm.motion_command"),
        recorded=at_edge(_MOTION_EDGE, "tamp.cli.settings.motion.motion_record"),
    )


def _executability_benchmark(bench, plan_opts: argparse.ArgumentParser) -> None:
    p = bench.add_parser(
        "executability",
        parents=[plan_opts],
        help="execute plans of any source (CSV) open-loop in the simulators",
    )
    executability_options(p)
    sweep_options(p)
    p.set_defaults(
        func=lazy("tamp.cli.bench.arm", "executability_command"),
        recorded=lazy("tamp.cli.recorded", "executability_config"),
    )


def _tamp_benchmark(bench) -> None:
    p = bench.add_parser(
        "tamp",
        help="the canonical TAMP problems where geometry decides the plan, planners side by side",
    )
    tamp_bench_options(p)
    sweep_options(p)
    progress_option(p)
    output_options(p, "write results.json and episodes.csv (and with --video, videos/) here")
    p.set_defaults(
        func=lazy("tamp.cli.bench.geo", "tamp_command"),
        recorded=lazy("tamp.cli.recorded", "tamp_bench_config"),
    )


def _checker_benchmark(bench) -> None:
    p = bench.add_parser(
        "checker",
        help="the sphere collision checker: configurations/s on one core, no false free against "
        "the meshes, rerouted moves",
    )
    p.add_argument(
        "--scenes",
        default="shelf,clutter,cramped",
        metavar="SCENE[,SCENE]",
        help=f"obstacle scenes with seeded towers of blocks, from {','.join(SCENES)} (%(default)s)",
    )
    p.add_argument(
        "--batch",
        type=positive_list,
        default=(1_000, 10_000, 100_000),
        metavar="B[,B...]",
        help="configurations per batched call timed (1000,10000,100000)",
    )
    p.add_argument("--repeats", type=positive, default=5, help="timed calls per batch size (5)")
    p.add_argument(
        "--near",
        type=positive,
        default=2_000,
        help="configurations near obstacles per scene checked by both models (2000)",
    )
    p.add_argument("--moves", type=positive, default=20, help="rerouted moves per scene (20)")
    p.add_argument(
        "--no-baseline",
        dest="baseline",
        action="store_false",
        help="do not also plan each move with OMPL's RRT-Connect on the mesh model alone",
    )
    p.add_argument("--seed", type=seed, default=0, help="scene, sample and planner seed (0)")
    progress_option(p)
    output_options(p, "write results.json, throughput.csv and moves.csv into this folder")
    p.set_defaults(
        func=lazy("tamp.cli.bench.checker", "checker_command"),
        recorded=lazy("tamp.cli.bench.checker", "checker_config"),
    )


def _perception_benchmark(bench, bench_opts: argparse.ArgumentParser) -> None:
    p = bench.add_parser(
        "perception", parents=[bench_opts], help="planning PlanBench instances from rendered images"
    )
    data_option(p)
    p.add_argument(
        "--n", type=positive, default=100, help="instances over block counts (100: 17/74/9)"
    )
    perception_bench_options(p, str(CHECKPOINT))
    p.add_argument("--seed", type=seed, default=0, help="planner and layout seed (0)")
    p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
    progress_option(p)
    output_options(p, "write results.json, instances.csv and example.png into this folder")
    p.set_defaults(
        func=lazy("tamp.cli.bench.vision", "perception_command"),
        recorded=lazy("tamp.cli.recorded", "perception_bench_config"),
    )


def _latplan_benchmark(bench, plan_opts: argparse.ArgumentParser) -> None:
    p = bench.add_parser("latplan", parents=[plan_opts], help="LatPlan-40: plan from its images")
    p.add_argument(
        "--data",
        default=str(DEFAULT_DATA / "latplan"),
        metavar="DIR",
        help="LatPlan-40 folder (%(default)s)",
    )
    p.add_argument(
        "--checkpoint",
        default=str(CHECKPOINT.with_name("support-latplan.pt")),
        metavar="FILE.pt",
        help="perception weights (%(default)s)",
    )
    p.add_argument(
        "--res",
        default="150x100,45x30",
        metavar="WxH[,WxH]",
        help="image_tr/ renders and/or LatPlan's own input (%(default)s)",
    )
    p.add_argument(
        "--modes",
        default="state,frozen,optimised",
        metavar="M[,M...]",
        help="state (the PDDL problem, no images), frozen, optimised (all)",
    )
    p.add_argument("--seeds", type=positive, default=3, metavar="S", help="planner seeds (3)")
    p.add_argument("--limit", type=positive, metavar="N", help="a spread of N instances (40)")
    p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
    progress_option(p)
    output_options(p, "write results.json and instances.csv into this folder")
    p.set_defaults(
        func=lazy("tamp.cli.bench.vision", "latplan_command"),
        recorded=lazy("tamp.cli.recorded", "latplan_config"),
    )


def _poses_benchmark(bench) -> None:
    p = bench.add_parser("poses", help="block poses from RGB-D images against the true poses")
    p.add_argument(
        "--sim",
        default=",".join(SIMULATORS),
        metavar="SIM[,SIM]",
        help=f"simulators, comma-separated ({','.join(SIMULATORS)})",
    )
    p.add_argument("--n", type=positive, default=200, help="random scenes per simulator (200)")
    p.add_argument("--seed", type=seed, default=0, help="scene seed (0)")
    p.add_argument("--min-blocks", type=bounded(1, MAX_BLOCKS), default=3, help="(3)")
    p.add_argument("--max-blocks", type=bounded(1, MAX_BLOCKS), default=6, help="(6)")
    p.add_argument(
        "--jitter", action="store_true", help="random camera and light, as in perception dataset"
    )
    progress_option(p)
    output_options(p, "write results.json and blocks.csv into this folder")
    p.set_defaults(
        func=lazy("tamp.cli.bench.vision", "poses_command"),
        recorded=lazy("tamp.cli.recorded", "poses_config"),
    )


def _segmentation_benchmark(bench) -> None:
    p = bench.add_parser(
        "segmentation",
        help="the colour segmentation's thresholds checked on fresh renders (not evaluation data)",
    )
    p.add_argument(
        "data",
        nargs="+",
        metavar="FILE.npz",
        help="datasets from `tamp perception dataset` (fresh seeds, never the evaluation images)",
    )
    p.add_argument(
        "--checkpoint",
        required=True,
        metavar="FILE.pt",
        help="perception weights that read the scenes (images resized to its input size)",
    )
    device_option(p, "the model's")
    progress_option(p)
    output_options(p, "write results.json into this folder")
    p.set_defaults(
        func=lazy("tamp.cli.bench.vision", "segmentation_command"),
        recorded=lazy("tamp.cli.recorded", "segmentation_config"),
    )


def _record_command(bench) -> None:
    p = bench.add_parser(
        "record",
        help="record benchmark results folders and regenerate BENCHMARKS.md and the README's "
        "results table",
    )
    p.add_argument(
        "--results",
        nargs="*",
        default=(),
        metavar="DIR",
        help="benchmark --out folders, or a folder of them (none: only regenerate the table)",
    )
    p.add_argument(
        "--into",
        default="results/current",
        metavar="DIR",
        help="the committed records, one per results folder name (%(default)s)",
    )
    p.add_argument(
        "--markdown",
        default="BENCHMARKS.md",
        metavar="FILE.md",
        help="the page written whole from the records and docs/experiments/index.md beside it "
        "(%(default)s)",
    )
    p.add_argument(
        "--readme",
        default="README.md",
        metavar="FILE.md",
        help="the file whose current-results block is regenerated (%(default)s; '' for none)",
    )
    p.add_argument("--json", action="store_true", help="the records written, as JSON")
    p.set_defaults(func=lazy("tamp.cli.bench.record", "record_command"))
