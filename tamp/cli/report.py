"""Human-readable output of the CLI: block towers, plans, validation lines and benchmark tables.

Pure string formatting; nothing here plans, validates or prints.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from tamp.bench.planning import Bench
from tamp.bench.summary import Summary, block_rows, main_rows
from task.problem import TABLE, Problem
from task.symbolic.validate import Validation


def towers(supports: Mapping[str, str]) -> list[list[str]]:
    """Towers bottom to top from ``block -> support``; a tower starts at a block on the table
    or at a block whose own support is not given (a partial goal leaves it free)."""
    above = {y: x for x, y in supports.items() if y != TABLE}
    named = set(supports) | set(above)
    bases = [x for x in named if supports.get(x, TABLE) == TABLE or supports[x] not in named]
    out = []
    for base in sorted(bases):
        tower = [base]
        while tower[-1] in above:
            tower.append(above[tower[-1]])
        out.append(tower)
    return out


def draw(stacks: Sequence[Sequence[str]]) -> list[str]:
    """ASCII picture of towers standing on a table line, top rows first."""
    width = max((len(b) for t in stacks for b in t), default=1)
    height = max((len(t) for t in stacks), default=0)
    lines = []
    for level in reversed(range(height)):
        cells = [t[level] if level < len(t) else "" for t in stacks]
        lines.append(" ".join(f"[{c}]" if c else " " * (width + 2) for c in cells))
    lines.append("=" * max(len(stacks) * (width + 3) - 1, 3))
    return lines


def side_by_side(left: list[str], right: list[str], gap: int = 6) -> list[str]:
    """Two pictures next to each other, bottoms aligned."""
    height = max(len(left), len(right))
    left = [""] * (height - len(left)) + left
    right = [""] * (height - len(right)) + right
    width = max(len(x) for x in left) + gap
    return [(a.ljust(width) + b).rstrip() for a, b in zip(left, right, strict=True)]


def problem_picture(problem: Problem) -> list[str]:
    """The initial towers and the goal towers (goal ``on`` atoms only), side by side."""
    init = draw(towers(dict(zip(problem.entities, problem.init, strict=True))))
    goal = draw(towers(dict(problem.goal)))
    head_width = max(len(x) for x in init) + 6
    return ["initial".ljust(head_width) + "goal", *side_by_side(init, goal)]


def validation_line(validation: Validation) -> str:
    """E.g. ``VALID: valid plan of 12 actions`` or ``INEXECUTABLE: step 3 (stack a b): ...``."""
    return f"{validation.status.name}: {validation.reason}"


def validation_dict(validation: Validation) -> dict:
    return {
        "valid": validation.valid,
        "status": validation.status.value,
        "step": validation.step,
        "reason": validation.reason,
        "failed": list(validation.failed),
        "length": validation.length,
    }


# ------------------------------------------------------------------------------------- tables


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


def bench_report(bench: Bench) -> str:
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
