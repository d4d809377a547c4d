"""Option groups of the ``tamp bench`` commands that sweep episodes or images: perception,
executability, where the episodes run (``--workers``, ``--ray``), what ``bench motion`` runs, and
``bench tamp``'s problems and planners. The option groups every command shares are in
`tamp.cli.options`; parsing only, nothing here imports torch or a simulator.
"""

from __future__ import annotations

import argparse

from tamp.cli.options import (
    data_option,
    output_options,
    progress_option,
    record_option,
    scene_options,
)
from tamp.cli.types import (
    PLAN_THREADS,
    block_counts,
    bounded,
    name_list,
    positive,
    radius_list,
    seed,
    threads,
)
from tamp.modes import Adapt, GeoPlanner, Observation
from tamp.sim.base import SIMULATORS


def perception_bench_options(p: argparse.ArgumentParser, checkpoint: str) -> None:
    """``bench perception``'s image options: modes, blur, crisp protocol, corruption, renderer,
    weights and the optimised mode's settings."""
    p.add_argument(
        "--modes",
        default="state,frozen,optimised",
        metavar="M[,M...]",
        help="state (ground truth), frozen, optimised (all three)",
    )
    p.add_argument(
        "--blur",
        type=radius_list,
        default=(0,),
        metavar="R[,R...]",
        help="Gaussian blur radii in pixels, 0 = clear (0)",
    )
    p.add_argument(
        "--crisp",
        default="true",
        metavar="C[,C...]",
        help="what decoded moves are checked against: true (the true state, the "
        "paper's) and/or perceived (the state read from the image) (true)",
    )
    p.add_argument(
        "--corrupt",
        default="",
        metavar="SPEC",
        help="degrade every render (stress ladder): noise:SIGMA (grey levels), dim:FACTOR, occlude",
    )
    p.add_argument("--sim", choices=SIMULATORS, default="pybullet", help="renderer (pybullet)")
    p.add_argument(
        "--checkpoint",
        default=checkpoint,
        metavar="FILE.pt",
        help="perception weights (the shipped checkpoint)",
    )
    # defaults of tamp.camera.from_images.PerceptionMode (not imported here: it pulls in torch)
    p.add_argument(
        "--kl-weight",
        type=float,
        default=10.0,
        metavar="W",
        help="optimised: weight of each KL anchor (%(default)s)",
    )
    p.add_argument(
        "--adapt",
        choices=[m.value for m in Adapt],
        default="head",
        help="optimised: weights to update (%(default)s)",
    )


def executability_options(p: argparse.ArgumentParser) -> None:
    """``bench executability``: plan sources, instances, simulators, the reference row."""
    p.add_argument(
        "--plans",
        required=True,
        metavar="FILE.csv|DIR",
        help="plans to execute: a CSV (one source, named by its stem) or a folder of "
        "CSVs, columns file, plan (actions joined by ';') and optionally llm_correct "
        "(PlanBench's verdict), as in ../shared/data/planbench/llm_plans",
    )
    data_option(p)
    p.add_argument(
        "--n",
        type=positive,
        help="at most N of the instances the plan files name, spread over sizes, the same "
        "for every source (all of them, up to 20)",
    )
    p.add_argument(
        "--sim",
        default="pybullet",
        metavar="SIM[,SIM]",
        help=f"simulators, comma-separated: {','.join(SIMULATORS)} (pybullet)",
    )
    p.add_argument(
        "--no-ours",
        dest="ours",
        action="store_false",
        help="leave out the reference row: our planner's plans of the same instances",
    )
    p.add_argument(
        "--grasp",
        choices=("friction", "weld"),
        default="friction",
        help="physical friction grasp or a weld attach (friction)",
    )
    p.add_argument("--seed", type=seed, default=0, help="scene layout and planner seed (0)")
    p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
    scene_options(p)
    record_option(p, "SIM-INSTANCE-SOURCE")  # a plan run once for several sources: the first
    progress_option(p)
    output_options(p, "write results.json and plans.csv into this folder")


def sweep_options(p: argparse.ArgumentParser) -> None:
    """``--workers`` and ``--ray``: where the episodes run."""
    p.add_argument(
        "--workers",
        type=threads,
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
        type=block_counts,
        metavar="B[,B...]",
        help="random problems of these block counts instead of PlanBench, seeded by --seed, "
        "those whose towers fit --scene (episodes.csv lists them)",
    )


# `tamp.world.canonical.PROBLEMS` (a test keeps them equal), named here so that the parser does
# not import the problems' generators
TAMP_PROBLEMS = ("blocked", "packed", "nonmonotonic", "sorting", "tall", "hanoi")


def tamp_bench_options(p: argparse.ArgumentParser) -> None:
    """What ``bench tamp`` runs: problems, variants, planners, simulators."""
    p.add_argument(
        "--problems",
        type=name_list("problem", TAMP_PROBLEMS),
        default=",".join(TAMP_PROBLEMS),
        metavar="P[,P]",
        help=f"canonical problems, comma-separated ({','.join(TAMP_PROBLEMS)}; default: all)",
    )
    p.add_argument(
        "--n",
        type=bounded(1, 1000, "a count"),
        default=20,
        help="seeded variants of each problem (20): variant k is seed + k",
    )
    p.add_argument(
        "--seed", type=seed, default=0, help="first variant's seed, and the episodes' (0)"
    )
    p.add_argument(
        "--planner",
        dest="planners",
        type=name_list("planner", [m.value for m in GeoPlanner]),
        default="soft,motion-aware,search-then-check",
        metavar="NAME[,NAME]",
        help="planners side by side (soft: task-only with execution; motion-aware: ours; "
        "search-then-check: the baseline; search: the complete geometric search alone; "
        "motion-aware-sampled: ours with region cells placed by rejection sampling)",
    )
    p.add_argument(
        "--sim",
        default=",".join(SIMULATORS),
        metavar="SIM[,SIM]",
        help=f"simulators, comma-separated ({','.join(SIMULATORS)})",
    )
    p.add_argument(
        "--video",
        action="store_true",
        help="record the first variant of each problem per planner and simulator to "
        "OUT/videos/ (needs --out)",
    )
    p.add_argument(
        "--observe",
        choices=[m.value for m in Observation],
        default="state",
        help="object poses from motion capture, or estimated from three RGB-D cameras and "
        "the objects' known models, with their errors against ground truth (state)",
    )
