"""Option groups shared by the ``tamp`` subcommands, and options -> configs.

The option types (value parsers, validators, bounds) are in `tamp.cli.types`. Parsing only:
nothing here plans or simulates, and nothing here imports torch, so ``tamp --help`` stays fast.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

from tamp.bench.official import OFFICIAL, default_data
from tamp.cli.types import (
    MAX_ITERS,
    MAX_RESTARTS,
    bounded,
    device,
    nonnegative,
    placement,
    positive,
    positive_float,
    radius,
    seconds,
    seconds_or_off,
    share,
    window,
    window_list,
)
from tamp.modes import Crisp, GeoPlanner, ImageScene, Observation, Perception
from tamp.sim.base import SIMULATORS
from task.config import PlannerConfig
from task.domains import names
from task.errors import TampError

SCENES = ("tabletop", "shelf", "clutter", "cramped")  # `tamp.obstacles` (no simulator import)
IMAGE_SCENES = [s.value for s in ImageScene]  # whose blocks an image shows

# every domain's goal-loss kinds: "default" (the domain's own), "atoms" (the paper's CE), then
# Blocksworld's "towers", Logistics' and Sokoban's "potential", the STRIPS lift's "ff" (its
# default, a soft relaxed plan's size) and "hadd"
GOAL_LOSSES = ("default", "atoms", "towers", "potential", "ff", "hadd")

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
    "improve_s",
    "device",
)


@dataclass(frozen=True)
class PlannerOverrides:
    """The planner options the user gave (``given``: ``(PlannerConfig field, value)`` pairs, in
    `_OVERRIDES` order; an option not given is absent), read once from the command line
    (`planner_overrides`); `config` lays them over a domain's defaults."""

    given: tuple[tuple[str, object], ...] = ()

    def get(self, name: str, default: object = None) -> object:
        """The value given for the `PlannerConfig` field ``name`` (``default``: not given)."""
        return dict(self.given).get(name, default)

    def config(self, domain: str | None = None) -> PlannerConfig:
        """PlannerConfig defaults (with ``domain``'s own, `PlannerConfig.for_domain`) and the
        options given."""
        given = dict(self.given)
        if "improve_s" in given:  # --improve applies at any size (a domain's cap is its default's)
            given["improve_up_to"] = None
        if domain is None:
            return PlannerConfig(**given)
        return PlannerConfig.for_domain(domain, **given)


def planner_overrides(args: argparse.Namespace) -> PlannerOverrides:
    """The planner options of ``args`` that were given (None: not given)."""
    return PlannerOverrides(
        tuple((k, getattr(args, k)) for k in _OVERRIDES if getattr(args, k, None) is not None)
    )


def planner_config(args: argparse.Namespace, domain: str | None = None) -> PlannerConfig:
    """PlannerConfig defaults (with ``domain``'s own, `PlannerConfig.for_domain`) and the
    options the user gave (None: not given)."""
    return planner_overrides(args).config(domain)


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage block); subparsers inherit the class."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def planner_options(horizon_list: bool) -> argparse.ArgumentParser:
    """Options shared by every command that plans; they override `PlannerConfig` fields."""
    d = PlannerConfig()
    p = Parser(add_help=False)
    g = p.add_argument_group("planner (overrides PlannerConfig defaults)")
    if horizon_list:
        g.add_argument(
            "--horizon",
            dest="horizons",
            type=window_list,
            metavar="T[,T...]",
            help=f"window lengths; several run the window ablation ({d.horizon})",
        )
    else:
        g.add_argument("--horizon", type=window, metavar="T", help=f"window length ({d.horizon})")
    g.add_argument(
        "--restarts",
        type=bounded(1, MAX_RESTARTS),
        metavar="K",
        help=f"random restarts ({d.restarts})",
    )
    g.add_argument(
        "--iters",
        type=bounded(1, MAX_ITERS),
        metavar="N",
        help=f"Adam steps per window ({d.iters})",
    )
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
        type=window,
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
        help="rank windows with moves to the table free (faster on big Blocksworld "
        "problems, plans a little longer; off, but on for Blocksworld problems of 30 blocks "
        "or more)",
    )
    g.add_argument(
        "--time-limit",
        dest="time_limit_s",
        type=seconds,
        metavar="SECONDS",
        help="stop planning at this wall-clock limit with the moves so far, and say so (none)",
    )
    g.add_argument(
        "--improve",
        dest="improve_s",
        type=seconds_or_off,
        metavar="SECONDS",
        help="anytime improvement: after a plan of L moves is found, A* on the domain's lower "
        f"bound looks for one shorter than L for up to this long and {d.improve_nodes} "
        "expansions (within --time-limit), proving it optimal when it completes; 0 = off "
        f"({d.improve_s:g}, but 30 for Blocksworld problems of up to 15 blocks; given, it "
        "applies at any size; without a cost source and perception only)",
    )
    g.add_argument(
        "--device",
        type=device,
        metavar="DEVICE",
        help=f"torch device of the planner's tensors (and of perception): cpu, cuda or cuda:N "
        f"({d.device}; refused where this machine has no such device)",
    )
    g.add_argument(
        "--tau-end",
        type=positive_float,
        metavar="TAU",
        help=f"softmax temperature at the last Adam step, annealed from {d.tau:g} "
        f"({d.tau_end:g}; {d.tau:g} = no annealing, the paper's planner)",
    )
    return p


