"""``tamp bench perception``: planning PlanBench instances from rendered images.

For each instance the initial state and a goal scene (the PDDL goal completed by
`task.domains.blocksworld.complete_goal`: blocks the goal leaves free keep their support when
they can) are rendered by a simulator camera. Every (blur, mode, horizon) row plans the same
instances with the same seed:

- ``state``: ground-truth symbolic states (no images);
- ``frozen`` / ``optimised``: see `tamp.camera.from_images`.

Every plan is validated against the instance's own PDDL goal (`tamp.bench.planning.check`). Each
window's image is a fresh render of the current true state (new slots, new jitter); a render in
which a block is hidden is redrawn with the next layout seed and counted. Times per instance exclude
rendering (a camera's job) but include segmentation, the model and planning.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import sys
import time
import zlib
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import torch
from tqdm import tqdm

from perception.errors import PerceptionError
from perception.perceive import Perceiver, blur
from perception.segment import find_boxes
from tamp.bench import suites
from tamp.bench.planning import check
from tamp.camera.from_images import MODES, ImageBeliefs, PerceptionMode, perceived_goal
from tamp.camera.render import StateRenderer, block_colours
from tamp.cli.plan import planner_config
from task.domains.blocksworld import complete_goal
from task.errors import TampError
from task.planner import plan_batch

REDRAWS = 8  # layout seeds tried before a render counts as hiding a block


class Renders:
    """Renders instance images, redrawing layouts that hide a block; keeps time and counts."""

    def __init__(self, renderer: StateRenderer, problems, seed: int) -> None:
        self.renderer, self.problems, self.seed = renderer, problems, seed
        self.render_s = 0.0
        self.redrawn = 0
        self._goals: dict[int, np.ndarray] = {}  # every row uses the same goal images

    def goal(self, i: int) -> np.ndarray:
        """The goal image of problem i: its completed goal scene, rendered once."""
        if i not in self._goals:
            self._goals[i] = self.image(i, complete_goal(self.problems[i]), "goal")
        return self._goals[i]

    def image(self, i: int, state, kind: str = "init") -> np.ndarray:
        p = self.problems[i]
        key = f"{self.seed}:{i}:{kind}:{','.join(state)}".encode()
        base = zlib.crc32(key)
        t0 = time.perf_counter()
        try:
            for k in range(REDRAWS):
                img = self.renderer.render(p.entities, state, seed=base + k)
                try:
                    find_boxes(img, block_colours(p.n))
                    return img
                except PerceptionError:
                    self.redrawn += 1
            return img
        finally:
            self.render_s += time.perf_counter() - t0


def run_row(suite, chosen, mode: str, radius: int, horizon: int, args, perceiver, camera):
    """Plan ``chosen`` once in one mode; returns per-instance rows and the row summary."""
    config = replace(planner_config(args), horizon=horizon)
    problems = [inst.problem for inst in chosen]
    planned = list(problems)
    failed_goal: set[int] = set()  # goal images in which a block could not be found
    render0, t0 = camera.render_s, time.perf_counter()
    beliefs = None
    if mode != "state":
        goal_images = [camera.goal(i) for i in range(len(problems))]
        for i, p in enumerate(problems):
            try:
                planned[i] = perceived_goal(p, perceiver, goal_images[i], radius)
            except PerceptionError:
                failed_goal.add(i)
        beliefs = ImageBeliefs(
            planned, perceiver, lambda i, s: camera.image(i, s),
            goal_images, PerceptionMode(mode, kl_weight=args.kl_weight, blur=radius,
                                        adapt=args.adapt),
        )  # fmt: skip
    keep = [i for i in range(len(problems)) if i not in failed_goal]
    results = dict.fromkeys(range(len(problems)))
    if keep:
        sub = [planned[i] for i in keep]
        source = None
        if beliefs is not None:

            def source(indices, states):
                return beliefs([keep[j] for j in indices], states)

        out = plan_batch(sub, config, args.seed, beliefs=source)
        for i, r in zip(keep, out, strict=True):
            results[i] = r
    wall = time.perf_counter() - t0 - (camera.render_s - render0)
    rows = []
    for i, inst in enumerate(chosen):
        r = results[i]
        if r is None:
            status, length = "perception_error", None
        else:
            status, length = check(suite.domain, inst, r)
        rows.append({
            "instance": inst.name, "blocks": inst.blocks, "optimal": inst.optimal,
            "mode": mode, "blur": radius, "horizon": horizon, "status": status,
            "length": length, "windows": None if r is None else r.stats.get("windows"),
            "goal_misread": mode != "state" and planned[i].goal != _full_goal(problems[i]),
        })  # fmt: skip
    valid = [r for r in rows if r["status"] == "valid"]
    summary = {
        "mode": mode, "blur": radius, "horizon": horizon, "n": len(rows), "valid": len(valid),
        "optimal": sum(r["length"] == r["optimal"] for r in valid),
        "time_s_per_instance": wall / len(rows),
        "perception_s": 0.0 if beliefs is None else beliefs.perception_s,
        "goal_misread": sum(r["goal_misread"] for r in rows),
        "perception_errors": sum(r["status"] == "perception_error" for r in rows),
    }  # fmt: skip
    return rows, summary


def _sizes(chosen) -> list[int]:
    return sorted({i.blocks for i in chosen})


def _full_goal(problem):
    """The completed goal of ``problem`` as atoms (what a perfect goal reading gives)."""
    return tuple(zip(problem.entities, complete_goal(problem), strict=True))


def table(summaries: list[dict]) -> str:
    head = f"{'mode':<10} {'blur':>4} {'T':>2} {'valid':>9} {'optimal':>8} {'s/inst':>7}  notes"
    lines = [head, "-" * len(head)]
    for s in summaries:
        opt = 100.0 * s["optimal"] / max(s["valid"], 1)
        notes = []
        if s["goal_misread"]:
            notes.append(f"{s['goal_misread']} goal images misread")
        if s["perception_errors"]:
            notes.append(f"{s['perception_errors']} blocks not found")
        lines.append(
            f"{s['mode']:<10} {s['blur']:>4} {s['horizon']:>2} "
            f"{s['valid']:>4}/{s['n']:<4} {opt:>7.1f}% {s['time_s_per_instance']:>7.3f}  "
            + "; ".join(notes)
        )
    return "\n".join(lines)


def perception_bench_command(args: argparse.Namespace) -> int:
    modes = tuple(m for m in args.modes.split(",") if m)
    for m in modes:
        if m not in MODES:
            raise TampError(f"--modes: unknown mode {m!r}; expected some of {', '.join(MODES)}")
    torch.set_num_threads(args.threads)
    suite = suites.planbench(args.data, args.n)
    chosen = list(suite.instances)
    perceiver = Perceiver.load(args.checkpoint)
    horizons = args.horizons or (planner_config(args).horizon,)
    combos = [(r, m, t) for r in args.blur for m in modes for t in horizons]
    combos = [(r, m, t) for r, m, t in combos if not (m == "state" and r != args.blur[0])]
    rows, summaries = [], []
    with StateRenderer(args.sim) as renderer:
        camera = Renders(renderer, [i.problem for i in chosen], args.seed)
        bar = tqdm(combos, desc="perception bench", unit="row", file=sys.stderr,
                   disable=not args.progress)  # fmt: skip
        for radius, mode, horizon in bar:
            bar.set_postfix(mode=mode, blur=radius, T=horizon)
            r, s = run_row(suite, chosen, mode, radius, horizon, args, perceiver, camera)
            rows += r
            summaries.append(s)
        sample = chosen[0].problem
        views = [camera.image(0, sample.init), camera.goal(0)]
        if args.blur[-1]:
            views += [blur(im, args.blur[-1]) for im in views]
        example = np.hstack(views)  # initial and goal images, then blurred
    results = {
        "suite": suite.name, "source": suite.source, "n": len(chosen),
        "instances": [i.name for i in chosen],
        "split": {str(b): sum(i.blocks == b for i in chosen) for b in _sizes(chosen)},
        "sim": args.sim, "checkpoint": str(args.checkpoint), "seed": args.seed,
        "threads": args.threads, "cores": os.cpu_count(), "machine": platform.processor(),
        "date": time.strftime("%Y-%m-%d"), "redrawn_renders": camera.redrawn,
        "rows": summaries,
    }  # fmt: skip
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(results, indent=2))
        with open(out / "instances.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        cv2.imwrite(str(out / "example.png"), example[..., ::-1])
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        split = "/".join(str(v) for v in results["split"].values())
        print(f"{suite.name}: {len(chosen)} instances ({split} by block count), sim {args.sim}")
        print(table(summaries))
        if camera.redrawn:
            print(f"{camera.redrawn} renders redrawn because a block was hidden")
    return 0
