"""BENCHMARKS.md and the README's "Current results" block, rendered from the typed records.

`render` turns every record of ``results/current/`` (`tamp.bench.record.records`) into the
"Current results" block (one table per family, the paper's or peers' figures beside ours), and
`page` into the whole of BENCHMARKS.md: that block, the families measured only in
``docs/experiments/`` so far (`STUDIED`: the command that would record each, the studies
holding its latest figures) and the index of those studies. The README carries the same block
between the same markers (`replace_block`). Both are regenerated, never typed, and tests check
that they still equal what the records give. `update` records results folders and regenerates
both.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from tamp.bench.record.records import (
    LABELS,
    Family,
    Record,
    extract,
    folders,
    load_all,
    write,
)
from task.errors import DataError

START = "<!-- current results: written by `tamp bench record`; do not edit by hand -->"
END = "<!-- end of current results -->"

TITLES = {  # each family's table heading in the "Current results" block
    Family.PLANNING: "Planning (`tamp bench planbench`, `bench pddl`, `bench random`)",
    Family.LATPLAN: "Planning from LatPlan's images (`tamp bench latplan`)",
    Family.MOTION: "Motion-level episodes (`tamp bench motion`)",
    Family.TAMP: "Geometric TAMP (`tamp bench tamp`)",
}
CITED = {  # (benchmark, instances) -> the paper's figures (Wei & AbdAlmageed 2026) and peers'
    ("planbench", 600): "paper 596/600, 58.78% optimal, 9.96 s/instance (A100); "
    "o1-preview 587/600, 40.43 s",
    ("planbench-logistics", 200): "paper 196/200, 36.28 s/instance (A100); o1-preview 188/200",
    ("planbench-sokoban", 55): "paper 33/55, 53.02 s/instance (A100); o1-preview 7/55",
    ("latplan-40", 40): "paper 40/40, 31/40 optimal; LatPlan AMA+4 33/40",
}

EXPERIMENTS = "docs/experiments"  # the studies, one file each, and their index.md


@dataclass(frozen=True)
class Studied:
    """A benchmark family measured so far only in studies under ``docs/experiments/``."""

    name: str  # the record it would have: results/current/<name>.json
    title: str
    command: str  # what produces it, as the studies last ran it (from the repository root)
    studies: tuple[str, ...]  # the files under docs/experiments/ that hold its latest figures
    readable: bool  # `extract` reads its results.json (a Family), so `bench record` records it


STUDIED = (
    Studied(
        "motion",
        "Motion-level episodes, PlanBench instances in both simulators",
        "tamp bench motion --n 100 --sim pybullet,mujoco --out results/motion",
        ("arm-moves.md", "executability.md", "hard-scenes.md"),
        True,
    ),
    Studied(
        "executability",
        "Motion-level executability of anyone's plans",
        "tamp bench executability --plans ../shared/data/planbench/llm_plans "
        "--data ../shared/data/planbench/blocksworld --n 600 --sim pybullet,mujoco --workers 2 "
        "--no-progress --out results/executability",
        ("executability.md",),
        False,
    ),
    Studied(
        "perception",
        "Planning from rendered images",
        "tamp bench perception --n 600 --modes frozen,optimised --crisp true,perceived "
        "--out results/perception",
        ("perception.md", "camera.md"),
        False,
    ),
    Studied(
        "latplan",
        "LatPlan-40 from its own images",
        "tamp bench latplan --threads 1 --out results/latplan",
        ("latplan.md",),
        True,
    ),
    Studied(
        "tamp",
        "Geometric TAMP: the six canonical problems",
        "tamp bench tamp --n 20 --sim pybullet,mujoco --planner motion-aware --workers 2 "
        "--no-progress --out results/tamp",
        ("geometric-tamp.md", "hard-scenes.md", "user-domain.md"),
        True,
    ),
    Studied(
        "big",
        "Big problems: 50 and 100 random Blocksworld blocks",
        "tamp bench random --blocks 100 --n 20 --seed 0 --max-nodes 1 --time-limit 120 "
        "--max-windows 1000 --one-at-a-time --baselines us,gn1 --lama --threads 1 --no-progress "
        "--out results/big",
        ("big-problems.md", "long-problems.md", "latency.md"),
        True,
    ),
    Studied(
        "lift",
        "The generic STRIPS lift on IPC domains",
        "tamp bench pddl --data ../shared/data/ipc/miconic --threads 1 --out results/lift",
        ("strips-lift.md", "cross-domain.md"),
        True,
    ),
    Studied(
        "checker",
        "Collision checking: the sphere checker",
        "tamp bench checker --out results/checker",
        ("sphere-checker.md",),
        False,
    ),
)

HEADER = (  # BENCHMARKS.md's opening paragraph (each item a line of the file)
    "# Benchmarks",
    "",
    "This file is generated whole by `tamp bench record` (`tamp.bench.record`) from the records "
    "in `results/current/` and the index of `docs/experiments/`; do not edit it by hand, and a "
    "test fails when it differs from what they give. **Current results** is the record to quote: "
    "one table per benchmark family, each row with the commit it ran at, the machine, the date "
    "and the command that reproduces it, the paper's or peers' figures beside ours. Each record "
    "(`results/current/NAME.json`, committed; the rest of `results/` is not) is written from a "
    "benchmark's `--out` folder; a run whose checkout had uncommitted changes is marked in its "
    "row, and a results folder that names no commit is refused. To refresh a row, run its "
    "command from the repository root, then `tamp bench record --results results/NAME`.",
)
NOTES = (  # the notes under the current results, one bullet a line
    "- **Machine and load.** The machine has 2 cores, shared with other people's work; the "
    '"load" column is the 1-minute load average as each run ended (above 2, every core was '
    "contended), so times per instance are upper bounds for this CPU. The paper's times are on "
    "an A100: different hardware, not a like-for-like speed ratio. No GPU run has been made.",
    "- **What is counted.** Every plan is converted to PDDL actions and checked by "
    "`task.symbolic.validate`, a STRIPS simulator over the PDDL files, cross-checked against "
    'unified-planning\'s `SequentialPlanValidator` in the tests. "Optimal" means a valid plan '
    "as long as the known optimum (`tamp.bench.summary.is_optimal`); its percentage is over the "
    "valid plans whose instance has a known optimum. Blocksworld-600 is PlanBench's official "
    "zero-shot set (`generated_basic/instance-1..500` and `generated_basic_3/instance-1..100`; "
    "100 x 3, 445 x 4, 55 x 5 blocks; optima from the manifest's BFS, which our A* reproduces "
    "on all 600). Logistics and Sokoban optima come from the manifest and, when the `bench` "
    "extra (Fast Downward) is installed, from `tamp.bench.fast_downward`. The Logistics and "
    "Sokoban rows at `cce0d0b` ran with it installed: every Logistics instance and 43 of the 55 "
    "Sokoban instances have a proven optimum (Fast Downward's search runs inside the "
    "benchmark's wall time, which is why Sokoban's whole process took 27 min against 542 s of "
    "planning). Without the extra, Logistics has no proven optimum and the row gives the share "
    "of valid plans no longer than PlanBench's reference plan instead.",
    "- **Tuning.** The planner's defaults were developed while looking at PlanBench-600, and "
    "Sokoban's domain defaults on the official 55 (the only Sokoban instances PlanBench has); "
    'see the caveats in the studies ("What these numbers mean" in '
    f"[{EXPERIMENTS}/planbench-blocksworld.md]({EXPERIMENTS}/planbench-blocksworld.md), the "
    f"cross-domain notes in [{EXPERIMENTS}/cross-domain.md]({EXPERIMENTS}/cross-domain.md)). "
    '"0 inexecutable" holds by construction: the decoder stops a window at its first illegal '
    "move.",
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


def _motion(row: Mapping) -> str:
    e = row["episodes"]
    text = (
        f"{row['sim']}: {row['goal_reached']}/{e} goal reached, {row['moves_ok']}/{row['moves']} "
        f"moves ok, {row['collided']} collided, {row['replans']} replans"
    )
    if row["plans_valid"] is not None:
        text += f", {row['plans_valid']}/{e} first plans valid"
    if row["with_faults"]:
        text += f", {row['recovered']}/{row['with_faults']} with injected faults recovered"
    return text + f", {row['wall_per_move_s']:.3g} s wall/move"


def _tamp(rows: Sequence[Mapping]) -> str:
    """Per planner and simulator: solved over every problem, then each problem's count."""
    groups: dict[tuple[str, str], list[Mapping]] = {}
    for r in rows:
        groups.setdefault((r["planner"], r["sim"]), []).append(r)
    parts = []
    for (planner, sim), mine in groups.items():
        solved, episodes = sum(r["solved"] for r in mine), sum(r["episodes"] for r in mine)
        each = ", ".join(f"{r['problem']} {r['solved']}/{r['episodes']}" for r in mine)
        collided = sum(r["collided"] for r in mine)
        parts.append(f"{planner}, {sim}: {solved}/{episodes} solved ({each}), {collided} collided")
    return "; ".join(parts)