def device_option(p: argparse.ArgumentParser, whose: str) -> None:
    """``--device cpu|cuda|cuda:N`` for a command that runs torch outside the planner."""
    p.add_argument(
        "--device",
        type=device,
        default="cpu",
        metavar="DEVICE",
        help=f"torch device of {whose} tensors: cpu, cuda or cuda:N (cpu; refused where this "
        "machine has no such device)",
    )


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


def peer_list(text: str) -> tuple[str, ...]:
    """``--peers``: comma-separated peer planners (`tamp.bench.peers.side_by_side.PEERS`)."""
    from tamp.bench.peers.side_by_side import parse

    try:
        return parse(text)
    except TampError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--peers: ")) from None


def peers_option(p: argparse.ArgumentParser) -> None:
    """``--peers``: classical planners run beside ours on the same instances."""
    p.add_argument(
        "--peers",
        type=peer_list,
        metavar="PEER[,PEER...]",
        help="also run these planners (pyperplan: GBF+hFF; lama: Fast Downward lama-first) on "
        "every instance within the same --time-limit, which they need; ours then plans one "
        "instance at a time; a table side by side (needs the bench extra)",
    )


def progress_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--no-progress", dest="progress", action="store_false", help="no progress bar on stderr"
    )


def output_options(p: argparse.ArgumentParser, out_help: str) -> None:
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.add_argument("--out", metavar="PATH", help=out_help)


def episode_options(
    p: argparse.ArgumentParser, multi_sim: bool = False, scene_files: bool = False
) -> None:
    """Options of commands that run closed-loop episodes in a simulator (``scene_files``:
    ``--scene`` also takes a scene file, `workcell_options`)."""
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
            "--domain",
            metavar="DOMAIN.pddl",
            help="domain file of PROBLEM.pddl (the embedded 4-op blocksworld), or with --scene "
            "FILE.json and --binding a pick-and-place domain of your own",
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
        choices=[m.value for m in Observation],
        default="state",
        help="state from block poses or from the camera image (state)",
    )
    p.add_argument(
        "--perception",
        choices=[Perception.FROZEN.value, Perception.OPTIMISED.value],
        default="frozen",
        help="camera: frozen or planning-optimised perception (frozen)",
    )
    p.add_argument(
        "--blur",
        type=radius,
        default=0,
        metavar="R",
        help="camera: Gaussian blur radius in pixels (0)",
    )
    p.add_argument(
        "--checkpoint", metavar="FILE.pt", help="camera: perception weights (perception/support.pt)"
    )
    p.add_argument(
        "--crisp",
        choices=[Crisp.PERCEIVED.value, Crisp.TRUE.value],
        default="perceived",
        help="decode moves against the observed state, or the simulator's true "
        "state (an oracle) (perceived)",
    )
    scene_options(p, scene_files)
    record_option(p, "SIM-INSTANCE" if multi_sim else None)


def record_option(p: argparse.ArgumentParser, episodes: str | None = None) -> None:
    """``--record``: a Rerun recording of the episode (``FILE.rrd``), or with ``episodes`` (a
    benchmark's file names, e.g. ``SIM-INSTANCE``) a flag for one recording per episode under
    ``--out`` (`tamp.rerun_log`)."""
    extra = "needs the rerun extra: pip install 'soft-tamp[rerun]'"
    if episodes is not None:
        p.add_argument(
            "--record",
            action="store_true",
            help=f"write a Rerun recording of every episode to OUT/recordings/{episodes}.rrd "
            f"(needs --out; {extra})",
        )
        return
    p.add_argument(
        "--record",
        metavar="FILE.rrd",
        help=f"write a Rerun recording of the episode to FILE.rrd ({extra})",
    )


