"""The LatPlan-40 benchmark (``tamp bench latplan``): planning from images nobody here rendered.

The data (``../shared/data/latplan``, its README): 40 instances ``prob-cylinders-4/<name>/``,
each an initial and a goal image at 150x100 (``image_tr/``, RGBA Blender renders) and 45x30
(what LatPlan's planner reads), its symbolic problem ``pddl/<name>.pddl`` (full-state goals,
table slots ignored) and ``manifest.csv`` (optimal 4-op lengths, ``opt_len_4op`` = 2 x moves).

Every (resolution, mode, seed) plans every instance: ``state`` plans the PDDL problem with the
soft planner (no images; once, not per resolution); ``frozen`` and ``optimised`` plan from the
image pair (`tamp.camera.image_pair.plan_from_images`, blocks named by colour). Every plan is
converted to 4-op PDDL actions and validated by `task.symbolic.validate` against the instance's
own PDDL problem (the ground truth). A pair that cannot be read (a block found in one image
only, an unreadable file) is a row of status ``unreadable`` with its error line. These images
are evaluation data only: nothing here trains or tunes on them.
"""

from __future__ import annotations

import csv
import sys
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain

from perception.perceive import Perceiver
from perception.train import checkpoint_scene, load_checkpoint
from tamp.bench.planning import check
from tamp.bench.suites import DEFAULT_DATA, spread
from tamp.bench.summary import is_optimal
from tamp.bench.tables import LATPLAN_CITED as CITED
from tamp.camera.image_pair import blocks_in, check_sizes, plan_from_images, read_image
from tamp.modes import Perception
from task.config import PlannerConfig
from task.errors import DataError, PDDLError, ProblemError, TampError
from task.instances import Instance, from_text
from task.planner import plan_batch
from task.problem import PlanStatus
from task.symbolic import pddl_io
from task.symbolic.validate import validate

DEFAULT = DEFAULT_DATA / "latplan"
INSTANCES = "prob-cylinders-4"
OPTIMAL = "opt_len_4op"  # manifest column: optimal 4-op plan length (2 x optimal moves)
FILES = {"150x100": ("image_tr/init.png", "image_tr/goal.png"), "45x30": ("init.png", "goal.png")}
SCENE = "latplan"  # the image scene of these images (`tamp.camera.image_pair.blocks_in`)
FIX = "get it as ../shared/data/latplan/README.md describes and pass --data DIR"


@dataclass(frozen=True)
class LatPlanData:
    """The instances (their PDDL problems and optimal lengths) and their image folders."""

    root: Path
    domain: Domain
    instances: tuple[Instance, ...]
    folders: tuple[Path, ...]


def load(root: str | Path = DEFAULT, limit: int | None = None) -> LatPlanData:
    """The instances of ``root`` listed in its manifest (``limit``: a spread of them)."""
    root = Path(root)
    needed = [root / INSTANCES, root / "manifest.csv", root / "pddl" / "domain.pddl"]
    missing = [p for p in needed if not p.exists()]
    if missing:
        raise DataError(
            f"LatPlan-40 data not found at {root.resolve()} (no {missing[0].name}): {FIX}"
        )
    try:
        domain = pddl_io.load_domain(root / "pddl" / "domain.pddl")
        with (root / "manifest.csv").open(newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(handle))
        instances, folders = [], []
        for row in spread(rows, limit, key=lambda r: r["problem"]):
            path = root / row["pddl_file"]
            text = pddl_io.read_text(path)
            optimal = int(row[OPTIMAL])
            instances.append(from_text(domain, text, str(path), row["problem"], optimal))
            folders.append(root / INSTANCES / row["problem"])
    except KeyError as exc:
        raise DataError(f"{root / 'manifest.csv'}: missing column {exc}") from None
    except ValueError as exc:
        raise DataError(f"{root / 'manifest.csv'}: {exc}") from None
    except (PDDLError, ProblemError, OSError) as exc:
        raise DataError(f"{root}: {exc}") from None
    if not instances:
        raise DataError(f"{root / 'manifest.csv'} lists no instances: {FIX}")
    return LatPlanData(root, domain, tuple(instances), tuple(folders))


def load_perceiver(path: str | Path, device: str = "cpu") -> Perceiver:
    """The perception checkpoint at ``path`` (its model on torch ``device``); one-line
    DataError naming the fix if absent.

    A checkpoint trained on another scene (the cube one, the documented negative control) is
    not refused, but warned about on stderr, and `report` records its scene
    (``checkpoint_scene``) so that its rows cannot pass for a LatPlan result."""
    if not Path(path).is_file():
        raise DataError(
            f"no LatPlan perception checkpoint at {path}: train one on rendered LatPlan-like "
            "scenes (tamp perception dataset --scene latplan, then tamp perception train) and "
            "pass it with --checkpoint FILE.pt, or run --modes state"
        )
    model, meta = load_checkpoint(path)
    trained = checkpoint_scene(meta)
    if trained != SCENE:
        print(f"warning: {scene_warning(path, trained)}", file=sys.stderr, flush=True)
    return Perceiver(model, input_hw=meta.get("input_hw"), device=device)


def scene_warning(path: str | Path, trained: str | None) -> str:
    """Why the image rows of a checkpoint not trained on LatPlan's scene are no result."""
    what = "an unknown scene" if trained is None else f"the {trained} scene"
    return (
        f"{path} was trained on {what}, not {SCENE}: its image rows measure a mismatched "
        "model (a negative control), not LatPlan perception"
    )


