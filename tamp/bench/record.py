"""The current results: one compact record per benchmark, and the table generated from them.

``tamp bench record --results DIR...`` reads benchmark results folders (each with the
``results.json`` its benchmark wrote through `tamp.bench.results`) and writes one `Record` per
folder into a committed folder (``results/current/<folder name>.json``): the summary figures the
benchmark's table shows, the command that produced them, the commit it ran at and whether the
checkout had uncommitted changes, the machine and the date. `render` turns every record of that
folder into the "Current results" table, and `replace_block` puts it between the `START` and
`END` markers of BENCHMARKS.md, so that table is regenerated, never typed, and a test checks
that it still equals what the records give.

A results folder that names no commit (written before results recorded one, or run outside a
git checkout) is refused: its code cannot be named. One run on uncommitted changes is recorded,
and its row says so.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from task.errors import DataError

START = "<!-- current results: written by `tamp bench record`; do not edit by hand -->"
END = "<!-- end of current results -->"

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
MACHINE = ("cores", "processor", "python", "torch", "torch_threads", "device", "load_1min")

LABELS = {  # results.json "benchmark" -> the table's name for it (the instance count follows)
    "planbench": "PlanBench Blocksworld",
    "planbench-logistics": "PlanBench Logistics",
    "planbench-sokoban": "PlanBench Sokoban",
    "latplan-40": "LatPlan",
}
CITED = {  # (benchmark, instances) -> the paper's figures (Wei & AbdAlmageed 2026) and peers'
    ("planbench", 600): "paper 596/600, 58.78% optimal, 9.96 s/instance (A100); "
    "o1-preview 587/600, 40.43 s",
    ("planbench-logistics", 200): "paper 196/200, 36.28 s/instance (A100); o1-preview 188/200",
    ("planbench-sokoban", 55): "paper 33/55, 53.02 s/instance (A100); o1-preview 7/55",
    ("latplan-40", 40): "paper 40/40, 31/40 optimal; LatPlan AMA+4 33/40",
}


@dataclass(frozen=True)
class Record:
    """What one benchmark run gave and what produced it (``results/current/<name>.json``)."""

    name: str  # the results folder's name, e.g. planbench, logistics
    benchmark: str  # results.json "benchmark": planbench, planbench-logistics, latplan-40, ...
    instances: int
    seeds: tuple[int, ...]
    figures: tuple[Mapping, ...]  # planning: a row per horizon; latplan: per resolution, mode
    command: str  # "tamp bench ..." as it was typed
    commit: str  # the git commit the code ran at
    dirty: bool  # the checkout had changes not in ``commit``
    machine: Mapping  # cores, processor, python, torch, threads, load average at the end
    date: str  # when the run ended (UTC, ISO 8601)

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, body: Mapping) -> Record:
        return cls(**{**body, "seeds": tuple(body["seeds"]), "figures": tuple(body["figures"])})


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
    benchmark = body.get("benchmark")
    if benchmark == "latplan-40":
        figures = tuple({k: s.get(k) for k in LATPLAN_FIGURES} for s in body["summary"])
        instances, seeds = body["n"], body["seeds"]
    elif isinstance(body.get("summary"), list) and "horizons" in body:
        figures, instances, seeds = _planning_figures(body), body["instances"], body["seeds"]
    else:
        raise DataError(
            f"{path}: not a planning (planbench, pddl, random) or latplan benchmark's results; "
            "those are the ones a record summarises"
        )
    return Record(
        name=name,
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
    order = list(LABELS)
    return sorted(
        records,
        key=lambda r: (order.index(r.benchmark) if r.benchmark in order else len(order), r.name),
    )


def _count(x: float) -> str:
    return f"{x:.0f}" if float(x).is_integer() else f"{x:.1f}"


def _planning(row: Mapping) -> str:
    n, valid = row["n"], row["valid"]
    text = f"{_count(valid)}/{n} valid"
    lost = [
        f"{_count(row[k])} {label}"
        for k, label in (
            ("inexecutable", "inexecutable"),
            ("non_goal_reaching", "non-goal"),
            ("no_plan", "no plan"),
        )
        if row[k]
    ]
    if lost:
        text += f" ({', '.join(lost)})"
    if row["optimal_pct"] is not None:
        text += f", {row['optimal_pct']:.1f}% optimal"
        if row["known"] < n:
            text += f" (of valid plans; optimum known for {row['known']}/{n})"
    elif row["at_most_ref_pct"] is not None:
        text += f", {row['at_most_ref_pct']:.1f}% no longer than the reference plan"
    wall = "" if row["wall_s"] is None else f", {row['wall_s']:.0f} s in all"
    return f"{text}, {row['time_s']:.3g} s/instance{wall}"


def _spread(values: Sequence[float], n: int) -> str:
    lo, hi = min(values), max(values)
    return f"{_count(lo)}/{n}" if lo == hi else f"{_count(lo)}-{_count(hi)}/{n}"


def _latplan(rows: Sequence[Mapping]) -> str:
    parts = []
    for label, chosen in (
        ("true states", [r for r in rows if r["mode"] == "state"]),
        ("images", [r for r in rows if r["mode"] != "state"]),
    ):
        if chosen:
            n = chosen[0]["n"]
            valid = _spread([r["valid"]["mean"] for r in chosen], n)
            optimal = _spread([r["optimal"]["mean"] for r in chosen], n)
            kinds = sorted({f"{r['mode']} {r['resolution']}" for r in chosen})
            where = "" if label == "true states" else f" ({', '.join(kinds)})"
            parts.append(f"{label}{where}: {valid} valid, {optimal} optimal")
    return "; ".join(parts)


def ours(record: Record) -> str:
    """The table's "ours" cell: valid, optimal, time (planning), or per input kind (latplan)."""
    if record.benchmark == "latplan-40":
        text = _latplan(record.figures)
    elif len(record.figures) == 1:
        text = _planning(record.figures[0])
    else:
        text = "; ".join(f"T={r['horizon']}: {_planning(r)}" for r in record.figures)
    seeds = len(record.seeds)
    return text + (f" (mean of {seeds} seeds)" if seeds > 1 else "")