def ours(record: Record) -> str:
    """The table's "ours" cell: valid, optimal, time (planning), per input kind (latplan), per
    simulator (motion), per planner and simulator (tamp)."""
    if record.family is Family.LATPLAN:
        text = _latplan(record.figures)
    elif record.family is Family.MOTION:
        text = "; ".join(_motion(r) for r in record.figures)
    elif record.family is Family.TAMP:
        text = _tamp(record.figures)
    elif len(record.figures) == 1:
        text = _planning(record.figures[0])
    else:
        text = "; ".join(f"T={r['horizon']}: {_planning(r)}" for r in record.figures)
    seeds = len(record.seeds)
    return text + (f" (mean of {seeds} seeds)" if seeds > 1 else "")


def label(record: Record) -> str:
    if record.family is Family.MOTION:
        return f"Motion, {record.instances} episodes per simulator"
    if record.family is Family.TAMP:
        return f"Canonical problems, {record.instances} variants each"
    return f"{LABELS.get(record.benchmark, record.benchmark)}-{record.instances}"


def _machine(m: Mapping) -> str:
    threads = m.get("torch_threads")
    load = m.get("load_1min")
    return (
        f"{m.get('cores')} cores {m.get('processor')} ({m.get('device')}), torch {m.get('torch')}, "
        f"{threads} thread{'s' if threads != 1 else ''}, load {load if load is not None else '?'}"
    )


