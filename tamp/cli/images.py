"""``tamp plan-images INIT GOAL``: a 4-op Blocksworld plan from an initial and a goal image.

Parsing and printing only: `tamp.camera.image_pair` finds the scene's colours in both images
(`tamp.scene.PALETTE` for ``cubes``, LatPlan's red, blue, green and black for ``latplan``),
names the blocks by colour, reads both states and plans (`plan_from_images`). The plan is
validated against the PDDL problem written from the two perceived states.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import torch

from perception import CHECKPOINT
from perception.perceive import Perceiver
from perception.train import load_checkpoint
from tamp.camera.image_pair import blocks_in, check_sizes, plan_from_images, read_image
from tamp.cli import report
from tamp.cli.options import planner_config
from tamp.cli.recorded import checkpoint as check_checkpoint
from tamp.cli.recorded import images_config, out_file
from tamp.modes import ImageScene
from task import data
from task.domains import blocksworld, blocksworld_pddl
from task.errors import TampError
from task.problem import Move, PlanStatus
from task.symbolic import pddl_io
from task.symbolic.validate import validate

LATPLAN_CHECKPOINT = CHECKPOINT.with_name("support-latplan.pt")  # the shipped LatPlan model


def _checkpoint(args: argparse.Namespace) -> Path:
    if args.checkpoint is not None:
        path = Path(args.checkpoint)
        if not path.is_file():
            raise TampError(f"no perception checkpoint at {path} (--checkpoint)")
        return path
    if args.image_scene == ImageScene.LATPLAN:
        if not LATPLAN_CHECKPOINT.is_file():
            raise TampError(
                f"no LatPlan perception checkpoint at {LATPLAN_CHECKPOINT} (is the package "
                "complete?): pass a model trained on the latplan scene with --checkpoint FILE.pt"
            )
        return LATPLAN_CHECKPOINT
    return CHECKPOINT


def _towers(entities, supports) -> str:
    """Towers bottom to top, e.g. ``[red blue] [green]``."""
    stacks = report.towers(dict(zip(entities, supports, strict=True)))
    return " ".join(f"[{' '.join(t)}]" for t in stacks)


def images_command(args: argparse.Namespace) -> int:
    """``tamp plan-images INIT GOAL``: the PDDL plan and its validation line."""
    t0 = time.perf_counter()
    recorded = images_config(args)
    out_file(args.out)
    paths = (args.init, args.goal)
    images = [read_image(p, args.image_scene) for p in paths]  # shrunk to the model's size
    checkpoint = _checkpoint(args)
    check_checkpoint(checkpoint)
    model, meta = load_checkpoint(checkpoint, args.image_scene)  # refuses another scene
    check_sizes(images, paths, model)
    names, rgbs = blocks_in(images, paths, args.image_scene)
    # a checkpoint trained at one input size for several resolutions resizes every image
    options = {"input_hw": meta["input_hw"]} if meta.get("input_hw") else {}
    config = planner_config(args, blocksworld.NAME)
    perceiver = Perceiver(model, **options, device=config.device)
    setup_s = time.perf_counter() - t0
    threads = torch.get_num_threads()
    torch.set_num_threads(args.threads)
    try:
        pair = plan_from_images(
            images[0], images[1], rgbs, names, perceiver, args.perception, config, args.seed
        )
    finally:
        torch.set_num_threads(threads)
    read_s = setup_s + pair.read_s
    problem, result, actions = pair.problem, pair.result, pair.actions
    init = problem.init
    moves = result.plan.moves
    text = blocksworld_pddl.to_pddl(problem)
    domain = data.domain()
    validation = None
    if result.status is not PlanStatus.NO_PLAN:
        validation = validate(domain, pddl_io.parse_problem(text, "<perceived>", domain), actions)
    if args.out is not None and validation is not None:
        try:
            pddl_io.write_plan(actions, args.out)
        except OSError as exc:
            raise TampError(f"cannot write {args.out} ({exc.strerror or exc})") from None
    ok = validation is not None and validation.valid
    goal = tuple(y for _, y in problem.goal)
    if args.json:
        print(
            json.dumps(
                {
                    "init_image": args.init,
                    "goal_image": args.goal,
                    "image_scene": args.image_scene,
                    "perception": args.perception,
                    "checkpoint": str(checkpoint),
                    "blocks": list(names),
                    "perceived_init": dict(zip(names, init, strict=True)),
                    "perceived_goal": dict(problem.goal),
                    "status": result.status.value,
                    "valid": ok,
                    "moves": [[m.entity, m.target] for m in moves if isinstance(m, Move)],
                    "actions": [str(a).lower() for a in actions],
                    "validation": None
                    if validation is None
                    else report.validation_dict(validation),
                    "problem_pddl": text,
                    "timing": {
                        "read_s": read_s,
                        "perception_s": pair.perception_s,
                        "planning_s": result.stats["time_s"],
                        "total_s": time.perf_counter() - t0,
                    },
                    "stats": result.stats,
                    "seed": args.seed,
                    "threads": args.threads,
                    "config": recorded,
                },
                indent=2,
            )
        )
        return 0 if ok else 1
    if validation is not None:
        print(pddl_io.format_plan(actions), end="")
    windows, k = result.stats.get("windows", 0), len(moves)
    took = (
        f"{k} move{'' if k == 1 else 's'}, {windows} window{'' if windows == 1 else 's'}, "
        f"{result.stats['time_s']:.2f} s"
    )
    if validation is None:
        head = f"NO PLAN: goal not reached after {took}"
    else:
        head = f"{report.validation_line(validation)} ({took})"
    seen = f"init {_towers(names, init)} -> goal {_towers(names, goal)}"
    print(f"{head}; {args.perception} perception: {seen}")
    return 0 if ok else 1