def label(record: Record) -> str:
    return f"{LABELS.get(record.benchmark, record.benchmark)}-{record.instances}"


def _machine(m: Mapping) -> str:
    threads = m.get("torch_threads")
    load = m.get("load_1min")
    return (
        f"{m.get('cores')} cores {m.get('processor')} ({m.get('device')}), torch {m.get('torch')}, "
        f"{threads} thread{'s' if threads != 1 else ''}, load {load if load is not None else '?'}"
    )


def render(records: Sequence[Record]) -> str:
    """The "Current results" block, markers included (the same records give the same text)."""
    lines = [
        START,
        "| benchmark | ours | cited beside it | commit, date | machine, load at end | command |",
        "|---|---|---|---|---|---|",
    ]
    for r in records:
        commit = f"`{r.commit[:7]}`" + (" **+ uncommitted changes**" if r.dirty else "")
        cited = CITED.get((r.benchmark, r.instances), "-")
        lines.append(
            f"| {label(r)} | {ours(r)} | {cited} | {commit}, {r.date[:10]} | "
            f"{_machine(r.machine)} | `{r.command}` |"
        )
    if not records:
        lines.append("| (no records yet: run `tamp bench record --results DIR`) | | | | | |")
    if any(r.dirty for r in records):
        lines += [
            "",
            "**+ uncommitted changes**: that run's checkout had changes not in the commit named, "
            "so the commit alone does not reproduce it.",
        ]
    lines.append(END)
    return "\n".join(lines)


def replace_block(text: str, block: str) -> str:
    """``text`` with what lies between its `START` and `END` lines replaced by ``block``."""
    start, end = text.find(START), text.find(END)
    if start < 0 or end < start:
        raise DataError(f"no current-results markers: add the lines {START!r} and {END!r}")
    return text[:start] + block + text[end + len(END) :]


def block_of(text: str) -> str:
    """The block between (and including) the markers of ``text``, as `render` writes it."""
    start, end = text.find(START), text.find(END)
    if start < 0 or end < start:
        raise DataError(f"no current-results markers: add the lines {START!r} and {END!r}")
    return text[start : end + len(END)]


def update(paths: Iterable[str | Path], into: str | Path, markdown: str | Path) -> list[Record]:
    """Record each results folder of ``paths`` into ``into``, then regenerate the table in
    ``markdown`` from every record there. Everything is read and checked before anything is
    written. Returns the records written."""
    records = [extract(f) for f in folders(paths)]
    names = [r.name for r in records]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise DataError(f"two results folders named {', '.join(twice)}: a record is per name")
    markdown = Path(markdown)
    try:
        text = markdown.read_text(encoding="utf-8")
    except OSError as exc:
        raise DataError(f"{markdown}: cannot read ({exc.strerror or exc})") from None
    block_of(text)
    for r in records:
        write(r, into)
    markdown.write_text(replace_block(text, render(load_all(into))), encoding="utf-8")
    return records
