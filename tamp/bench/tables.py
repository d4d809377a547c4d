"""The one table printer of every benchmark: the paper-style tables as text.

`table` pads columns to their widest cell (numbers right-aligned); `planning_report` prints a
planning benchmark (by horizon and seed, then by block count), `motion_table` the executability
table of the motion benchmark, `perception_table` the rows of planning from images,
`poses_table` the pose errors of the pose benchmark, `segmentation_table` and
`dark_margins_table` the segmentation check, `tamp_table` the TAMP benchmark. Pure string
formatting: nothing here runs a benchmark or prints.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from tamp.bench.peers.slaney import LABELS as BASELINE_LABELS
from tamp.bench.planning import Bench
from tamp.bench.summary import Summary, latency_rows, main_rows, size_rows

# the rows LatPlan-40 tables cite beside ours: (row, valid, optimal)
LATPLAN_CITED = (
    ("LatPlan AMA+4 (as the paper cites it)", "33/40", "-"),
    ("the paper", "40/40", "31/40"),
)


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
    """A count, a ratio, a percentage, or "-" (not applicable) in a numeric column."""
    return (
        text == "-"
        or text.replace(".", "", 1).replace("%", "").replace("/", "", 1).strip("-").isdigit()
    )


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
_SIZE_LABEL = {"blocks": "block count"}


def _ref(cells: list[str], s: Summary | None, refs: bool) -> list[str]:
    """``cells`` with the reference-plan columns after "known" when the data have references."""
    if not refs:
        return list(cells)
    if s is None:
        extra = ["<=ref", "<ref"]
    else:
        pct = "-" if s.at_most_ref_pct is None else f"{s.at_most_ref_pct:.1f}%"
        extra = [pct, count(s.shorter_than_ref)]
    return [*cells[:5], *extra, *cells[5:]]


def _part_settings(config, size_name: str) -> str:
    """The windows' own settings on the problems that take safe moves, for the report's head
    (`PlannerConfig.part_window`); empty when there are none."""
    if config.safe_from is None or not config.part_window:
        return ""
    settings = ", ".join(f"{k} {v}" for k, v in config.part_window)
    return f"; from {config.safe_from} {size_name}: {settings}"


def planning_report(bench: Bench) -> str:
    """The paper-style tables of a benchmark: by (horizon, seed), then by block count."""
    c = bench.config
    seeds = ",".join(str(s) for s in bench.seeds)
    lines = [
        f"{bench.suite}: {bench.n} instances ({bench.source})",
        f"seeds {seeds}; restarts {c.restarts}, iters {c.iters}, goal loss {c.goal_loss}, "
        f"lookahead {c.lookahead} x {c.lookahead_share:g} of restarts, "
        f"tau {c.tau:g}->{c.tau_end:g}, max windows {c.max_windows}"
        + _part_settings(c, bench.size_name)
        + ("" if c.crisp_check else "; NO crisp check (illegal moves kept, restarts by loss)"),
        "",
    ]
    refs = any(r.reference is not None for r in bench.rows())
    main = [
        _ref(_row(s, "mean" if s.seed is None else str(s.seed)), s, refs) for s in main_rows(bench)
    ]
    lines += [table(_ref(["T", "seed", *_HEAD], None, refs), main), ""]
    lines.append(f"by {_SIZE_LABEL.get(bench.size_name, bench.size_name)} (mean over seeds):")
    by_size = [
        _ref([*_row(s, str(s.size))[:-2], f"{s.windows:.2f}"], s, refs) for s in size_rows(bench)
    ]
    head = ["T", bench.size_name, *_HEAD[:-2], "win."]
    lines.append(table(_ref(head, None, refs), by_size))
    lines.append(
        "optimal: share of valid plans (on instances with a known optimum) that are optimal; "
        "known: instances with a known optimum"
    )
    if refs:
        lines.append(
            "<=ref: share of valid plans no longer than the data's reference plan (which need not "
            "be optimal); <ref: valid plans shorter than it"
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
        if sp.latency_s:
            q = sp.latency_s
            lines.append(
                f"one problem at a time, planning latency: p50 {q['p50']:.3f} s, "
                f"p90 {q['p90']:.3f} s, max {q['max']:.3f} s"
            )
    return "\n".join(lines)


def motion_table(rows: dict[str, dict], inject: str) -> str:
    """plans valid: the first task plan replayed by the validator ("-" with the camera, whose
    first plan is one window); exec. valid: the moves that executed ok, replayed."""
    head = [
        "sim",
        "episodes",
        "plans valid",
        "exec. valid",
        "goal",
        "moves ok",
        "replans",
        "disturbed",
        "unreadable",
        "wall/move",
        "sim/move",
        "x real",
    ]
    body = []
    for sim, s in rows.items():
        e = s["episodes"]
        valid = "-" if s["plans_valid"] is None else f"{s['plans_valid']}/{e}"
        body.append(
            [
                sim,
                e,
                valid,
                f"{s['executed_valid']}/{e}",
                f"{s['goal_reached']}/{e}",
                f"{s['moves_ok']}/{s['moves']}",
                s["replans"],
                s["disturbed"],
                s.get("unreadable", "-"),  # of the disturbed; "-": results from before it
                f"{s['wall_per_move_s']:.2f}s",
                f"{s['sim_per_move_s']:.2f}s",
                f"{s['sim_per_move_s'] / max(s['wall_per_move_s'], 1e-9):.1f}",
            ]
        )
    lines = [table(head, body, indent="")]
    lines.append("")
    for sim, s in rows.items():
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(s["failures"].items())) or "none"
        lines.append(f"{sim}: failures by kind: {kinds}; episode outcomes: {s['statuses']}")
        if "collided" in s:
            hit = ", ".join(f"{k} {v}" for k, v in sorted(s["touched"].items())) or "nothing"
            lines.append(
                f"{sim}: collisions in executed trajectories: {s['collided']} episodes "
                f"(touched: {hit}); collision checks {s['check_per_move_s']:.3f} s/move; "
                f"{s['rerouted']} moves rerouted by the motion planner"
                f"{_planner_failures(s)}, {s['path_per_move_s']:.3f} s/move"
            )
        if "arm_path_rad" in s:
            lines.append(
                f"{sim}: arm path {s['arm_path_rad']:.2f} rad per episode; task "
                f"planning {s['plan_per_episode_s']:.2f} s per episode"
            )
        if inject != "none":
            lines.append(
                f"{sim}: faults ({inject}) hit {s['with_faults']} episodes, "
                f"{s['recovered']} of them still reached the goal"
            )
    return "\n".join(lines)


def _planner_failures(s: dict) -> str:
    """The motion planner's runs that found no way, in a motion summary ("" in one from before
    they were counted)."""
    if "planner_failures" not in s:
        return ""
    return f", {s['planner_failures']} planner runs found no way"


def perception_table(summaries: list[dict]) -> str:
    """One row per (mode, crisp protocol, blur, horizon); a ``crisp`` column when rows differ in
    it. redrawn: images the row used that were re-rendered because a block was hidden."""
    crisp = len({s.get("crisp", "true") for s in summaries}) > 1
    head = [
        "mode",
        *(["crisp"] if crisp else []),
        "blur",
        "T",
        "valid",
        "optimal",
        "inexec.",
        "non-goal",
        "no plan",
        "redrawn",
        "s/inst",
        "notes",
    ]
    rows = []
    for s in summaries:
        pct = s.get("optimal_pct", 100.0 * s["optimal"] / max(s["valid"], 1))
        notes = []
        if s["goal_misread"]:
            notes.append(f"{s['goal_misread']} goal images misread")
        if s["perception_errors"]:
            notes.append(f"{s['perception_errors']} blocks not found")
        if s.get("misread_windows"):
            notes.append(f"{s['misread_windows']} windows decoded against a misread state")
        rows.append(
            [
                s["mode"],
                *([s.get("crisp", "true")] if crisp else []),
                s["blur"],
                s["horizon"],
                f"{s['valid']}/{s['n']}",
                "-" if pct is None else f"{pct:.1f}%",
                s.get("inexecutable", 0),
                s.get("non_goal_reaching", 0),
                s.get("no_plan", 0),
                s.get("redrawn", 0),
                f"{s['time_s_per_instance']:.3f}",
                "; ".join(notes),
            ]
        )
    return table(head, rows, indent="")


def poses_table(summary: dict[str, dict]) -> str:
    """The pose benchmark: per simulator and split (all, top face free, covered), the blocks
    estimated, position error (mm) and yaw error (degrees, modulo 90)."""
    head = [
        "sim",
        "blocks",
        "estimated",
        "pos mean",
        "median",
        "p95",
        "max mm",
        "yaw mean",
        "median",
        "p95",
        "max deg",
    ]
    rows = []
    for sim, by_split in summary.items():
        for split in ("all", "top", "covered"):
            s = by_split[split]
            pos, yaw = s["position_mm"], s["yaw_deg"]
            cells = [
                f"{v[k]:.2f}" if v is not None else "-"
                for v in (pos, yaw)
                for k in ("mean", "median", "p95", "max")
            ]
            name = sim if split == "all" else ""
            label = {"all": "all", "top": "top free", "covered": "covered"}[split]
            rows.append([name, label, f"{s['estimated']}/{s['blocks']}", *cells])
    return table(head, rows, indent="")


def executability_table(summary: Sequence[dict], sims: Sequence[str]) -> str:
    """One row per source: our and PlanBench's task-level verdicts, then per simulator the
    goals reached (ground truth), disturbed stacks, s/plan and the top 3 first failures."""
    head = [
        "source",
        "plans",
        "task-valid",
        "PlanBench-valid",
        "agree",
        *(f"{h} {s}" for s in sims for h in ("goal", "disturbed", "s/plan")),
    ]
    body, lines = [], ["", "", "first failures (top 3):"]
    for s in summary:
        n = s["plans"]
        flags = ("-" if v is None else f"{v}/{n}" for v in (s["planbench_valid"], s["agree"]))
        body.append(
            [
                s["source"],
                n,
                f"{s['task_valid']}/{n}",
                *flags,
                *(
                    v
                    for sim in sims
                    for v in (
                        f"{s['reached'][sim]}/{n}",
                        s["disturbed"][sim],
                        f"{s['s_per_plan'][sim]:.1f}",
                    )
                ),
            ]
        )
        for sim in sims:
            kinds = ", ".join(f"{k} {v}" for k, v in s["failures"][sim].items())
            lines.append(f"  {s['source']} in {sim}: {kinds or 'none'}")
    return table(head, body, indent="") + "\n".join(lines)


def latplan_table(summary: Sequence[dict]) -> str:
    """The issue's table: the cited rows, then ours per mode and resolution (mean over seeds,
    min-max in brackets when seeds differ)."""
    head = ["row", "valid", "optimal", "read right", "s/inst", "failures (all seeds)"]
    body = [[name, valid, optimal, "-", "-", ""] for name, valid, optimal in LATPLAN_CITED]
    for s in summary:
        what = (
            "ours, from the true states"
            if s["mode"] == "state"
            else f"ours, {s['mode']} perception, {s['resolution']}"
        )
        read = "-" if s["read_right"] is None else _count(s["read_right"], s["n"])
        fails = ", ".join(
            f"{v} {k.replace('_', ' ')}" for k, v in sorted(s["statuses"].items()) if k != "valid"
        )
        body.append(
            [
                what,
                _count(s["valid"], s["n"]),
                _count(s["optimal"], s["n"]),
                read,
                f"{s['time_s_per_instance']:.2f}",
                fails,
            ]
        )
    return table(head, body, indent="")


def _count(s: dict, n: int) -> str:
    mean = f"{s['mean']:.1f}".removesuffix(".0")
    spread_ = "" if s["min"] == s["max"] else f" ({s['min']}-{s['max']})"
    return f"{mean}/{n}{spread_}"


def lengths_table(bench: Bench) -> str:
    """Plan lengths by size, mean over seeds: ours (valid plans) and, where ``--lama`` ran,
    LAMA's first plan beside them. Lengths in moves (4-op actions / 2; blocksworld only)."""
    lama = any(s.lama is not None for s in size_rows(bench))
    baselines = [
        b for b in ("us", "gn1") if any(getattr(s, b) is not None for s in size_rows(bench))
    ]
    head = ["T", bench.size_name, "valid", "moves", "x opt", "s/inst"]
    head += ["LAMA solved", "LAMA moves", "LAMA x opt", "LAMA s", "ours/LAMA"] if lama else []
    for b in baselines:
        label = BASELINE_LABELS[b]
        head += [f"{label} moves", f"{label} x opt", f"{label} s", f"ours/{label}"]
    beside = lama or bool(baselines)
    head += ["at best", "x best"] if beside else []
    body = []
    for s in size_rows(bench):
        row = [
            str(s.horizon),
            str(s.size),
            f"{count(s.valid)}/{s.n}",
            _num(s.length, 0.5),
            _num(s.ratio),
            f"{s.time_s:.2f}",
        ]
        if lama:
            row += [
                f"{count(s.lama or 0)}/{s.n}",
                _num(s.lama_length, 0.5),
                _num(s.lama_ratio),
                _num(s.lama_s),
                _num(s.vs_lama),
            ]
        for b in baselines:
            row += [
                _num(getattr(s, f"{b}_length"), 0.5),
                _num(getattr(s, f"{b}_ratio")),
                _seconds(getattr(s, f"{b}_s")),
                _num(getattr(s, f"vs_{b}")),
            ]
        if beside:
            row += [f"{count(s.best)}/{count(s.valid)}" if s.best is not None else "-"]
            row += [_num(s.vs_best)]
        body.append(row)
    note = "moves: mean over plans found; x opt: mean length / optimum where the optimum is known"
    note += "; ours/LAMA: mean length ratio where both found a plan" if lama else ""
    if baselines:
        note += "; US, GN1: Slaney & Thiebaux's near-optimal Blocksworld algorithms (validated)"
    if beside:
        note += (
            "; at best: our valid plans as short as the shortest known (optimum, ours, the "
            "peers'); x best: mean our length / that shortest"
        )
    latency = latency_rows(bench)
    if latency:
        rows = [
            [str(r["horizon"]), str(r["size"]), str(r["n"])]
            + [f"{r[q]:.3f}" for q in ("p50", "p90", "max")]
            for r in latency
        ]
        note += f"\n\nplanning latency by {bench.size_name}, one problem at a time (s):\n"
        note += table(["T", bench.size_name, "plans", "p50", "p90", "max"], rows)
    return table(head, body) + "\n" + note


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.4f}"


