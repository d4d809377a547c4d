"""``tamp plan-images INIT GOAL``: a 4-op Blocksworld plan from an initial and a goal image.

The blocks are the scene's colours found in both images (`tamp.scene.PALETTE` for ``cubes``,
LatPlan's red, blue, green and black for ``latplan``), named by colour. The trained model reads
the most likely valid state of each image (`tamp.camera.from_images.perceived_state`); those two
perceived states make the problem (the goal: every block's support in the goal image). There is
no ground truth, so the planner plans under the perceived protocol with the chosen perception
mode (`ImageBeliefs`); the world it plans in is the perceived initial state. Only the initial
state was photographed: windows that start elsewhere start from the one-hot state the plan's
moves reach (no camera sees it) and keep reading the goal image. The plan is validated against
the PDDL problem written from the two perceived states.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import asdict, replace
from pathlib import Path

import cv2
import numpy as np
import torch

from perception import CHECKPOINT
from perception.perceive import Perceiver
from perception.segment import SegmentConfig, colour_labels, scaled_min_area
from perception.train import load_checkpoint
from tamp.camera.from_images import ImageBeliefs, PerceptionMode, perceived_goal, perceived_state
from tamp.cli import report
from tamp.cli.options import planner_config
from tamp.scene import CAMERA_COLOURS, PALETTE
from task import data
from task.domains import blocksworld, blocksworld_pddl, get_domain
from task.errors import TampError
from task.planner import plan
from task.problem import TABLE, Move, PlanStatus, Problem
from task.symbolic import pddl_io
from task.symbolic.validate import validate

LATPLAN_CHECKPOINT = CHECKPOINT.with_name("support-latplan.pt")  # not shipped yet


def scene_colours(scene: str) -> tuple[tuple[str, tuple[float, float, float]], ...]:
    """The block colours a scene's images may show, (name, RGB in [0, 1]) in palette order."""
    if scene == "latplan":
        from tamp.camera.latplan import COLOURS

        return COLOURS
    return PALETTE[:CAMERA_COLOURS]


def read_image(path: str) -> np.ndarray:
    """An RGB uint8 image (H, W, 3) from a PNG or JPG file; one-line TampError otherwise."""
    if not Path(path).is_file():
        raise TampError(f"no image file at {path}")
    raw = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if raw is None:
        raise TampError(f"cannot read {path} as an image (expected PNG or JPG)")
    if raw.dtype == np.uint16:
        raw = (raw >> 8).astype(np.uint8)
    if raw.dtype != np.uint8:
        raise TampError(f"{path}: unsupported pixel type {raw.dtype} (expected 8- or 16-bit)")
    if raw.ndim == 2 or raw.shape[2] not in (3, 4):
        raise TampError(f"{path} is not a colour image: blocks are told apart by colour")
    code = cv2.COLOR_BGRA2RGB if raw.shape[2] == 4 else cv2.COLOR_BGR2RGB
    return np.ascontiguousarray(cv2.cvtColor(raw, code))


def found_colours(image: np.ndarray, rgbs, config: SegmentConfig = SegmentConfig()) -> list[bool]:
    """Whether each colour shows a region big enough to be a block (as `find_boxes` counts)."""
    labels = colour_labels(image, rgbs, config)  # (H, W)
    min_area = scaled_min_area(image.shape, config)
    opening = min(image.shape[:2]) >= config.open_min_side
    out = []
    for k in range(len(rgbs)):
        mask = (labels == k).astype(np.uint8)
        if opening:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, np.ones((2, 2), np.uint8))
        count, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        out.append(count > 1 and int(stats[1:, cv2.CC_STAT_AREA].max()) >= min_area)
    return out


class ColourPerceiver(Perceiver):
    """A Perceiver that looks for the blocks' own colours, whatever colours it is asked for
    (`tamp.camera.from_images` asks for the first N palette colours)."""

    def __init__(self, model, colours, **options) -> None:
        super().__init__(model, **options)
        self.colours = [tuple(c) for c in colours]

    def inputs(self, images, colours, names=None):
        return super().inputs(images, [self.colours] * len(images), names)


class Unseen:
    """Window beliefs for states no camera saw: the rows of problems whose state is not the
    photographed initial state start from that state one-hot (and are decoded against it);
    the goal (read from the goal image, adapted in ``optimised``) and the penalty are kept."""

    def __init__(self, inner, problem: Problem, states) -> None:
        self.inner, self.lr, self.problem, self.states = inner, inner.lr, problem, list(states)
        self.unseen = torch.tensor([s != problem.init for s in states])[:, None, None]
        domain = get_domain(problem.domain)
        self.onehot = domain.encode([problem] * len(states), states, torch.float32).F0
        read = zip(states, inner.crisp_states, strict=True)
        self.crisp_states = [s if s != problem.init else r for s, r in read]
        if hasattr(inner, "fallback"):  # optimised: a stuck window is retried frozen
            self.fallback = self._fallback

    def _fallback(self, rows):
        states = [self.states[r] for r in rows]
        return Unseen(self.inner.fallback(rows), self.problem, states)

    def compute(self):
        F0, goal, penalty = self.inner.compute()  # (P, N, Y), (P, N, Y), (P,)
        return torch.where(self.unseen, self.onehot, F0), goal, penalty

    def parameters(self):
        return self.inner.parameters()


