"""Benchmark suites: the official PlanBench Blocksworld-600 and seeded random problems.

PlanBench is read through its ``manifest.csv`` where there is one, else the official files are
picked by name and their optima searched (`tamp.bench.optimal`); seeded random problems get
their optimal lengths from A* with a node budget (``generated``). A `Suite` is a tuple of
`task.symbolic.instances.Instance` that all validate against one PDDL domain.
"""

from __future__ import annotations

import csv
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from pddl.core import Domain

from tamp.bench.optimal import digest, optimal_lengths
from task import data
from task.domains import blocksworld
from task.errors import DataError, PDDLError
from task.symbolic import pddl_io
from task.symbolic.generate import random_problem
from task.symbolic.instances import Instance, from_text
from task.symbolic.search import optimal_moves

PLANBENCH_SOURCE = (
    "github.com/karthikv792/LLMs-Planning, folder llm_planning_analysis/instances/blocksworld"
)
DEFAULT_PLANBENCH = Path("..") / "shared" / "data" / "planbench" / "blocksworld"
_COLUMNS = ("file", "in_official_600", "n_blocks", "optimal_plan_length")
_DOMAIN_FILES = ("domain.pddl", "generated_domain.pddl")  # ours, PlanBench's own name
# The official 600 as (subfolder, last instance number), in manifest.csv order: PlanBench's
# zero-shot configs run blocksworld_3 instances 1..100 and blocksworld instances 1..500.
OFFICIAL_600 = (("generated_basic_3", 100), ("generated_basic", 500))


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
        f"PlanBench data not found at {root.resolve()} (needs domain.pddl and "
        f"instances/generated_basic{{,_3}}/instance-N.pddl); get it from {PLANBENCH_SOURCE}, "
        f"laid out as {DEFAULT_PLANBENCH}, and pass --data DIR"
    )


def _signature(domain: Domain) -> tuple[frozenset, frozenset]:
    """Action and predicate names with their arities, lowercased."""
    actions = frozenset((str(a.name).lower(), len(a.parameters)) for a in domain.actions)
    predicates = frozenset((str(p.name).lower(), p.arity) for p in domain.predicates)
    return actions, predicates


def _blocksworld_domain(root: Path) -> Domain:
    """The domain file of ``root``, which must be the 4-op blocksworld domain."""
    path = next((root / n for n in _DOMAIN_FILES if (root / n).is_file()), None)
    if path is None:
        raise _missing(root)
    domain = pddl_io.load_domain(path)
    expected = data.domain()
    if _signature(domain) != _signature(expected):
        actions = ", ".join(sorted(str(a.name).lower() for a in domain.actions))
        wanted = ", ".join(sorted(str(a.name) for a in expected.actions))
        raise DataError(
            f"{root}: {path.name} is domain {str(domain.name)!r} (actions {actions}), "
            f"not the blocksworld 4-op domain {str(expected.name)!r} (actions {wanted})"
        )
    return domain


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


def official_600() -> tuple[str, ...]:
    """Names of the official 600 in ``manifest.csv`` order: 3-block set first, each by number."""
    return tuple(f"{sub}/instance-{i}" for sub, n in OFFICIAL_600 for i in range(1, n + 1))


def _load(
    domain: Domain, path: Path, name: str, optimal: int | None = None
) -> tuple[Instance, str]:
    """``(instance, text)`` of one file; a problem of another domain is a `DataError`."""
    try:
        text = pddl_io.read_text(path)
        return from_text(domain, text, str(path), name, optimal), text
    except PDDLError as exc:
        raise DataError(str(exc)) from None


def _with_manifest(
    root: Path, domain: Domain, rows: list[tuple[str, int, int]], limit: int | None
) -> list[Instance]:
    """The official ``rows`` of ``manifest.csv``, their block counts checked against the files."""
    instances = []
    for file, blocks, optimal in spread(rows, limit, key=lambda row: row[1]):
        path = root / file
        name = file.removeprefix("instances/").removesuffix(".pddl")
        instance, _ = _load(domain, path, name, optimal)
        if instance.blocks != blocks:
            raise DataError(f"{path}: {instance.blocks} blocks, manifest.csv says {blocks}")
        instances.append(instance)
    return instances


def _without_manifest(
    root: Path, domain: Domain, limit: int | None, cache_dir: str | Path | None
) -> list[Instance]:
    """The official files present, optima from `tamp.bench.optimal` (cached in ``cache_dir``)."""
    folder = root / "instances" if (root / "instances").is_dir() else root
    paths = [(name, folder / f"{name}.pddl") for name in official_600()]
    found = [_load(domain, path, name) for name, path in paths if path.is_file()]
    if not found:
        raise DataError(
            f"{root}: no PlanBench Blocksworld instances (expected "
            "instances/generated_basic/instance-1..500.pddl and "
            "instances/generated_basic_3/instance-1..100.pddl)"
        )
    chosen = spread(found, limit, key=lambda item: item[0].blocks)
    keys = [(i.name, digest(text), i.problem) for i, text in chosen]
    lengths = optimal_lengths(keys, cache_dir)
    return [replace(i, optimal=length) for (i, _), length in zip(chosen, lengths, strict=True)]


def planbench(
    data_dir: str | Path, limit: int | None = None, cache_dir: str | Path | None = None
) -> Suite:
    """The official PlanBench Blocksworld-600 (or a ``limit``-instance `spread` of it).

    With a ``manifest.csv`` in ``data_dir``, its official rows and optimal lengths are used.
    Without one, the official files are known by name (`OFFICIAL_600`; others are left out)
    and their optima are searched, cached in ``cache_dir`` when given (see `tamp.bench.optimal`).
    Both ways give the same instances in the same order. ``data_dir`` may also be PlanBench's
    own folder (``generated_domain.pddl``, ``generated_basic*/`` without ``instances/``).
    """
    root = Path(data_dir)
    if not root.is_dir():
        raise _missing(root)
    domain = _blocksworld_domain(root)  # first: another benchmark's folder has a manifest too
    if (root / "manifest.csv").is_file():
        instances = _with_manifest(root, domain, _manifest(root), limit)
    else:
        instances = _without_manifest(root, domain, limit, cache_dir)
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
