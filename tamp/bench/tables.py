"""The one table printer of every benchmark: the paper-style tables as text.

`table` pads columns to their widest cell (numbers right-aligned); `planning_report` prints a
planning benchmark (by horizon and seed, then by block count), `motion_table` the executability
table of the motion benchmark, `perception_table` the rows of planning from images. Pure string
formatting: nothing here runs a benchmark or prints.
"""

from __future__ import annotations

from collections.abc import Sequence

from tamp.bench.planning import Bench
from tamp.bench.summary import Summary, block_rows, main_rows


def table(headers: Sequence[str], rows: Sequence[Sequence[object]], indent: str = "  ") -> str:
    """Columns padded to their widest cell; numbers right-aligned, text left-aligned."""
    cells = [[str(c) for c in headers], *[[str(c) for c in r] for r in rows]]
    widths = [max(len(r[k]) for r in cells) for k in range(len(headers))]
    numeric = [all(_is_number(r[k]) for r in cells[1:]) for k in range(len(headers))]
    lines = []
    for r in cells:
        parts = [
            c.rjust(w) if num else c.ljust(w) for c, w, num in zip(r, widths, numeric, strict=True)
        ]
        lines.append(indent + "  ".join(parts).rstrip())
    return "\n".join(lines)


def _is_number(text: str) -> bool:
    return text.replace(".", "", 1).replace("%", "").replace("/", "", 1).strip("-").isdigit()


def count(value: float) -> str:
    """A count, or a mean count over seeds with one decimal."""
    return str(int(value)) if float(value).is_integer() else f"{value:.1f}"


def _row(s: Summary, first: str) -> list[str]:
    pct = "-" if s.optimal_pct is None else f"{s.optimal_pct:.1f}%"
    wall = "" if s.wall_s is None else f"{s.wall_s:.1f}"
    return [
        str(s.horizon),
        first,
        f"{count(s.valid)}/{s.n}",
        pct,
        str(s.known),
        count(s.inexecutable),
        count(s.non_goal_reaching),
        count(s.no_plan),
        f"{s.time_s:.3f}",
        wall,
        f"{s.windows:.2f}",
    ]


_HEAD = ["valid", "optimal", "known", "inexec.", "non-goal", "no plan", "s/inst", "wall s", "win."]


def planning_report(bench: Bench) -> str:
    """The paper-style tables of a benchmark: by (horizon, seed), then by block count."""
    c = bench.config
    seeds = ",".join(str(s) for s in bench.seeds)
    lines = [
        f"{bench.suite}: {bench.n} instances ({bench.source})",
        f"seeds {seeds}; restarts {c.restarts}, iters {c.iters}, goal loss {c.goal_loss}, "
        f"lookahead {c.lookahead} x {c.lookahead_share:g} of restarts, "
        f"tau {c.tau:g}->{c.tau_end:g}, max windows {c.max_windows}",
        "",
    ]
    main = [_row(s, "mean" if s.seed is None else str(s.seed)) for s in main_rows(bench)]
    lines += [table(["T", "seed", *_HEAD], main), ""]
    lines.append("by block count (mean over seeds):")
    blocks = [[*_row(s, str(s.blocks))[:-2], f"{s.windows:.2f}"] for s in block_rows(bench)]
    lines.append(table(["T", "blocks", *_HEAD[:-2], "win."], blocks))
    lines.append(
        "optimal: share of valid plans (on instances with a known optimum) that are optimal; "
        "known: instances with a known optimum"
    )
    if bench.speed is not None:
        sp = bench.speed
        ratio = "n/a" if sp.speedup is None else f"{sp.speedup:.1f}x"
        lines += [
            "",
            f"batched vs sequential on the first {sp.n} instances (T={sp.horizon}, seed "
            f"{sp.seed}): {sp.batched_s:.1f} s vs {sp.sequential_s:.1f} s, batched {ratio} "
            f"faster; valid {sp.batched_valid} vs {sp.sequential_valid}",
        ]
    return "\n".join(lines)


def motion_table(rows: dict[str, dict], inject: str) -> str:
    head = (
        f"{'sim':9} {'episodes':>8} {'plans valid':>11} {'goal':>9} {'moves ok':>13} "
        f"{'replans':>7} "
        f"{'disturbed':>9} {'wall/move':>9} {'sim/move':>8} {'x real':>6}"
    )
    lines = [head]
    for sim, s in rows.items():
        e = s["episodes"]
        lines.append(
            f"{sim:9} {e:>8} {s['plans_valid']:>7}/{e:<3} {s['goal_reached']:>4}/{e:<4} "
            f"{s['moves_ok']:>6}/{s['moves']:<6} {s['replans']:>7} {s['disturbed']:>9} "
            f"{s['wall_per_move_s']:>8.2f}s {s['sim_per_move_s']:>7.2f}s "
            f"{s['sim_per_move_s'] / max(s['wall_per_move_s'], 1e-9):>6.1f}"
        )
    lines.append("")
    for sim, s in rows.items():
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(s["failures"].items())) or "none"
        lines.append(f"{sim}: failures by kind: {kinds}; episode outcomes: {s['statuses']}")
        if inject != "none":
            lines.append(
                f"{sim}: faults ({inject}) hit {s['with_faults']} episodes, "
                f"{s['recovered']} of them still reached the goal"
            )
    return "\n".join(lines)


def perception_table(summaries: list[dict]) -> str:
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
