"""Option types and option groups shared by the ``tamp`` subcommands, and options -> configs.

Parsing only: nothing here plans or simulates, and nothing here imports torch, so ``tamp --help``
stays fast.
"""

from __future__ import annotations

import argparse

from tamp.bench.suites import OFFICIAL, default_data
from tamp.sim.base import SIMULATORS
from task.config import PlannerConfig
from task.domains import names
from task.errors import TampError

# every domain's goal-loss kinds: "default" (the domain's own), "atoms" (the paper's CE), then
# Blocksworld's "towers", Logistics' and Sokoban's "potential", the STRIPS lift's "hadd"
GOAL_LOSSES = ("default", "atoms", "towers", "potential", "hadd")

_OVERRIDES = (
    "horizon",
    "restarts",
    "iters",
    "goal_loss",
    "lookahead_share",
    "tau_end",
    "crisp_check",
    "lookahead",
    "max_windows",
    "time_limit_s",
    "lambda_motion",
    "park_free",
)


def sim_list(text: str) -> tuple[str, ...]:
    """``--sim pybullet,mujoco`` as a tuple; TampError naming an unknown simulator."""
    sims = tuple(dict.fromkeys(t.strip() for t in text.split(",")))
    for name in sims:
        if name not in SIMULATORS:
            raise TampError(f"unknown simulator {name!r} (valid: {', '.join(SIMULATORS)})")
    return sims


def planner_config(args: argparse.Namespace, domain: str | None = None) -> PlannerConfig:
    """PlannerConfig defaults (with ``domain``'s own, `PlannerConfig.for_domain`) and the
    options the user gave (None: not given)."""
    given = {k: getattr(args, k) for k in _OVERRIDES if getattr(args, k, None) is not None}
    return PlannerConfig(**given) if domain is None else PlannerConfig.for_domain(domain, **given)


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage block); subparsers inherit the class."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def seconds(text: str) -> float:  # a positive number of seconds
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected seconds > 0, got {text!r}")
    return value


def nonnegative(text: str) -> int:
    return 0 if text.strip() == "0" else positive(text)


def positive_list(text: str) -> tuple[int, ...]:
    try:
        values = tuple(int(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated positive integers such as 1,3,5, got {text!r}"
        ) from None
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"expected positive integers, got {text!r}")
    return tuple(dict.fromkeys(values))


def radius_list(text: str) -> tuple[int, ...]:
    try:
        values = tuple(int(t) for t in text.split(","))
    except ValueError:
        values = (-1,)
    if not values or min(values) < 0:
        raise argparse.ArgumentTypeError(f"expected radii >= 0 such as 0,6, got {text!r}")
    return tuple(dict.fromkeys(values))


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0.0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def share(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}")
    return value


def planner_options(horizon_list: bool) -> argparse.ArgumentParser:
    """Options shared by every command that plans; they override `PlannerConfig` fields."""
    d = PlannerConfig()
    p = Parser(add_help=False)
    g = p.add_argument_group("planner (overrides PlannerConfig defaults)")
    if horizon_list:
        g.add_argument(
            "--horizon",
            dest="horizons",
            type=positive_list,
            metavar="T[,T...]",
            help=f"window lengths; several run the window ablation ({d.horizon})",
        )
    else:
        g.add_argument("--horizon", type=positive, metavar="T", help=f"window length ({d.horizon})")
    g.add_argument("--restarts", type=positive, metavar="K", help=f"random restarts ({d.restarts})")
    g.add_argument("--iters", type=positive, metavar="N", help=f"Adam steps per window ({d.iters})")
    g.add_argument("--goal-loss", choices=GOAL_LOSSES, help=f"goal objective ({d.goal_loss})")
    g.add_argument(
        "--lookahead-share",
        type=share,
        metavar="S",
        help=f"share of restarts whose window is {d.lookahead} moves long "
        f"({d.lookahead_share:g}; 0 = the paper's planner)",
    )
    g.add_argument(
        "--lookahead",
        type=positive,
        metavar="T",
        help=f"length of the long-lookahead windows ({d.lookahead})",
    )
    g.add_argument(
        "--max-windows",
        type=positive,
        metavar="W",
        help=f"replanning windows before giving up ({d.max_windows})",
    )
    g.add_argument(
        "--park-free",
        action="store_const",
        const=True,
        help="rank windows with "
        "moves to the table free (faster on big Blocksworld problems, plans a little "
        "longer; off)",
    )
    g.add_argument(
        "--time-limit",
        dest="time_limit_s",
        type=seconds,
        metavar="SECONDS",
        help="stop planning at this wall-clock limit with the moves so far, and say so (none)",
    )
    g.add_argument(
        "--tau-end",
        type=positive_float,
        metavar="TAU",
        help=f"softmax temperature at the last Adam step, annealed from {d.tau:g} "
        f"({d.tau_end:g}; {d.tau:g} = no annealing, the paper's planner)",
    )
    return p


