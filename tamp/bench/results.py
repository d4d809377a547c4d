"""Benchmark artefacts: ``instances.csv``, ``results.json`` and ``steps.png`` in one folder.

``results.json`` holds the configuration, the machine (cores, platform, torch version, date),
the summaries and the batched-vs-sequential timing; ``instances.csv`` one row per instance,
horizon and seed; ``steps.png`` our plan lengths against the optimal ones. matplotlib is
imported only when the plot is drawn (Agg backend, no display needed).
"""

from __future__ import annotations

import csv
import datetime
import json
import os
import platform
from collections import Counter
from dataclasses import asdict, fields
from pathlib import Path

from tamp.bench.planning import Bench, Row
from tamp.bench.summary import block_rows, main_rows
from task.errors import TampError


def machine() -> dict:
    """Where the benchmark ran."""
    import torch

    return {
        "cores": os.cpu_count(),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "torch": torch.__version__,
        "torch_threads": torch.get_num_threads(),
        "device": "cpu",
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
    }


def results(bench: Bench) -> dict:
    """The JSON-ready report of a benchmark (no per-instance rows; see ``instances.csv``)."""
    speed = None
    if bench.speed is not None:
        speed = {**asdict(bench.speed), "speedup": bench.speed.speedup}
    return {
        "benchmark": bench.suite,
        "source": bench.source,
        "instances": bench.n,
        "seeds": list(bench.seeds),
        "horizons": list(bench.horizons),
        "config": asdict(bench.config),
        "machine": machine(),
        "summary": [s.asdict() for s in main_rows(bench)],
        "by_blocks": [s.asdict() for s in block_rows(bench)],
        "speed": speed,
    }


def _cell(value: object) -> object:
    if value is None:
        return ""
    return f"{value:.4f}" if isinstance(value, float) else value


def write_csv(rows: tuple[Row, ...], path: Path) -> None:
    names = [f.name for f in fields(Row)]
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(names)
        for row in rows:
            values = (getattr(row, n) for n in names)
            writer.writerow(_cell(v) for v in values)


def _bars(ax, series: list[tuple[str, Counter, float]]) -> None:
    """Grouped bars: one group per x value, one bar per ``(label, counts, scale)`` series."""
    width = 1.6 / len(series)
    for k, (label, counts, scale) in enumerate(series):
        xs = sorted(counts)
        offset = (k - (len(series) - 1) / 2) * width
        ax.bar([x + offset for x in xs], [counts[x] * scale for x in xs], width, label=label)
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.legend()


def plot_steps(bench: Bench, path: Path) -> None:
    """Left: plan-length distributions, the optimal one against ours per horizon (valid plans).

    Right: how many actions our valid plans exceed the optimum by, where it is known.
    Counts of our plans are means over seeds.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, scale = bench.rows(), 1.0 / len(bench.seeds)
    first = [r for r in rows if r.horizon == bench.horizons[0] and r.seed == bench.seeds[0]]
    lengths = [("optimal", Counter(r.optimal for r in first if r.optimal is not None), 1.0)]
    excess = []
    for h in bench.horizons:
        valid = [r for r in rows if r.horizon == h and r.status == "valid"]
        lengths.append((f"ours, T={h}", Counter(r.length for r in valid), scale))
        known = Counter(r.length - r.optimal for r in valid if r.optimal is not None)
        excess.append((f"T={h}", known, scale))
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    _bars(left, lengths)
    left.set(xlabel="plan length (4-op actions)", ylabel="instances")
    left.set_title(f"{bench.suite} ({bench.n} instances): plan lengths")
    _bars(right, excess)
    right.set(xlabel="our length - optimal length (actions)", ylabel="valid plans")
    right.set_title("excess over the optimum")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write(bench: Bench, out_dir: str | Path, report: dict | None = None) -> tuple[Path, ...]:
    """Write the three artefacts into ``out_dir`` (created); returns their paths."""
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise TampError(f"--out {out}: cannot create folder ({exc.strerror or exc})") from None
    paths = (out / "instances.csv", out / "results.json", out / "steps.png")
    write_csv(bench.rows(), paths[0])
    text = json.dumps(report if report is not None else results(bench), indent=2)
    paths[1].write_text(text + "\n", encoding="utf-8")
    plot_steps(bench, paths[2])
    return paths
