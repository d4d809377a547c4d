"""Benchmark instances: a relational problem, its parsed PDDL (for validation), its optimum.

Three sources: PDDL files (``from_files``), the embedded example (``example``), the official
PlanBench Blocksworld-600 read through its ``manifest.csv`` (``planbench``), and seeded random
problems whose optimal lengths come from A* with a node budget (``generated``). Every instance
keeps the parsed PDDL problem so plans are checked by `task.validate` against the PDDL itself,
independently of the planner's crisp replay.
"""

from __future__ import annotations

import csv
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from pddl.core import Domain
from pddl.core import Problem as PDDLProblem

from task import data, pddl_io
from task.domains import blocksworld
from task.errors import DataError, PDDLError
from task.generate import random_problem
from task.problem import Problem
from task.search import optimal_moves

PLANBENCH_SOURCE = (
    "github.com/karthikv792/LLMs-Planning, folder llm_planning_analysis/instances/blocksworld"
)
DEFAULT_PLANBENCH = Path("..") / "shared" / "data" / "planbench" / "blocksworld"
_COLUMNS = ("file", "in_official_600", "n_blocks", "optimal_plan_length")


@dataclass(frozen=True)
class Instance:
    """One benchmark problem. ``optimal`` is the optimal 4-op plan length (None: unknown)."""

    name: str
    problem: Problem
    pddl: PDDLProblem
    optimal: int | None = None

    @property
    def blocks(self) -> int:
        return self.problem.n


@dataclass(frozen=True)
class Suite:
    """Instances that all validate against one PDDL ``domain``; ``source`` says where from."""

    name: str
    domain: Domain
    instances: tuple[Instance, ...]
    source: str


def from_text(
    domain: Domain, text: str, source: str, name: str | None = None, optimal: int | None = None
) -> Instance:
    """Parse blocksworld problem text; errors name ``source``."""
    parsed = pddl_io.parse_problem(text, source, domain)
    try:
        problem = blocksworld.from_pddl(domain, parsed, pddl_io.object_order(text))
    except PDDLError as exc:
        raise PDDLError(f"{source}: {exc}") from None
    return Instance(name or problem.name, problem, parsed, optimal)


def from_files(domain_path: str | Path, problem_path: str | Path) -> tuple[Domain, Instance]:
    """Load a domain file and a problem file."""
    domain = pddl_io.load_domain(domain_path)
    return domain, from_text(domain, pddl_io.read_text(problem_path), str(problem_path))


def example() -> tuple[Domain, Instance]:
    """The embedded 5-block example (`task.data`) and its domain."""
    text = data.read_text(data.EXAMPLE_FILE)
    return data.domain(), from_text(data.domain(), text, data.source(data.EXAMPLE_FILE))


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
    source = f"task.generate.random_problem, seed {seed}, A* budget {max_nodes} nodes"
    return Suite("random", domain, tuple(instances), source)
