"""Benchmark suites: the official PlanBench Blocksworld-600 and seeded random problems.

PlanBench is read through its ``manifest.csv``; seeded random problems get their optimal
lengths from A* with a node budget (``generated``). A `Suite` is a tuple of
`task.symbolic.instances.Instance` that all validate against one PDDL domain.
"""

from __future__ import annotations

import csv
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain

from task import data
from task.domains import blocksworld
from task.errors import DataError
from task.symbolic import pddl_io
from task.symbolic.generate import random_problem
from task.symbolic.instances import Instance, from_text
from task.symbolic.search import optimal_moves

PLANBENCH_SOURCE = (
    "github.com/karthikv792/LLMs-Planning, folder llm_planning_analysis/instances/blocksworld"
)
DEFAULT_PLANBENCH = Path("..") / "shared" / "data" / "planbench" / "blocksworld"
_COLUMNS = ("file", "in_official_600", "n_blocks", "optimal_plan_length")


@dataclass(frozen=True)
class Suite:
    """Instances that all validate against one PDDL ``domain``; ``source`` says where from."""

    name: str
    domain: Domain
    instances: tuple[Instance, ...]
    source: str


def spread(items: Sequence, limit: int | None, key: Callable) -> list:
    """``limit`` items spread evenly over ``items`` stably sorted by ``key`` (all if None).

    Item ``i`` of the result is the middle of the ``i``-th of ``limit`` equal slices, so every
    block count gets its share: ``--limit 6`` of PlanBench gives one 3-, four 4- and one 5-block.
    """
    ordered = sorted(items, key=key)
    if limit is None or limit >= len(ordered):
        return ordered
    return [ordered[(2 * i + 1) * len(ordered) // (2 * limit)] for i in range(limit)]


def _missing(root: Path) -> DataError:
    return DataError(
        f"PlanBench data not found at {root.resolve()} (needs domain.pddl, manifest.csv and "
        f"instances/); get it from {PLANBENCH_SOURCE}, laid out as {DEFAULT_PLANBENCH} with its "
        "manifest, and pass --data DIR"
    )


def _manifest(root: Path) -> list[tuple[str, int, int]]:
    """``(file, n_blocks, optimal length)`` of the official rows of ``manifest.csv``."""
    path = root / "manifest.csv"
    with path.open(newline="", encoding="utf-8") as handle:
        reader = csv.DictReader(handle)
        missing = [c for c in _COLUMNS if c not in (reader.fieldnames or ())]
        if missing:
            raise DataError(f"{path}: missing column(s) {', '.join(missing)}")
        rows = []
        for line, row in enumerate(reader, start=2):
            if row["in_official_600"].strip() != "1":
                continue
            try:
                rows.append((row["file"], int(row["n_blocks"]), int(row["optimal_plan_length"])))
            except ValueError:
                raise DataError(
                    f"{path}: line {line}: n_blocks/optimal_plan_length not integers"
                ) from None
    if not rows:
        raise DataError(f"{path}: no rows with in_official_600 = 1")
    return rows


def planbench(data_dir: str | Path, limit: int | None = None) -> Suite:
    """The official PlanBench Blocksworld-600 (or a ``limit``-instance `spread` of it)."""
    root = Path(data_dir)
    if not all(
        p.exists() for p in (root / "domain.pddl", root / "manifest.csv", root / "instances")
    ):
        raise _missing(root)
    rows = _manifest(root)
    domain = pddl_io.load_domain(root / "domain.pddl")
    chosen = spread(range(len(rows)), limit, key=lambda i: rows[i][1])
    instances = []
    for i in chosen:
        file, blocks, optimal = rows[i]
        path = root / file
        name = file.removeprefix("instances/").removesuffix(".pddl")
        instance = from_text(domain, pddl_io.read_text(path), str(path), name, optimal)
        if instance.blocks != blocks:
            raise DataError(f"{path}: {instance.blocks} blocks, manifest.csv says {blocks}")
        instances.append(instance)
    return Suite("planbench", domain, tuple(instances), str(root.resolve()))


def generated(
    blocks: Sequence[int],
    n: int,
    seed: int,
    max_nodes: int = 20_000,
    progress: Callable[[int], None] | None = None,
) -> Suite:
    """``n`` random problems per block count; optimal lengths from A* within ``max_nodes``.

    Instance ``i`` of ``b`` blocks uses the ``i``-th seed drawn from ``Random(f"{seed}:{b}")``,
    so adding a block count leaves the others unchanged. Each problem goes through its PDDL
    text (`blocksworld.to_pddl`), so validation sees exactly what a PDDL file would hold.
    """
    report = progress or (lambda k: None)
    domain = data.domain()
    instances = []
    for b in blocks:
        seeds = random.Random(f"{seed}:{b}")
        for i in range(1, n + 1):
            problem = random_problem(b, seeds.randrange(2**31))
            moves = optimal_moves(problem, max_nodes)
            name = f"random-{b}/instance-{i}"
            text = blocksworld.to_pddl(problem)
            optimal = None if moves is None else 2 * len(moves)
            instances.append(from_text(domain, text, name, name, optimal))
            report(1)
    source = f"task.symbolic.generate.random_problem, seed {seed}, A* budget {max_nodes} nodes"
    return Suite("random", domain, tuple(instances), source)