def _num(value: float | None, scale: float = 1.0) -> str:
    return "-" if value is None else f"{value * scale:.2f}"


def segmentation_table(files: Mapping[str, dict]) -> str:
    """The segmentation check: per dataset file, the blocks of each palette colour found out of
    those shown, under the current thresholds and unguarded; with the current ones, the images
    in which every block was found and the scenes (and relations) the model read right. Below
    it, each palette colour as RGB 0-255."""
    names = list(dict.fromkeys(name for f in files.values() for name in f["blocks_shown"]))
    head = ["file", "thresholds", "images", *names, "all found", "scenes right", "relations"]
    body = []
    for path, f in files.items():
        for label in ("current", "unguarded"):
            found = [
                f"{f['blocks_found'][label][n]}/{f['blocks_shown'][n]}"
                if n in f["blocks_shown"]
                else "-"
                for n in names
            ]
            read = label == "current" and f["scenes_read"] > 0
            body.append(
                [
                    path if label == "current" else "",
                    label,
                    str(f["images"]),
                    *found,
                    str(f["images_with_every_block_found"]) if label == "current" else "-",
                    f"{f['scenes_right']}/{f['scenes_read']}" if read else "-",
                    f"{f['relation_accuracy']:.1%}" if read else "-",
                ]
            )
    palettes = {
        ", ".join(f"#{k} {tuple(round(255 * c) for c in rgb)}" for k, rgb in enumerate(p))
        for p in (tuple(map(tuple, f["palette"])) for f in files.values())
    }
    return table(head, body, indent="") + "".join(f"\ncolours: {p}" for p in sorted(palettes))


