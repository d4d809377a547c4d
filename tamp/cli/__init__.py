"""The ``tamp`` command line: argparse subcommands around `tamp.cli.plan` and `tamp.cli.bench`.

    tamp plan DOMAIN.pddl PROBLEM.pddl [--horizon 3 --restarts K --seed S --json --out plan.txt]
    tamp validate DOMAIN.pddl PROBLEM.pddl PLAN [--json]
    tamp demo [--json --out DIR]
    tamp bench planbench [--data DIR --limit N --seeds 3 --horizon 1,3,5 --sequential N --out DIR]
    tamp bench random [--blocks 6,8,10 --n 50 --seed 0 --max-nodes 20000 --out DIR]
    tamp run [PROBLEM.pddl] [--sim pybullet|mujoco --inject drop:0.2 --seed S --out DIR]
    tamp bench motion [--sim pybullet,mujoco --data DIR --n 100 --inject drop:0.2 --out DIR]

Exit codes: 0 success, 1 no plan or an invalid plan, 2 usage error or bad input (one line on
stderr: ``tamp: error: ...``; argparse errors read ``tamp plan: error: ...``).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from tamp.bench.suites import DEFAULT_PLANBENCH
from tamp.cli import bench as bench_cli
from tamp.cli import perception as perception_cmd
from tamp.cli import plan as commands
from tamp.sim.base import SIMULATORS
from task.config import PlannerConfig
from task.domains.blocksworld import GOAL_LOSSES
from task.errors import TampError


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage block); subparsers inherit the class."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def _count(text: str) -> int:
    return 0 if text.strip() == "0" else _positive(text)


def _positive_list(text: str) -> tuple[int, ...]:
    try:
        values = tuple(int(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated positive integers such as 1,3,5, got {text!r}"
        ) from None
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"expected positive integers, got {text!r}")
    return tuple(dict.fromkeys(values))


def _radius_list(text: str) -> tuple[int, ...]:
    try:
        values = tuple(int(t) for t in text.split(","))
    except ValueError:
        values = (-1,)
    if not values or min(values) < 0:
        raise argparse.ArgumentTypeError(f"expected radii >= 0 such as 0,6, got {text!r}")
    return tuple(dict.fromkeys(values))


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0.0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def _share(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}")
    return value


def _planner_options(horizon_list: bool) -> argparse.ArgumentParser:
    """Options shared by every command that plans; they override `PlannerConfig` fields."""
    d = PlannerConfig()
    p = _Parser(add_help=False)
    g = p.add_argument_group("planner (overrides PlannerConfig defaults)")
    if horizon_list:
        g.add_argument(
            "--horizon",
            dest="horizons",
            type=_positive_list,
            metavar="T[,T...]",
            help=f"window lengths; several run the window ablation ({d.horizon})",
        )
    else:
        g.add_argument(
            "--horizon", type=_positive, metavar="T", help=f"window length ({d.horizon})"
        )
    g.add_argument(
        "--restarts", type=_positive, metavar="K", help=f"random restarts ({d.restarts})"
    )
    g.add_argument(
        "--iters", type=_positive, metavar="N", help=f"Adam steps per window ({d.iters})"
    )
    g.add_argument("--goal-loss", choices=GOAL_LOSSES, help=f"goal objective ({d.goal_loss})")
    g.add_argument(
        "--lookahead-share",
        type=_share,
        metavar="S",
        help=f"share of restarts whose window is {d.lookahead} moves long "
        f"({d.lookahead_share:g}; 0 = the paper's planner)",
    )
    g.add_argument(
        "--tau-end",
        type=_positive_float,
        metavar="TAU",
        help=f"softmax temperature at the last Adam step, annealed from {d.tau:g} "
        f"({d.tau_end:g}; {d.tau:g} = no annealing, the paper's planner)",
    )
    return p


def _data_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--data",
        default=str(DEFAULT_PLANBENCH),
        metavar="DIR",
        help=f"PlanBench blocksworld folder ({DEFAULT_PLANBENCH})",
    )


def _progress_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--no-progress", dest="progress", action="store_false", help="no progress bar on stderr"
    )


def _output(p: argparse.ArgumentParser, out_help: str) -> None:
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.add_argument("--out", metavar="PATH", help=out_help)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="tamp", description="Differentiable soft-T_P task planning.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    plan_opts, bench_opts = _planner_options(False), _planner_options(True)

    p = sub.add_parser("plan", parents=[plan_opts], help="plan a blocksworld PDDL problem")
    p.add_argument("domain", metavar="DOMAIN.pddl")
    p.add_argument("problem", metavar="PROBLEM.pddl")
    p.add_argument("--seed", type=int, default=0, help="planner seed (0)")
    _output(p, "write the plan file (VAL format) here")
    p.set_defaults(func=commands.plan_command)

    p = sub.add_parser("validate", help="validate a plan file against a domain and a problem")
    p.add_argument("domain", metavar="DOMAIN.pddl")
    p.add_argument("problem", metavar="PROBLEM.pddl")
    p.add_argument("plan", metavar="PLAN")
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.set_defaults(func=commands.validate_command)

    p = sub.add_parser("demo", parents=[plan_opts], help="plan the embedded 5-block example")
    p.add_argument("--seed", type=int, default=0, help="planner seed (0)")
    _output(p, "write the example's domain, problem and plan files into this folder")
    p.set_defaults(func=commands.demo_command)

    p = sub.add_parser(
        "run", parents=[plan_opts], help="plan and execute a problem with the simulated Panda"
    )
    p.add_argument(
        "problem", nargs="?", metavar="PROBLEM.pddl", help="blocksworld problem (the example)"
    )
    _episode_options(p)
    p.add_argument("--seed", type=int, default=0, help="scene, planner and fault seed (0)")
    p.add_argument("--no-video", action="store_true", help="skip the camera video")
    p.add_argument("--video-format", choices=("mp4", "gif"), default="mp4", help="(mp4)")
    _output(p, "write the episode video and report.json into this folder")
    p.set_defaults(func=_run_command)

    bench = sub.add_parser("bench", help="planning benchmarks").add_subparsers(
        dest="suite", required=True, metavar="SUITE"
    )
    for name, what in (("planbench", "PlanBench Blocksworld-600"), ("random", "random problems")):
        p = bench.add_parser(name, parents=[bench_opts], help=f"benchmark on {what}")
        p.add_argument(
            "--seeds", type=_positive, default=1, metavar="S", help="planner seeds 0..S-1 (1)"
        )
        p.add_argument(
            "--sequential",
            type=_count,
            default=0,
            metavar="N",
            help="also time batched vs sequential planning on the first N instances",
        )
        _progress_option(p)
        _output(p, "write instances.csv, results.json and steps.png into this folder")
    planbench, random_ = bench.choices["planbench"], bench.choices["random"]
    _data_option(planbench)
    planbench.add_argument(
        "--limit",
        type=_positive,
        metavar="N",
        help="a spread of N instances over the block counts (all 600)",
    )
    planbench.set_defaults(func=bench_cli.planbench_command)
    random_.add_argument(
        "--blocks",
        type=_positive_list,
        default=(6, 8, 10, 15, 20),
        metavar="B[,B...]",
        help="block counts (6,8,10,15,20)",
    )
    random_.add_argument("--n", type=_positive, default=50, help="instances per block count (50)")
    random_.add_argument("--seed", type=int, default=0, help="instance generator seed (0)")
    random_.add_argument(
        "--max-nodes",
        type=_positive,
        default=20_000,
        metavar="N",
        help="A* expansion budget for the optimal lengths (20000)",
    )
    random_.set_defaults(func=bench_cli.random_command)

    p = bench.add_parser(
        "motion", parents=[plan_opts], help="motion-level executability in the simulators"
    )
    _episode_options(p, multi_sim=True)
    _data_option(p)
    p.add_argument("--n", type=_positive, default=100, help="instances, spread over sizes (100)")
    p.add_argument("--seed", type=int, default=0, help="scene, planner and fault seed (0)")
    _progress_option(p)
    _output(p, "write results.json and episodes.csv into this folder")
    p.set_defaults(func=_motion_command)
    p = bench.add_parser(
        "perception", parents=[bench_opts], help="planning PlanBench instances from rendered images"
    )
    _data_option(p)
    p.add_argument(
        "--n", type=_positive, default=100, help="instances over block counts (100: 17/74/9)"
    )
    p.add_argument("--modes", default="state,frozen,optimised", metavar="M[,M...]",
                   help="state (ground truth), frozen, optimised (all three)")  # fmt: skip
    p.add_argument("--blur", type=_radius_list, default=(0,), metavar="R[,R...]",
                   help="Gaussian blur radii in pixels, 0 = clear (0)")  # fmt: skip
    p.add_argument("--sim", choices=SIMULATORS, default="pybullet", help="renderer (pybullet)")
    p.add_argument(
        "--checkpoint", default=str(perception_cmd.DEFAULT_CHECKPOINT), metavar="FILE.pt",
        help="perception weights (the shipped checkpoint)",
    )  # fmt: skip
    # defaults of tamp.camera.from_images.PerceptionMode (not imported here: it pulls in torch)
    p.add_argument("--kl-weight", type=float, default=10.0, metavar="W",
                   help="optimised: weight of each KL anchor (%(default)s)")  # fmt: skip
    p.add_argument("--adapt", choices=("head", "all"), default="head",
                   help="optimised: weights to update (%(default)s)")  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="planner and layout seed (0)")
    p.add_argument("--threads", type=_positive, default=2, help="torch threads (2)")
    _progress_option(p)
    _output(p, "write results.json, instances.csv and example.png into this folder")
    p.set_defaults(func=_perception_bench_command)
    perception_cmd.add_parser(sub, _positive)
    return parser


def _episode_options(p: argparse.ArgumentParser, multi_sim: bool = False) -> None:
    """Options of commands that run closed-loop episodes in a simulator."""
    if multi_sim:
        p.add_argument(
            "--sim", default=",".join(SIMULATORS), metavar="SIM[,SIM]",
            help=f"simulators, comma-separated ({','.join(SIMULATORS)})",
        )  # fmt: skip
    else:
        p.add_argument("--sim", choices=SIMULATORS, default="pybullet", help="(pybullet)")
    p.add_argument(
        "--domain", metavar="DOMAIN.pddl", help="domain file (the embedded 4-op blocksworld)"
    )
    p.add_argument("--grasp", choices=("friction", "weld"), default="friction",
                   help="physical friction grasp or a weld attach (friction)")  # fmt: skip
    p.add_argument("--inject", metavar="KIND:P[,...]",
                   help="faults with probabilities, e.g. drop:0.2,nudge:0.1,noise:0.1")  # fmt: skip
    p.add_argument("--max-replans", type=_count, metavar="N", help="replanning budget (8)")
    p.add_argument("--observe", choices=("state", "camera"), default="state",
                   help="state from block poses or from the camera image (state)")  # fmt: skip
    p.add_argument("--perception", choices=("frozen", "optimised"), default="frozen",
                   help="camera: frozen or planning-optimised perception (frozen)")  # fmt: skip
    p.add_argument("--blur", type=int, default=0, metavar="R",
                   help="camera: Gaussian blur radius in pixels (0)")  # fmt: skip
    p.add_argument("--checkpoint", metavar="FILE.pt",
                   help="camera: perception weights (perception/support.pt)")  # fmt: skip


def _run_command(args: argparse.Namespace) -> int:
    from tamp.cli.run import run_command  # imports the simulators only when needed

    return run_command(args)


def _perception_bench_command(args: argparse.Namespace) -> int:
    from tamp.bench.perception import perception_bench_command

    return perception_bench_command(args)


def _motion_command(args: argparse.Namespace) -> int:
    from tamp.bench.motion import motion_command

    return motion_command(args)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``tamp`` command line; returns the exit code."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # argparse: --help exits 0, usage errors 2
        return exc.code if isinstance(exc.code, int) else 2
    try:
        return args.func(args)
    except TampError as exc:
        print(f"tamp: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("tamp: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # stdout closed early (e.g. piped into head): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
