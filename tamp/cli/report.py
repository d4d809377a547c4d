"""Human-readable output of the CLI: block towers, plans and validation lines.

Pure string formatting; nothing here plans, validates or prints. Benchmark tables are
`tamp.bench.tables`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

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