def scene_options(p: argparse.ArgumentParser, files: bool = False) -> None:
    """The scene's obstacles, what happens to a trajectory that would hit one, and
    motion-aware planning on it (`workcell_options`)."""
    workcell_options(p, files)
    p.add_argument(
        "--collision",
        choices=("plan", "check", "off"),
        default="plan",
        help="check every trajectory and route blocked ones with the motion planner "
        "(plan), fail them (check), or run unchecked (off) (plan)",
    )


def workcell_options(p: argparse.ArgumentParser, files: bool = False) -> None:
    """The robot's table (``--scene``) and motion-aware planning on it (``--motion-aware``,
    ``--placements``): the one place these options are defined. With ``files``, ``--scene``
    also takes a scene file (`tamp.world`), checked by `tamp.cli.settings.run.run_settings`."""
    if files:
        p.add_argument(
            "--scene",
            default="tabletop",
            metavar="NAME|FILE.json",
            help=f"the workcell ({', '.join(SCENES)}; tabletop: no obstacles), a scene "
            "file whose objects start where it puts them, their state read from the geometry "
            "(with --goal), or a canonical problem's name (blocked, packed, nonmonotonic, "
            "sorting, tall, hanoi: its shipped scene and goal)",
        )
    else:
        p.add_argument(
            "--scene",
            choices=SCENES,
            default="tabletop",
            help="the workcell: obstacles on the robot's table (tabletop: none)",
        )
    p.add_argument(
        "--motion-aware",
        dest="lambda_motion",
        action="store_const",
        const=0.05,
        help="put the arm's cost of each move into the planner's objective, weight "
        "0.05, and plan on the table's slots, the problem laid out on --scene (off: "
        "task-only planning)",
    )
    p.add_argument(
        "--placements",
        type=placement,
        default=0.0,
        metavar="M",
        help="--motion-aware, state observation: blocks up to M m (<= 0.03) off a slot's "
        "centre, where planned (0)",
    )


def check_workcell(args: argparse.Namespace, executes: bool) -> None:
    """``--scene``, ``--placements`` and ``--perception/--blur/--checkpoint`` only where they
    take effect: a one-line usage error (TampError) in any other combination. ``executes``:
    the command runs the arm (its scene's obstacles matter without ``--motion-aware``)."""
    aware = bool(getattr(args, "lambda_motion", None))
    camera = getattr(args, "observe", "state") == Observation.CAMERA
    if getattr(args, "placements", 0.0) and not aware:
        raise TampError("--placements needs --motion-aware (it places the planned moves)")
    if getattr(args, "placements", 0.0) and camera:
        raise TampError(
            "--placements needs --observe state: a camera window's moves go to a free slot"
        )
    if not executes and args.scene != "tabletop" and not aware:
        raise TampError(f"--scene {args.scene} needs --motion-aware (the arm's table to plan on)")
    if not camera and hasattr(args, "observe"):
        given = [
            f"--{name}"
            for name, default in (("perception", "frozen"), ("blur", 0), ("checkpoint", None))
            if getattr(args, name, default) != default
        ]
        if given:
            raise TampError(f"{', '.join(given)} need --observe camera (they read the image)")


def run_options(p: argparse.ArgumentParser) -> None:
    """``tamp run``'s own options: the video, and a given plan to execute instead of planning."""
    p.add_argument("--no-video", action="store_true", help="skip the camera video")
    p.add_argument("--video-format", choices=("mp4", "gif"), default="mp4", help="(mp4)")
    p.add_argument(
        "--goal",
        metavar="PDDL|FILE",
        help="--scene FILE.json: the goal over its objects, inline such as '(and (on a b) "
        "(in c tray))' or a file (a PDDL goal or problem): on, ontable and in atoms (a "
        "canonical problem's name: its shipped goal)",
    )
    p.add_argument(
        "--geo-planner",
        choices=[m.value for m in GeoPlanner],
        help="--scene FILE.json or a canonical problem: run the geometric TAMP episode with "
        "this planner (motion-aware where the Blocksworld loop cannot run the scene: regions, "
        "shapes, parking rules; else the loop); PROBLEM.pddl (or the example) on a named "
        "workcell: the problem laid out on its slots as the loop lays it out, run by this "
        "planner (without it: the Blocksworld loop)",
    )
    p.add_argument(
        "--binding",
        metavar="FILE.json|toml",
        help="--scene FILE.json with --domain DOMAIN.pddl: plan through your own "
        "pick-and-place domain, this file binding its actions to the arm (which picks, "
        "which places what) and saying how the scene reads as its state (see "
        "examples/domains/tray.binding.json)",
    )
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
        help="--plan: an experimenter grant: the experimenter (not the robot) reads the TRUE "
        "state before each step and stops at the first step invalid there instead of "
        "attempting it (report.json counts these reads under truth_reads.experimenter)",
    )
