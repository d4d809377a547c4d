"""The official benchmark sets and where their data lives: names and paths only, no planning.

PlanBench's three official sets (Blocksworld-600, Logistics-200, Sokoban-55; `OFFICIAL`) by
file name and ``manifest.csv`` column, and the default data folder (``../shared/data``, beside
the repository). Kept apart from `tamp.bench.suites`, which reads the sets with the planner's
PDDL machinery, so that the command-line parser can name the sets and defaults without
importing torch (``tamp --help`` stays fast).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

PLANBENCH_SOURCE = "github.com/karthikv792/LLMs-Planning, folder llm_planning_analysis/instances"
DEFAULT_DATA = Path("..") / "shared" / "data"
DEFAULT_PLANBENCH = DEFAULT_DATA / "planbench" / "blocksworld"


@dataclass(frozen=True)
class Official:
    """An official PlanBench set: its files by name and its ``manifest.csv`` columns."""

    domain: str
    names: tuple[str, ...]  # paths below instances/ without .pddl, in manifest order
    flag: str  # manifest column: 1 for the official rows
    size: str  # manifest column: the size the domain's `size` counts
    optimal: str | None  # manifest column of optimal lengths (blank: unknown)
    reference: str | None  # manifest column of reference lengths (not necessarily optimal)


# Blocksworld-600: PlanBench's zero-shot configs run blocksworld_3 instances 1..100 and
# blocksworld instances 1..500; Logistics-200: 1..200; Sokoban-55: 1..55 (README there).
OFFICIAL = {
    "blocksworld": Official(
        "blocksworld",
        tuple(
            f"{sub}/instance-{i}"
            for sub, n in (("generated_basic_3", 100), ("generated_basic", 500))
            for i in range(1, n + 1)
        ),
        "in_official_600",
        "n_blocks",
        "optimal_plan_length",
        None,
    ),
    "logistics": Official(
        "logistics",
        tuple(f"instance-{i}" for i in range(1, 201)),
        "in_official_200",
        "n_packages",
        None,
        "planbench_ground_truth_plan_length",
    ),
    "sokoban": Official(
        "sokoban",
        tuple(f"instance-{i}" for i in range(1, 56)),
        "in_official_55",
        "n_boxes",
        "optimal_plan_length_astar",
        None,
    ),
}


def default_data(domain: str) -> Path:  # where `planbench` looks by default
    return DEFAULT_DATA / "planbench" / domain