def _checkpoint(args: argparse.Namespace) -> Path:
    if args.checkpoint is not None:
        path = Path(args.checkpoint)
        if not path.is_file():
            raise TampError(f"no perception checkpoint at {path} (--checkpoint)")
        return path
    if args.scene == "latplan":
        if not LATPLAN_CHECKPOINT.is_file():
            raise TampError(
                f"no LatPlan perception checkpoint at {LATPLAN_CHECKPOINT} (none is shipped "
                "yet): pass a model trained on the latplan scene with --checkpoint FILE.pt"
            )
        return LATPLAN_CHECKPOINT
    return CHECKPOINT


def _check_sizes(images, paths, model) -> None:
    """One-line errors for images of different sizes or a size the model cannot read."""
    (h0, w0), (h1, w1) = images[0].shape[:2], images[1].shape[:2]
    if (h0, w0) != (h1, w1):
        raise TampError(f"{paths[0]} is {w0}x{h0} but {paths[1]} is {w1}x{h1}: sizes must match")
    layers = len(model.config.channels)
    if min(h0, w0) < 2**layers:
        raise TampError(
            f"images of {w0}x{h0} are too small for the perception model: each of its {layers} "
            f"backbone layers halves the image, so it reads at least {2**layers}x{2**layers} pixels"
        )


def _blocks(images, paths, scene: str) -> tuple[tuple[str, ...], list]:
    """Names and colours of the scene's blocks in both images; one-line errors otherwise."""
    palette = scene_colours(scene)
    rgbs = [rgb for _, rgb in palette]
    seen = [found_colours(im, rgbs) for im in images]
    odd = [
        f"{name} is in {paths[0 if a else 1]} but not in {paths[1 if a else 0]}"
        for (name, _), a, b in zip(palette, *seen, strict=True)
        if a != b
    ]
    if odd:
        raise TampError("the images show different blocks: " + "; ".join(odd))
    names = tuple(name for (name, _), a in zip(palette, seen[0], strict=True) if a)
    if not names:
        valid = ", ".join(name for name, _ in palette)
        raise TampError(f"no blocks found in {paths[0]} or {paths[1]} (looked for {valid})")
    return names, [rgb for (name, rgb) in palette if name in names]


def _towers(entities, supports) -> str:
    """Towers bottom to top, e.g. ``[red blue] [green]``."""
    stacks = report.towers(dict(zip(entities, supports, strict=True)))
    return " ".join(f"[{' '.join(t)}]" for t in stacks)


def images_command(args: argparse.Namespace) -> int:
    """``tamp plan-images INIT GOAL``: the PDDL plan and its validation line."""
    t0 = time.perf_counter()
    paths = (args.init, args.goal)
    images = [read_image(p) for p in paths]
    checkpoint = _checkpoint(args)
    model, meta = load_checkpoint(checkpoint)
    _check_sizes(images, paths, model)
    names, rgbs = _blocks(images, paths, args.scene)
    # a checkpoint trained at one input size for several resolutions resizes every image
    options = {"input_hw": meta["input_hw"]} if meta.get("input_hw") else {}
    perceiver = ColourPerceiver(model, rgbs, **options)
    n = len(names)
    blank = Problem("plan-images", blocksworld.NAME, names, (TABLE,) * n, ())
    init, _ = perceived_state(blank, perceiver, images[0])
    problem = perceived_goal(replace(blank, init=init), perceiver, images[1])
    read_s = time.perf_counter() - t0

    mode = PerceptionMode(args.perception, crisp="perceived")
    config = planner_config(args, problem.domain)
    beliefs = ImageBeliefs([problem], perceiver, lambda i, s: images[0], [images[1]], mode)

    def source(indices, states):
        return Unseen(beliefs(indices, states), problem, states)

    threads = torch.get_num_threads()
    torch.set_num_threads(args.threads)
    try:
        result = plan(problem, config, args.seed, beliefs=source)
    finally:
        torch.set_num_threads(threads)
    moves = result.plan.moves
    actions = blocksworld.moves_to_actions(problem, moves, strict=False)
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
        print(json.dumps({
            "init_image": args.init, "goal_image": args.goal, "scene": args.scene,
            "perception": args.perception, "checkpoint": str(checkpoint), "blocks": list(names),
            "perceived_init": dict(zip(names, init, strict=True)),
            "perceived_goal": dict(problem.goal),
            "status": result.status.value, "valid": ok,
            "moves": [[m.entity, m.target] for m in moves if isinstance(m, Move)],
            "actions": [str(a).lower() for a in actions],
            "validation": None if validation is None else report.validation_dict(validation),
            "problem_pddl": text,
            "timing": {"read_s": read_s, "perception_s": beliefs.perception_s,
                       "planning_s": result.stats["time_s"],
                       "total_s": time.perf_counter() - t0},
            "stats": result.stats, "seed": args.seed, "threads": args.threads,
            "config": asdict(config),
        }, indent=2))  # fmt: skip
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