def data_option(p: argparse.ArgumentParser, domains: bool = False) -> None:
    """``--data`` (and with ``domains``, ``--domain``: which PlanBench set)."""
    if domains:
        p.add_argument(
            "--domain",
            choices=tuple(OFFICIAL),
            default="blocksworld",
            help="which PlanBench set: Blocksworld-600, Logistics-200, Sokoban-55 (blocksworld)",
        )
    p.add_argument(
        "--data",
        default=None if domains else str(default_data("blocksworld")),
        metavar="DIR",
        help=f"PlanBench folder of the domain ({default_data('DOMAIN')})"
        if domains
        else f"PlanBench blocksworld folder ({default_data('blocksworld')})",
    )


def rules_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--domain-rules",
        choices=names(),
        metavar="NAME",
        help=f"plan with these domain rules ({'|'.join(names())}; default: recognised from the "
        "PDDL domain, the generic STRIPS lift for a domain no file is written for)",
    )


def progress_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--no-progress", dest="progress", action="store_false", help="no progress bar on stderr"
    )


def output_options(p: argparse.ArgumentParser, out_help: str) -> None:
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.add_argument("--out", metavar="PATH", help=out_help)


def episode_options(p: argparse.ArgumentParser, multi_sim: bool = False) -> None:
    """Options of commands that run closed-loop episodes in a simulator."""
    if multi_sim:
        p.add_argument(
            "--sim",
            default=",".join(SIMULATORS),
            metavar="SIM[,SIM]",
            help=f"simulators, comma-separated ({','.join(SIMULATORS)})",
        )
    else:
        p.add_argument("--sim", choices=SIMULATORS, default="pybullet", help="(pybullet)")
    p.add_argument(
        "--domain", metavar="DOMAIN.pddl", help="domain file (the embedded 4-op blocksworld)"
    )
    p.add_argument(
        "--grasp",
        choices=("friction", "weld"),
        default="friction",
        help="physical friction grasp or a weld attach (friction)",
    )
    p.add_argument(
        "--inject",
        metavar="KIND:P[,...]",
        help="faults with probabilities, e.g. drop:0.2,nudge:0.1,noise:0.1",
    )
    p.add_argument("--max-replans", type=nonnegative, metavar="N", help="replanning budget (8)")
    p.add_argument(
        "--observe",
        choices=("state", "camera"),
        default="state",
        help="state from block poses or from the camera image (state)",
    )
    p.add_argument(
        "--perception",
        choices=("frozen", "optimised"),
        default="frozen",
        help="camera: frozen or planning-optimised perception (frozen)",
    )
    p.add_argument(
        "--blur",
        type=int,
        default=0,
        metavar="R",
        help="camera: Gaussian blur radius in pixels (0)",
    )
    p.add_argument(
        "--checkpoint", metavar="FILE.pt", help="camera: perception weights (perception/support.pt)"
    )
    p.add_argument(
        "--crisp",
        choices=("perceived", "true"),
        default="perceived",
        help="decode moves against the observed state, or the simulator's true "
        "state (an oracle) (perceived)",
    )
    scene_options(p)


def scene_options(p: argparse.ArgumentParser) -> None:
    """The scene's obstacles, and what happens to a trajectory that would hit one."""
    p.add_argument(
        "--scene",
        choices=("tabletop", "shelf", "clutter", "cramped"),
        default="tabletop",
        help="obstacles on the table (tabletop: none)",
    )
    p.add_argument(
        "--collision",
        choices=("plan", "check", "off"),
        default="plan",
        help="check every trajectory and route blocked ones with the motion planner "
        "(plan), fail them (check), or run unchecked (off) (plan)",
    )
    p.add_argument(
        "--motion-aware",
        dest="lambda_motion",
        action="store_const",
        const=0.05,
        help="put the arm's cost of each move into the planner's objective, weight "
        "0.05, and plan on the table's slots (off: task-only planning)",
    )
    p.add_argument(
        "--placements",
        type=float,
        default=0.0,
        metavar="M",
        help="--motion-aware: blocks up to M m (<= 0.03) off a slot's centre, where planned (0)",
    )


def run_options(p: argparse.ArgumentParser) -> None:
    """``tamp run``'s own options: the video, and a given plan to execute instead of planning."""
    p.add_argument("--no-video", action="store_true", help="skip the camera video")
    p.add_argument("--video-format", choices=("mp4", "gif"), default="mp4", help="(mp4)")
    p.add_argument(
        "--plan",
        metavar="PLAN",
        help="execute this plan open-loop instead of planning: 4-op PDDL actions "
        "(VAL format) or moves 'move(a -> b)', one per line",
    )
    p.add_argument(
        "--replan",
        action="store_true",
        help="--plan: after a failed or invalid step, replan from the observed state",
    )
    p.add_argument(
        "--stop-at-invalid",
        action="store_true",
        help="--plan: stop at the first step invalid at task level instead of attempting it",
    )


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
        choices=("head", "all"),
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
        default=20,
        help="a spread of N Blocksworld-600 instances over sizes, the same for every "
        "source (20; 600 is all)",
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
    p.add_argument("--seed", type=int, default=0, help="scene layout and planner seed (0)")
    p.add_argument("--threads", type=positive, default=2, help="torch threads (2)")
    scene_options(p)
    progress_option(p)
    output_options(p, "write results.json and plans.csv into this folder")