def _table(records: Sequence[Record]) -> list[str]:
    lines = [
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
    return lines


def render(records: Sequence[Record]) -> str:
    """The "Current results" block, markers included: one table per family that has records
    (the same records give the same text)."""
    lines = [START]
    for family in Family:
        mine = [r for r in records if r.family is family]
        if mine:
            lines += ["", f"**{TITLES[family]}**", "", *_table(mine)]
    if not records:
        lines += ["", "(no records yet: run `tamp bench record --results DIR`)"]
    if any(r.dirty for r in records):
        lines += [
            "",
            "**+ uncommitted changes**: that run's checkout had changes not in the commit named, "
            "so the commit alone does not reproduce it.",
        ]
    lines += ["", END]
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


def studied(records: Sequence[Record]) -> list[str]:
    """The "Families without a current record" section: each `STUDIED` family whose record
    name is not among ``records``, the command that would record it, and its studies."""
    names = {r.name for r in records}
    lines = [
        "## Families without a current record",
        "",
        "These families were measured, but no run of theirs has a record yet, so their figures",
        "stand only in the studies under `docs/experiments/`, at the commits those name. To",
        "record one, run its command (from the repository root, on a clean checkout), then",
        "`tamp bench record --results results/NAME`. Where `bench record` cannot read the",
        "family's results yet, the row says so.",
        "",
        "| family | record | command that would produce it | latest measured figures |",
        "|---|---|---|---|",
    ]
    missing = [s for s in STUDIED if s.name not in names]
    for s in missing:
        where = ", ".join(f"[{f}]({EXPERIMENTS}/{f})" for f in s.studies)
        reads = f"`{s.name}`" + ("" if s.readable else " (not yet readable by `bench record`)")
        lines.append(f"| {s.title} | {reads} | `{s.command}` | {where} |")
    if not missing:
        lines.append("| (every family has a record) | | | |")
    return lines


def experiments_index(root: str | Path = ".") -> list[str]:
    """The list of ``docs/experiments/index.md`` (its ``- [title](file): ...`` lines), the
    links made relative to the repository root; DataError when it cannot be read."""
    path = Path(root) / EXPERIMENTS / "index.md"
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise DataError(f"{path}: cannot read ({exc.strerror or exc})") from None
    items = [line for line in text.splitlines() if line.startswith("- [")]
    return [re.sub(r"\]\(([^)/]+\.md)\)", rf"]({EXPERIMENTS}/\1)", line) for line in items]


def page(records: Sequence[Record], root: str | Path = ".") -> str:
    """The whole of BENCHMARKS.md: the header, `render`'s block, the notes on it, `studied`,
    and the index of ``root``'s ``docs/experiments/``."""
    lines = [
        *HEADER,
        "",
        "## Current results",
        "",
        render(records),
        "",
        *NOTES,
        "",
        *studied(records),
        "",
        "## Experiments",
        "",
        f"Studies, ablations, negative results and profiles, one file per study under "
        f"[{EXPERIMENTS}/]({EXPERIMENTS}/index.md); each names the commits its runs used and the "
        "records it reads.",
        "",
        *experiments_index(root),
    ]
    return "\n".join(lines) + "\n"


def update(
    paths: Iterable[str | Path],
    into: str | Path,
    markdown: str | Path,
    readme: str | Path | None = None,
) -> list[Record]:
    """Record each results folder of ``paths`` into ``into``, then write ``markdown`` whole
    (`page`, with the experiments index under ``markdown``'s folder) and regenerate the block
    in ``readme`` (None: no README) from every record there. Everything is read and checked
    before anything is written. Returns the records written."""
    records = [extract(f) for f in folders(paths)]
    names = [r.name for r in records]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise DataError(f"two results folders named {', '.join(twice)}: a record is per name")
    text = None
    if readme is not None:
        readme = Path(readme)
        try:
            text = readme.read_text(encoding="utf-8")
        except OSError as exc:
            raise DataError(f"{readme}: cannot read ({exc.strerror or exc})") from None
        block_of(text)
    markdown = Path(markdown)
    root = markdown.parent
    experiments_index(root)
    for r in records:
        write(r, into)
    every = load_all(into)
    markdown.write_text(page(every, root), encoding="utf-8")
    if readme is not None:
        readme.write_text(replace_block(text, render(every)), encoding="utf-8")
    return records
