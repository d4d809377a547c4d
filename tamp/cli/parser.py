"""The ``tamp`` argument parser: `build_parser` and the top-level commands (``plan``,
``validate``, ``example``, ``plan-images``, ``run``, ``demo``), each binding its handler; the
``bench`` and ``perception`` groups have their parsers in `tamp.cli.parsers`.

Handlers of commands that need torch or a simulator are imported when the command runs, so
``tamp --help`` and usage errors stay fast.
"""

from __future__ import annotations

import argparse

from tamp.cli.options import (
    IMAGE_SCENES,
    Parser,
    episode_options,
    output_options,
    planner_options,
    rules_option,
    run_options,
    workcell_options,
)
from tamp.cli.parsers.bench import bench_commands
from tamp.cli.parsers.handlers import at_edge, lazy
from tamp.cli.parsers.perception import perception_commands
from tamp.cli.types import PLAN_THREADS, seed, threads
from tamp.modes import Perception


def version() -> str:
    """The installed distribution's version (``soft-tamp``), or "unknown" when not installed."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as installed

    try:
        return installed("soft-tamp")
    except PackageNotFoundError:
        return "unknown"


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="tamp", description="Differentiable soft-T_P task planning.")
    parser.add_argument(
        "--version", action="version", version=f"tamp {version()}", help="print the version"
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    plan_opts, bench_opts = planner_options(False), planner_options(True)
    _plan_commands(sub, plan_opts)
    _images_command(sub, plan_opts)
    _run_command(sub, plan_opts)
    bench_commands(sub, plan_opts, bench_opts)
    perception_commands(sub)
    return parser


def _plan_commands(sub, plan_opts: argparse.ArgumentParser) -> None:
    """``plan``, ``validate`` and ``demo``."""
    p = sub.add_parser(
        "plan",
        parents=[plan_opts],
        help="plan a PDDL problem (blocksworld, logistics, sokoban or any STRIPS domain)",
    )
    p.add_argument("domain", metavar="DOMAIN.pddl")
    p.add_argument("problem", metavar="PROBLEM.pddl")
    p.add_argument(
        "--seed",
        type=seed,
        default=0,
        help="planner seed (0) and, with --motion-aware, the scene layout's",
    )
    p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
    workcell_options(p)
    rules_option(p)
    output_options(p, "write the plan file (VAL format) here")
    p.set_defaults(
        func=at_edge(_PLAN_EDGE + "plan_settings", "tamp.cli.plan.plan_command"),
        recorded=at_edge(_PLAN_EDGE + "plan_settings", _PLAN_EDGE + "plan_record"),
    )

    p = sub.add_parser("validate", help="validate a plan file against a domain and a problem")
    p.add_argument("domain", metavar="DOMAIN.pddl")
    p.add_argument("problem", metavar="PROBLEM.pddl")
    p.add_argument("plan", metavar="PLAN")
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.set_defaults(
        func=at_edge(_PLAN_EDGE + "validate_settings", "tamp.cli.plan.validate_command"),
        recorded=at_edge(_PLAN_EDGE + "validate_settings", _PLAN_EDGE + "validate_record"),
    )

    p = sub.add_parser(
        "example",
        parents=[plan_opts],
        help="plan the embedded 5-block example and show every stage (no robot)",
    )
    p.add_argument("--seed", type=seed, default=0, help="planner seed (0)")
    p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
    output_options(p, "write the example's domain, problem and plan files into this folder")
    p.set_defaults(
        func=at_edge(_PLAN_EDGE + "example_settings", "tamp.cli.plan.example_command"),
        recorded=at_edge(_PLAN_EDGE + "example_settings", _PLAN_EDGE + "plan_record"),
    )


def _images_command(sub, plan_opts: argparse.ArgumentParser) -> None:
    p = sub.add_parser(
        "plan-images",
        parents=[plan_opts],
        help="plan a blocksworld problem from an initial and a goal image",
    )
    p.add_argument("init", metavar="INIT.png", help="image of the initial scene (PNG or JPG)")
    p.add_argument("goal", metavar="GOAL.png", help="image of the goal scene, the same size")
    p.add_argument(
        "--image-scene",
        choices=IMAGE_SCENES,
        default="cubes",
        help="whose block colours to look for: the robot's cubes or LatPlan's red, "
        "blue, green and black cylinders (cubes)",
    )
    p.add_argument(
        "--perception",
        choices=[Perception.FROZEN.value, Perception.OPTIMISED.value],
        default="frozen",
        help="frozen or planning-optimised perception (frozen)",
    )
    p.add_argument(
        "--checkpoint",
        metavar="FILE.pt",
        help="perception weights (cubes: perception/support.pt; latplan: "
        "perception/support-latplan.pt)",
    )
    p.add_argument("--seed", type=seed, default=0, help="planner seed (0)")
    p.add_argument("--threads", type=threads, default=1, help=PLAN_THREADS)
    output_options(p, "write the plan file (VAL format) here")
    p.set_defaults(
        func=lazy("tamp.cli.images", "images_command"),
        recorded=lazy("tamp.cli.recorded", "images_config"),
    )


def _run_command(sub, plan_opts: argparse.ArgumentParser) -> None:
    """``run``, and ``demo``: the same episode observed by the camera, written to out/demo."""
    for name, what in (
        ("run", "plan and execute a problem with the simulated Panda"),
        ("demo", "the camera-to-arm episode of 'make demo': run --observe camera --out out/demo"),
    ):
        p = sub.add_parser(name, parents=[plan_opts], help=what)
        p.add_argument(
            "problem", nargs="?", metavar="PROBLEM.pddl", help="blocksworld problem (the example)"
        )
        episode_options(p, scene_files=True)
        p.add_argument("--seed", type=seed, default=0, help="scene, planner and fault seed (0)")
        run_options(p)
        output_options(p, "write the episode video and report.json into this folder")
        p.set_defaults(
            func=at_edge("tamp.cli.settings.run.run_settings", "tamp.cli.run.run_command"),
            recorded=at_edge(
                "tamp.cli.settings.run.run_settings", "tamp.cli.settings.run.run_record"
            ),
        )
    sub.choices["demo"].set_defaults(observe="camera", out="out/demo")


_PLAN_EDGE = "tamp.cli.settings.plan."  # the edges of plan, validate and example