def _row(inst: Instance, res: str, mode: str, seed: int) -> dict:
    return {
        "instance": inst.name,
        "resolution": res,
        "mode": mode,
        "seed": seed,
        "init_read": None,
        "goal_read": None,
        "status": None,
        "error": None,
        "length": None,
        "optimal": inst.optimal,
        "time_s": None,
    }


def _state_rows(data: LatPlanData, config: PlannerConfig, seed: int) -> list[dict]:
    """Every instance planned from its true state, in one batch."""
    t0 = time.perf_counter()
    results = plan_batch([i.problem for i in data.instances], config, seed)
    each = (time.perf_counter() - t0) / len(data.instances)
    rows = []
    for inst, result in zip(data.instances, results, strict=True):
        row = _row(inst, "-", "state", seed)
        row["status"], row["length"] = check(data.domain, inst, result)
        row["time_s"] = each
        rows.append(row)
    return rows


def image_row(data, k: int, res: str, mode: str, seed: int, perceiver, config) -> dict:
    """Instance ``k`` planned from its image pair at ``res`` with ``mode`` perception."""
    inst, t0 = data.instances[k], time.perf_counter()
    row = _row(inst, res, mode, seed)
    paths = [str(data.folders[k] / f) for f in FILES[res]]
    try:
        images = [read_image(p) for p in paths]
        check_sizes(images, paths, perceiver.model)
        names, rgbs = blocks_in(images, paths, SCENE)
        pair = plan_from_images(*images, rgbs, names, perceiver, mode, config, seed)
    except TampError as exc:
        row.update(status="unreadable", error=str(exc), time_s=time.perf_counter() - t0)
        return row
    true = inst.problem
    row["init_read"] = dict(zip(names, pair.problem.init, strict=True)) == dict(
        zip(true.entities, true.init, strict=True)
    )
    row["goal_read"] = dict(pair.problem.goal) == dict(true.goal)
    if pair.result.status is PlanStatus.NO_PLAN:
        row["status"] = "no_plan"
    else:
        validation = validate(data.domain, inst.pddl, pair.actions)
        row["status"], row["length"] = validation.status.value, validation.length
    row["time_s"] = time.perf_counter() - t0
    return row


def run(
    data: LatPlanData,
    perceiver: Perceiver | None,
    resolutions: Sequence[str],
    modes: Sequence[str],
    seeds: Sequence[int],
    config: PlannerConfig,
    progress: Callable[[int], None] | None = None,
) -> list[dict]:
    """Per-instance rows of every (resolution, mode, seed), ``state`` first and once."""
    rows = []
    for mode in modes:
        for res in ("-",) if mode == Perception.STATE else resolutions:
            for seed in seeds:
                if mode == Perception.STATE:
                    rows += _state_rows(data, config, seed)
                    if progress is not None:
                        progress(len(data.instances))
                    continue
                for k in range(len(data.instances)):
                    rows.append(image_row(data, k, res, mode, seed, perceiver, config))
                    if progress is not None:
                        progress(1)
    return rows


def total(n: int, resolutions: int, modes: Sequence[str], seeds: int) -> int:
    """Instance plans of one run (the progress bar's length)."""
    return n * seeds * sum(1 if m == "state" else resolutions for m in modes)


def _spread(values: list[float]) -> dict:
    return {"mean": sum(values) / len(values), "min": min(values), "max": max(values)}


def summaries(rows: Sequence[dict]) -> list[dict]:
    """One summary per (resolution, mode): valid and optimal counts per seed (mean, min, max),
    pairs read right (both states), statuses over all seeds, seconds per instance."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for r in rows:
        groups.setdefault((r["resolution"], r["mode"]), []).append(r)
    out = []
    for (res, mode), group in groups.items():
        seeds = sorted({r["seed"] for r in group})
        per = [[r for r in group if r["seed"] == s] for s in seeds]
        valid = [[r for r in g if r["status"] == "valid"] for g in per]
        optimal = [
            sum(is_optimal(r["length"], r["optimal"], r["instance"]) for r in v) for v in valid
        ]
        read = [sum(bool(r["init_read"] and r["goal_read"]) for r in g) for g in per]
        out.append(
            {
                "resolution": res,
                "mode": mode,
                "n": len(per[0]),
                "seeds": seeds,
                "valid": _spread([len(v) for v in valid]),
                "optimal": _spread(optimal),
                "read_right": None if mode == Perception.STATE else _spread(read),
                "statuses": dict(Counter(r["status"] for r in group)),
                "time_s_per_instance": sum(r["time_s"] for r in group) / len(group),
            }
        )
    return out


def report(data: LatPlanData, rows, summary, options: dict, machine: dict) -> dict:
    """The ``results.json`` body: options, machine, the cited rows and every summary. With a
    checkpoint, the scene it was trained on (``checkpoint_scene``, from its meta) and, when
    that is not LatPlan's, the warning `load_perceiver` printed (``warnings``)."""
    scenes = {}
    if options.get("checkpoint"):
        trained = checkpoint_scene(load_checkpoint(options["checkpoint"])[1])
        scenes["checkpoint_scene"] = trained
        if trained != SCENE:
            scenes["warnings"] = [scene_warning(options["checkpoint"], trained)]
    return {
        "benchmark": "latplan-40",
        "data": str(data.root),
        "n": len(data.instances),
        "instances": [i.name for i in data.instances],
        **options,
        **scenes,
        "machine": machine,
        "cited": [dict(zip(("row", "valid", "optimal"), c, strict=True)) for c in CITED],
        "summary": list(summary),
    }
