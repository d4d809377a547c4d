"""The typed record of one benchmark run, and reading it from a benchmark's results folder.

``tamp bench record --results DIR...`` reads benchmark results folders (each with the
``results.json`` its benchmark wrote through `tamp.bench.results`) and writes one `Record` per
folder into a committed folder (``results/current/<folder name>.json``): its `Family` (planning,
latplan, motion, tamp), the summary figures that family's table shows (`FIGURES`), the command
that produced them, the commit it ran at and whether the checkout had uncommitted changes, the
machine and the date. `tamp.bench.record.markdown` renders the records as BENCHMARKS.md and the
README's "Current results" block.

A results folder that names no commit (written before results recorded one, or run outside a
git checkout) is refused: its code cannot be named; so is a partial (interrupted) run. One run
on uncommitted changes is recorded, and its row says so.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass
from enum import StrEnum
from pathlib import Path

from task.errors import DataError


class Family(StrEnum):
    """A benchmark family: which results.json layout a record reads and which table it joins."""

    PLANNING = "planning"  # bench planbench, bench pddl, bench random
    LATPLAN = "latplan"  # bench latplan
    MOTION = "motion"  # bench motion
    TAMP = "tamp"  # bench tamp


PLANNING_FIGURES = (  # of a planning benchmark's summary row, the figures a record keeps
    "horizon",
    "n",
    "known",
    "valid",
    "optimal",
    "optimal_pct",
    "inexecutable",
    "non_goal_reaching",
    "no_plan",
    "time_s",
    "wall_s",
    "with_ref",
    "at_most_ref_pct",
    "length",
    "ratio",
)
LATPLAN_FIGURES = ("resolution", "mode", "n", "valid", "optimal", "read_right")
MOTION_FIGURES = (  # of `tamp.bench.motion.summarise`'s figures per simulator (its key: "sim")
    "sim",
    "episodes",
    "plans_valid",
    "executed_valid",
    "goal_reached",
    "moves",
    "moves_ok",
    "failures",
    "replans",
    "with_faults",
    "recovered",
    "collided",
    "rerouted",
    "geo_moves",
    "wall_per_move_s",
    "plan_per_episode_s",
    "arm_path_rad",
)
TAMP_FIGURES = (  # of `tamp.bench.geo.run.summarise`'s row per (problem, planner, simulator)
    "problem",
    "planner",
    "sim",
    "episodes",
    "solved",
    "clean",
    "collided",
    "plan_length",
    "planning_p50_s",
    "planning_p90_s",
    "execution_s",
    "arm_path_rad",
)
FIGURES = {
    Family.PLANNING: PLANNING_FIGURES,
    Family.LATPLAN: LATPLAN_FIGURES,
    Family.MOTION: MOTION_FIGURES,
    Family.TAMP: TAMP_FIGURES,
}
MACHINE = ("cores", "processor", "python", "torch", "torch_threads", "device", "load_1min")

LABELS = {  # results.json "benchmark" -> the table's name for it (the instance count follows)
    "planbench": "PlanBench Blocksworld",
    "planbench-logistics": "PlanBench Logistics",
    "planbench-sokoban": "PlanBench Sokoban",
    "latplan-40": "LatPlan",
}


@dataclass(frozen=True)
class Record:
    """What one benchmark run gave and what produced it (``results/current/<name>.json``)."""

    name: str  # the results folder's name, e.g. planbench, logistics
    family: Family  # which results.json layout it was read from; its figures are FIGURES[family]
    benchmark: (
        str  # planning: results.json "benchmark" (planbench, ...); else latplan-40, motion, tamp
    )
    instances: int  # planning, latplan: instances; motion: episodes per simulator; tamp: variants
    seeds: tuple[int, ...]
    figures: tuple[Mapping, ...]  # planning: per horizon; latplan: per resolution and mode;
    # motion: per simulator; tamp: per problem, planner and simulator
    command: str  # "tamp bench ..." as it was typed
    commit: str  # the git commit the code ran at
    dirty: bool  # the checkout had changes not in ``commit``
    machine: Mapping  # cores, processor, python, torch, threads, load average at the end
    date: str  # when the run ended (UTC, ISO 8601)

    def to_json(self) -> dict:
        return {**asdict(self), "family": self.family.value}

    @classmethod
    def from_json(cls, body: Mapping) -> Record:
        try:
            family = Family(body["family"])
        except ValueError:
            valid = ", ".join(f.value for f in Family)
            raise DataError(f"family {body['family']!r} is not one of {valid}") from None
        seeds, figures = tuple(body["seeds"]), tuple(body["figures"])
        return cls(**{**body, "family": family, "seeds": seeds, "figures": figures})


def _read(path: Path) -> dict:
    try:
        body = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise DataError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataError(f"{path}: not JSON ({exc})") from None
    if not isinstance(body, dict):
        raise DataError(f"{path}: not a benchmark's results.json (no JSON object)")
    return body


def _planning_figures(body: dict) -> tuple[Mapping, ...]:
    """The row over all instances per horizon: the mean over seeds, or the one seed's row."""
    rows = [r for r in body["summary"] if r["size"] is None]
    several = len(body["seeds"]) > 1
    chosen = [r for r in rows if (r["seed"] is None) == several]
    return tuple({k: r.get(k) for k in PLANNING_FIGURES} for r in chosen)


