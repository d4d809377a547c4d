"""Benchmark suites: PlanBench's official sets, any folder of PDDL problems, random problems.

PlanBench (Blocksworld-600, Logistics-200, Sokoban-55; `OFFICIAL`) is read through its
``manifest.csv`` where there is one, else the official files are picked by name. Lengths the
data lack come from A* for Blocksworld (`tamp.bench.optimal`), else Fast Downward when the
benchmark extra is installed (`tamp.bench.fast_downward`), cached in the output folder.
`pddl_folder` reads a domain and its problems (the IPC sets); ``generated`` makes seeded random
Blocksworld problems. A `Suite`'s instances all validate against one PDDL domain."""

from __future__ import annotations

import csv
import random
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from pddl.core import Domain

from tamp.bench.official import (  # noqa: F401  (re-exported: the sets and their data)
    DEFAULT_DATA,
    DEFAULT_PLANBENCH,
    OFFICIAL,
    PLANBENCH_SOURCE,
    Official,
    default_data,
)
from tamp.bench.optimal import digest, optimal_lengths
from task import data
from task.domains import blocksworld
from task.errors import DataError, PDDLError, ProblemError, one_of
from task.instances import Instance, from_text, rules_for
from task.symbolic import pddl_io
from task.symbolic.generate import random_problem
from task.symbolic.search import optimal_moves

_DOMAIN_FILES = ("domain.pddl", "generated_domain.pddl")  # ours, PlanBench's own name
FD_CACHE, FD_LIMIT_S, FD_WORKERS = "fd_optima.json", 120.0, 2  # Fast Downward optima


@dataclass(frozen=True)
class Suite:
    """Instances that all validate against one PDDL ``domain``; ``source`` says where from."""

    name: str
    domain: Domain
    instances: tuple[Instance, ...]
    source: str