def dark_margins_table(files: Mapping[str, dict]) -> str:
    """The dark class's margins per file and measure: the threshold, then the worst, the 5%
    tail on the threshold's side and the median of the per-image medians."""
    head = ["file", "images", "measure", "threshold", "worst", "5% tail", "median"]
    body = []
    for path, f in files.items():
        margins = f.get("dark_margins")
        if margins is None:
            continue
        measures = [(k, v) for k, v in margins.items() if k != "images"]
        for k, (measure, s) in enumerate(measures):
            tail = s["p95"] if "p95" in s else s["p5"]
            body.append(
                [
                    path if k == 0 else "",
                    str(margins["images"]),
                    measure,
                    *(
                        _margin(v, "ratio" in measure)
                        for v in (s["threshold"], s["worst"], tail, s["median"])
                    ),
                ]
            )
    return table(head, body, indent="")


def _margin(value: float, ratio: bool) -> str:
    """A ratio with two decimals; a grey level with one, dropped when it is 0 (25, 27.5)."""
    return f"{value:.2f}" if ratio else f"{value:.1f}".removesuffix(".0")


def tamp_table(summary: Sequence[dict], sims: Sequence[str]) -> str:
    """``bench tamp``: one row per problem and planner; per simulator the goals reached (ground
    truth), those reached without a motion failure, the first plan's median length, planning
    time p50/p90 (s), median simulated execution (s) and arm path (rad) of solved episodes,
    and the episodes in which the arm touched something it should not have."""
    head = [
        "problem",
        "planner",
        *(
            f"{h} {s}"
            for s in sims
            for h in ("solved", "clean", "len", "plan p50/p90 s", "exec s", "path rad", "collided")
        ),
    ]
    by = {(s["problem"], s["planner"], s["sim"]): s for s in summary}
    keys = list(dict.fromkeys((s["problem"], s["planner"]) for s in summary))
    body = []
    for problem, planner in keys:
        cells: list[object] = [problem, planner]
        for sim in sims:
            s = by.get((problem, planner, sim))
            if s is None:
                cells += ["-"] * 7
                continue
            n = s["episodes"]
            cells += [
                f"{s['solved']}/{n}",
                f"{s['clean']}/{n}",
                _num(s["plan_length"]),
                f"{_num(s['planning_p50_s'])}/{_num(s['planning_p90_s'])}",
                _num(s["execution_s"]),
                _num(s["arm_path_rad"]),
                f"{s['collided']}/{n}",
            ]
        body.append(cells)
    return table(head, body, indent="")