def _family(body: dict, path: Path) -> tuple[Family, str, int, tuple, tuple[Mapping, ...]]:
    """``(family, benchmark, instances, seeds, figures)`` of a results.json, told apart by its
    layout: latplan's "benchmark", the planning suites' "horizons", the motion benchmark's
    summary per simulator beside its "ik_batch", the TAMP benchmark's rows per problem."""
    summary, config = body.get("summary"), body.get("config") or {}
    if body.get("benchmark") == "latplan-40":
        figures = tuple({k: s.get(k) for k in LATPLAN_FIGURES} for s in summary)
        return Family.LATPLAN, "latplan-40", body["n"], tuple(body["seeds"]), figures
    if isinstance(summary, list) and "horizons" in body:
        figures = _planning_figures(body)
        return Family.PLANNING, body["benchmark"], body["instances"], tuple(body["seeds"]), figures
    if isinstance(summary, dict) and summary and "ik_batch" in body:
        figures = tuple(
            {"sim": sim, **{k: s.get(k) for k in MOTION_FIGURES if k != "sim"}}
            for sim, s in summary.items()
        )
        episodes = figures[0]["episodes"]
        return Family.MOTION, "motion", episodes, (config.get("seed"),), figures
    if isinstance(summary, list) and summary and all("planner" in s for s in summary):
        figures = tuple({k: s.get(k) for k in TAMP_FIGURES} for s in summary)
        return Family.TAMP, "tamp", config.get("n"), (config.get("seed"),), figures
    valid = ", ".join(f.value for f in Family)
    raise DataError(
        f"{path}: not the results of a benchmark a record summarises (families: {valid}; "
        "planning is bench planbench, pddl and random)"
    )


def extract(folder: str | Path) -> Record:
    """The record of one benchmark results folder (its ``results.json``); DataError when the
    folder has none, the benchmark is not one a record summarises, or no commit is named."""
    folder = Path(folder)
    path = folder / "results.json"
    if not path.is_file():
        raise DataError(f"{folder}: no results.json (not a benchmark's --out folder)")
    name = folder.resolve().name
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", name):
        raise DataError(f"{folder}: name the folder with letters, digits, '.', '_', '-' only")
    body = _read(path)
    machine = body.get("machine") or {}
    if not machine.get("command"):
        raise DataError(
            f"{path}: records no command line (written by older code or not by `tamp`); "
            "rerun the benchmark with this version"
        )
    if not machine.get("commit"):
        raise DataError(
            f"{path}: records no git commit (run outside a git checkout), so its code cannot "
            "be named; rerun it in a checkout"
        )
    if body.get("partial"):
        part = body["partial"]
        raise DataError(
            f"{path}: a partial run ({part.get('done')} of {part.get('of')} done, interrupted); "
            "record a finished one"
        )
    family, benchmark, instances, seeds, figures = _family(body, path)
    return Record(
        name=name,
        family=family,
        benchmark=str(benchmark),
        instances=int(instances),
        seeds=tuple(seeds),
        figures=figures,
        command=machine["command"],
        commit=machine["commit"],
        dirty=bool(machine.get("dirty")),
        machine={k: machine.get(k) for k in MACHINE},
        date=str(machine.get("date")),
    )


def folders(paths: Iterable[str | Path]) -> list[Path]:
    """Each path that holds a ``results.json``, else its subfolders that do (a parent folder
    of several benchmarks' results); DataError for a path with neither."""
    out = []
    for p in map(Path, paths):
        if (p / "results.json").is_file():
            out.append(p)
            continue
        found = sorted(q.parent for q in p.glob("*/results.json"))
        if not found:
            raise DataError(f"{p}: no results.json in it or in its subfolders")
        out += found
    return out


def write(record: Record, into: str | Path) -> Path:
    """``record`` as ``into/<name>.json`` (``into`` created)."""
    into = Path(into)
    try:
        into.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise DataError(f"{into}: cannot create folder ({exc.strerror or exc})") from None
    path = into / f"{record.name}.json"
    path.write_text(json.dumps(record.to_json(), indent=2) + "\n", encoding="utf-8")
    return path


def load_all(into: str | Path) -> list[Record]:
    """Every record in ``into``, in the table's order (the paper's benchmarks first)."""
    records = []
    for path in sorted(Path(into).glob("*.json")):
        try:
            records.append(Record.from_json(_read(path)))
        except (KeyError, TypeError) as exc:
            raise DataError(f"{path}: not a record ({exc})") from None
        except DataError as exc:
            raise DataError(f"{path}: {exc}") from None
    order = list(LABELS)
    return sorted(
        records,
        key=lambda r: (order.index(r.benchmark) if r.benchmark in order else len(order), r.name),
    )