def spread(items: Sequence, limit: int | None, key: Callable) -> list:
    """``limit`` items spread evenly over ``items`` stably sorted by ``key`` (all if None):
    item ``i`` is the middle of the ``i``-th of ``limit`` equal slices, so every size gets its
    share (``--limit 6`` of Blocksworld-600 gives one 3-, four 4- and one 5-block)."""
    ordered = sorted(items, key=key)
    if limit is None or limit >= len(ordered):
        return ordered
    return [ordered[(2 * i + 1) * len(ordered) // (2 * limit)] for i in range(limit)]


def _missing(root: Path, domain: str) -> DataError:
    return DataError(
        f"PlanBench {domain} data not found at {root.resolve()} (needs domain.pddl and "
        f"instances/*.pddl); get it from {PLANBENCH_SOURCE}/{domain}, laid out as "
        f"{default_data(domain)}, and pass --data DIR"
    )


def _domain(root: Path, rules: str | None) -> tuple[Domain, Path]:
    """The domain file of ``root`` (None if absent); with ``rules``, it must be that domain."""
    path = next((root / n for n in _DOMAIN_FILES if (root / n).is_file()), None)
    if path is None:
        raise DataError(f"{root}: no domain.pddl")
    domain = pddl_io.load_domain(path)
    try:
        rules_for(domain, rules)
    except PDDLError as exc:
        raise DataError(f"{root}: {path.name}: {exc}") from None
    return domain, path


def _int(text: str | None, path: Path, line: int, column: str) -> int | None:
    if text is None or not text.strip():
        return None
    try:
        return int(text)
    except ValueError:
        raise DataError(f"{path}: line {line}: {column} {text!r} is not an integer") from None


def _manifest(root: Path, spec: Official) -> list[tuple[str, int, int | None, int | None]]:
    """``(file, size, optimal, reference)`` of the official rows of ``manifest.csv``."""
    path = root / "manifest.csv"
    lengths = [c for c in (spec.optimal, spec.reference) if c]
    with path.open(newline="", encoding="utf-8") as handle:
        reader = csv.DictReader(handle)
        missing = [
            c
            for c in ("file", spec.flag, spec.size, *lengths)
            if c not in (reader.fieldnames or ())
        ]
        if missing:
            raise DataError(f"{path}: missing column(s) {', '.join(missing)}")
        rows = []
        for line, row in enumerate(reader, start=2):
            if row[spec.flag].strip() == "1":
                size = _int(row[spec.size], path, line, spec.size)
                if size is None:
                    raise DataError(f"{path}: line {line}: {spec.size} is blank")
                opt, ref = (
                    _int(row[c], path, line, c) if c else None
                    for c in (spec.optimal, spec.reference)
                )
                rows.append((row["file"], size, opt, ref))
    if not rows:
        raise DataError(f"{path}: no rows with {spec.flag} = 1")
    return rows


def _load(domain: Domain, path: Path, name: str, rules: str) -> tuple[Instance, str, Path]:
    """``(instance, text, path)`` of one file; a problem of another domain is a `DataError`."""
    try:
        text = pddl_io.read_text(path)
        return from_text(domain, text, str(path), name, rules=rules), text, path
    except (PDDLError, ProblemError) as exc:
        raise DataError(str(exc)) from None


def _fill_optima(
    found: list[tuple[Instance, str, Path]],
    domain_path: Path,
    cache_dir: str | Path | None,
    progress: Callable[[int], None] | None = None,
) -> list[Instance]:
    """Optima for the instances whose data give none (a reference plan's length is kept beside
    it): A* for Blocksworld problems, else Fast Downward (`FD_LIMIT_S` each) when the benchmark
    extra is installed (None when it is not, or when it runs out of time). Cached in
    ``cache_dir`` (``optimal_lengths.json``, ``fd_optima.json``)."""
    out = [i for i, _, _ in found]
    lacking = [k for k, i in enumerate(out) if i.optimal is None]
    if not lacking:
        return out
    from tamp.bench import fast_downward  # benchmark-only extra, imported when needed

    if out[0].problem.domain == blocksworld.NAME:
        keys = [(out[k].name, digest(found[k][1]), out[k].problem) for k in lacking]
        lengths = optimal_lengths(keys, cache_dir)
    elif fast_downward.available():
        cache = None if cache_dir is None else Path(cache_dir) / FD_CACHE
        pairs = [(domain_path, found[k][2]) for k in lacking]
        results = fast_downward.optimal_lengths(pairs, cache, FD_LIMIT_S, progress, FD_WORKERS)
        lengths = [r.length if r.status == "optimal" else None for r in results]
    else:
        return out
    for k, length in zip(lacking, lengths, strict=True):
        out[k] = replace(out[k], optimal=length)
    return out


def planbench(
    data_dir: str | Path,
    limit: int | None = None,
    cache_dir: str | Path | None = None,
    domain: str = "blocksworld",
    progress: Callable[[int], None] | None = None,
    rules: str | None = None,
    names: Sequence[str] | None = None,
) -> Suite:
    """The official PlanBench set of ``domain`` (or a ``limit``-instance `spread` of it;
    ``names``: of these instances only, e.g. ``generated_basic_3/instance-1``; DataError naming
    those not in the set). ``limit`` beyond the instances there are: `DataError`.

    With a ``manifest.csv`` in ``data_dir``, its official rows and lengths are used (sizes are
    checked against the files); without one the official files are known by name (others are
    left out). Lengths the data lack are searched (`_fill_optima`), cached in ``cache_dir``;
    ``progress(k)``: k more searched. ``rules`` plans the set with other domain rules
    (``strips``: the generic lift).
    ``data_dir`` may also be PlanBench's own folder (``generated_domain.pddl``, instance
    folders without ``instances/``). Both ways give the same instances in the same order.
    """
    if domain not in OFFICIAL:
        raise ProblemError(f"--domain: no PlanBench set for {one_of(domain, OFFICIAL)}")
    spec, root = OFFICIAL[domain], Path(data_dir)
    if not root.is_dir() or not any((root / n).is_file() for n in _DOMAIN_FILES):
        raise _missing(root, domain)
    pddl_domain, domain_path = _domain(root, domain)
    folder = root / "instances" if (root / "instances").is_dir() else root
    if (root / "manifest.csv").is_file():
        rows = _only(_manifest(root, spec), names, lambda row: _name(row[0]), root)
        rows = spread(_at_most(rows, limit, root), limit, key=lambda row: row[1])
        found = []
        for file, size, opt, ref in rows:
            instance, text, _ = _load(pddl_domain, root / file, _name(file), rules or domain)
            if rules in (None, domain) and instance.size != size:
                raise DataError(f"{root / file}: size {instance.size}, manifest.csv says {size}")
            found.append((replace(instance, optimal=opt, reference=ref), text, root / file))
    else:
        there = [n for n in spec.names if (folder / f"{n}.pddl").is_file()]
        there = _only(there, names, lambda n: n, root)
        found = [_load(pddl_domain, folder / f"{n}.pddl", n, rules or domain) for n in there]
        if not found:
            first, last = spec.names[0], spec.names[-1]
            raise DataError(
                f"{root}: no official PlanBench {domain} instances (expected "
                f"instances/{first}.pddl ... {last}.pddl)"
            )
        found = spread(_at_most(found, limit, root), limit, key=lambda item: item[0].size)
    instances = _fill_optima(found, domain_path, cache_dir, progress)
    name = "planbench" if domain == "blocksworld" else f"planbench-{domain}"
    name += f" ({rules} rules)" if rules not in (None, domain) else ""
    return Suite(name, pddl_domain, tuple(instances), str(root.resolve()))


def _name(file: str) -> str:
    """``instances/generated_basic_3/instance-1.pddl`` -> ``generated_basic_3/instance-1``."""
    return file.removeprefix("instances/").removesuffix(".pddl")


def _only(items: list, names: Sequence[str] | None, name: Callable, root: Path) -> list:
    """``items`` whose ``name(item)`` is one of ``names`` (all when None), in data order."""
    if names is None:
        return items
    have = {name(item) for item in items}
    unknown = [n for n in dict.fromkeys(names) if n not in have]
    if unknown:
        more = f" and {len(unknown) - 3} more" if len(unknown) > 3 else ""
        raise DataError(
            f"{root}: no instance {', '.join(unknown[:3])}{more} in this PlanBench set "
            "(names like generated_basic_3/instance-1)"
        )
    wanted = set(names)
    return [item for item in items if name(item) in wanted]


def _at_most(items: list, limit: int | None, root: Path) -> list:
    """``items``, or `DataError` when ``limit`` asks for more than there are."""
    if limit is not None and limit > len(items):
        raise DataError(f"asked for {limit} instances, but {root} has {len(items)}")
    return items


def _natural(path: Path) -> tuple:
    return tuple(int(t) if t.isdigit() else t for t in re.split(r"(\d+)", path.name))


def pddl_folder(
    data_dir: str | Path,
    limit: int | None = None,
    cache_dir: str | Path | None = None,
    rules: str | None = None,
    progress: Callable[[int], None] | None = None,
) -> Suite:
    """Every problem file of a folder holding ``domain.pddl`` and problems (``*.pddl``),
    natural order; planned with the recognised domain rules or ``rules``."""
    root = Path(data_dir)
    if not root.is_dir():
        raise DataError(f"{root}: no such folder (needs domain.pddl and problem files)")
    pddl_domain, domain_path = _domain(root, rules)
    chosen = rules_for(pddl_domain, rules)
    paths = sorted((p for p in root.glob("*.pddl") if p.name not in _DOMAIN_FILES), key=_natural)
    if not paths:
        raise DataError(f"{root}: no problem files (*.pddl besides {domain_path.name})")
    found = [_load(pddl_domain, p, p.stem, chosen) for p in paths]
    found = spread(_at_most(found, limit, root), limit, key=lambda item: item[0].size)
    instances = _fill_optima(found, domain_path, cache_dir, progress)
    return Suite(root.name, pddl_domain, tuple(instances), str(root.resolve()))


def generated(
    blocks: Sequence[int],
    n: int,
    seed: int,
    max_nodes: int = 20_000,
    progress: Callable[[int], None] | None = None,
    keep: Callable | None = None,
) -> Suite:
    """``n`` random problems per block count (only those ``keep`` accepts, if given: a scene
    they must fit); optimal lengths from A* within ``max_nodes``. Instance ``i`` of ``b``
    blocks uses the ``i``-th kept seed drawn from ``Random(f"{seed}:{b}")``, so adding a block
    count leaves the others unchanged. Each problem goes through its PDDL text. DataError when
    no problem of a block count is kept (a benchmark of zero episodes), or ``n`` < 1."""
    if n < 1:
        raise DataError(f"n={n}: a random suite needs at least one problem per block count")
    report = progress or (lambda k: None)
    domain = data.domain()
    instances = []
    for b in blocks:
        seeds, kept = random.Random(f"{seed}:{b}"), 0
        for _ in range(100 * n):
            problem = random_problem(b, seeds.randrange(2**31))
            if keep is not None and not keep(problem):
                continue
            kept += 1
            moves = optimal_moves(problem, max_nodes)
            name = f"random-{b}/instance-{kept}"
            text = blocksworld.to_pddl(problem)
            optimal = None if moves is None else 2 * len(moves)
            instances.append(from_text(domain, text, name, name, optimal))
            report(1)
            if kept == n:
                break
        if kept == 0:
            raise DataError(
                f"--blocks {b}: none of {100 * n} random {b}-block problems fits the scene "
                "(a slot per tower, one to spare, none too tall): fewer blocks, or another scene"
            )
    source = f"task.symbolic.generate.random_problem, seed {seed}, A* budget {max_nodes} nodes"
    return Suite("random", domain, tuple(instances), source)


def domain_of(suite: Suite) -> str:
    """The domain rules that plan ``suite`` (its first instance's)."""
    return suite.instances[0].problem.domain if suite.instances else blocksworld.NAME
