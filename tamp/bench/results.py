"""The one results writer of every benchmark: output folder, machine record, JSON, CSV, plots.

Every benchmark writes through here: `out_folder` creates ``--out`` (one-line error when it
cannot), `write_json` a ``results.json`` that carries the configuration and `machine` (cores,
platform, torch version, date, and what produced it: the command line, the git commit and
whether the checkout had uncommitted changes), `write_csv` one row per instance or episode.
The planning benchmarks also get ``steps.png`` (`plot_steps`: our plan lengths against the
optimal ones). matplotlib is imported only when a plot is drawn (Agg backend, no display
needed).
"""

from __future__ import annotations

import csv
import datetime
import json
import os
import platform
import shlex
import subprocess
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path

from tamp.bench.planning import INSTANCE_COLUMNS, Bench, beside_best
from tamp.bench.summary import latency_rows, main_rows, size_rows
from task.errors import TampError


def git_state(root: Path | None = None) -> tuple[str | None, bool | None]:
    """``(commit, dirty)`` of the checkout holding this code (``root``: this repository);
    ``(None, None)`` outside a git checkout of it (an installed copy, no git). ``dirty``: the
    checkout has changes not committed, untracked files included (ignored ones not)."""
    root = Path(__file__).resolve().parents[2] if root is None else root

    def git(*args: str) -> str | None:
        try:
            done = subprocess.run(
                ["git", "-C", str(root), *args], capture_output=True, text=True, timeout=30
            )
        except (OSError, subprocess.SubprocessError):
            return None
        return done.stdout if done.returncode == 0 else None

    top = git("rev-parse", "--show-toplevel")
    if top is None or Path(top.strip()).resolve() != root.resolve():
        return None, None  # not a checkout, or this code sits inside some other repository
    commit, status = git("rev-parse", "HEAD"), git("status", "--porcelain")
    if commit is None or status is None:
        return None, None
    return commit.strip(), bool(status.strip())


def machine(argv: Sequence[str] | None = None, device: str | None = None) -> dict:
    """Where and from what the benchmark ran: the machine, its load average as the run ended,
    the date, the command line ``tamp`` + ``argv`` (None when no command line ran it),
    `git_state`, and the torch ``device`` planning ran on (None: the CPU) with the GPU's name
    on a CUDA device."""
    import torch

    device = device or "cpu"
    gpu = torch.cuda.get_device_name(torch.device(device)) if device != "cpu" else None

    commit, dirty = git_state()
    return {
        "cores": os.cpu_count(),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "torch": torch.__version__,
        "torch_threads": torch.get_num_threads(),
        "device": device,
        "gpu": gpu,
        "cuda": torch.version.cuda,
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "load_1min": round(os.getloadavg()[0], 2),  # other work on the machine as it finished
        "command": None if argv is None else f"tamp {shlex.join(argv)}".strip(),
        "commit": commit,
        "dirty": dirty,
    }


def results(bench: Bench, argv: Sequence[str] | None = None) -> dict:
    """The JSON-ready report of a benchmark (no per-instance rows; see ``instances.csv``);
    ``argv``: the command line's arguments after ``tamp``, recorded in ``machine``."""
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
        "machine": machine(argv, bench.config.device),
        "summary": [s.asdict() for s in main_rows(bench)],
        "size_name": bench.size_name,
        "by_size": [s.asdict() for s in size_rows(bench)],
        "latency_by_size": latency_rows(bench),
        "speed": speed,
    }


def _cell(value: object, digits: int | None) -> object:
    if value is None:
        return ""
    if isinstance(value, float) and digits is not None:
        return f"{value:.{digits}f}"
    return value


def write_csv(
    path: Path,
    rows: Sequence[Mapping | object],
    columns: Sequence[str] | None = None,
    digits: int | None = None,
) -> Path:
    """One CSV row per mapping or dataclass in ``rows``; columns default to the first row's
    keys or fields; None is written empty and floats with ``digits`` decimals when given."""
    dicts = [r if isinstance(r, Mapping) else asdict(r) for r in rows]
    names = list(columns if columns is not None else (dicts[0] if dicts else ()))
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(names)
        for row in dicts:
            writer.writerow(_cell(row.get(n), digits) for n in names)
    return path


def write_json(path: Path, body: dict) -> Path:
    """``body`` as indented JSON (a trailing newline)."""
    path.write_text(json.dumps(body, indent=2) + "\n", encoding="utf-8")
    return path


def out_folder(path: str | Path) -> Path:
    """``--out`` as a created folder; TampError naming it when it cannot be created."""
    out = Path(path)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise TampError(f"--out {out}: cannot create folder ({exc.strerror or exc})") from None
    return out


def _bars(ax, series: list[tuple[str, Counter, float]]) -> None:
    """Grouped bars: one group per x value, one bar per ``(label, counts, scale)`` series."""
    width = 1.6 / len(series)
    for k, (label, counts, scale) in enumerate(series):
        xs = sorted(counts)
        offset = (k - (len(series) - 1) / 2) * width
        ax.bar([x + offset for x in xs], [counts[x] * scale for x in xs], width, label=label)
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.legend()


def plot_steps(bench: Bench, path: Path) -> Path:
    """Left: plan-length distributions, the optimal one against ours per horizon (valid plans).

    Right: how many actions our valid plans exceed the optimum by, where it is known.
    Counts of our plans are means over seeds.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, scale = bench.rows(), 1.0 / len(bench.seeds)
    first = [r for r in rows if r.horizon == bench.horizons[0] and r.seed == bench.seeds[0]]
    best = {r.instance: r.optimal if r.optimal is not None else r.reference for r in first}
    label = "optimal" if all(r.reference is None for r in first) else "optimal or reference"
    lengths = [(label, Counter(v for v in best.values() if v is not None), 1.0)]
    excess = []
    for h in bench.horizons:
        valid = [r for r in rows if r.horizon == h and r.status == "valid"]
        lengths.append((f"ours, T={h}", Counter(r.length for r in valid), scale))
        known = Counter(r.length - best[r.instance] for r in valid if best[r.instance] is not None)
        excess.append((f"T={h}", known, scale))
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    _bars(left, lengths)
    left.set(xlabel="plan length (PDDL actions)", ylabel="instances")
    left.set_title(f"{bench.suite} ({bench.n} instances): plan lengths")
    _bars(right, excess)
    right.set(xlabel=f"our length - {label} length (actions)", ylabel="valid plans")
    right.set_title(f"excess over the {label}")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write(bench: Bench, out_dir: str | Path, report: dict | None = None) -> tuple[Path, ...]:
    """A planning benchmark's three artefacts in ``out_dir`` (created); returns their paths."""
    out = out_folder(out_dir)
    return (
        write_csv(
            out / "instances.csv",
            [beside_best(r) for r in bench.rows()],
            INSTANCE_COLUMNS,
            digits=4,
        ),
        write_json(out / "results.json", report if report is not None else results(bench)),
        plot_steps(bench, out / "steps.png"),
    )
