"""Optimal 4-op plan lengths for PlanBench instances without a manifest, cached on disk.

The optimum is exact: A* over blocksworld moves with an admissible heuristic
(`task.symbolic.search.optimal_moves`), and the 4-op length is ``2 * moves`` (each move is a
pick-up/unstack followed by a put-down/stack). All 600 official instances take well under a
second, but the results are still kept in ``optimal_lengths.json`` in the benchmark's output
folder, keyed by instance name and the SHA-256 of the problem file's text: a second run reads
them back, and an edited file is searched again. A cache that cannot be read is rebuilt.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from pathlib import Path

from task.errors import DataError
from task.problem import Problem
from task.symbolic.search import optimal_moves

CACHE_FILE = "optimal_lengths.json"
METHOD = "task.symbolic.search.optimal_moves (A*), 4-op length = 2 x moves"


def digest(text: str) -> str:
    """SHA-256 (hex) of a problem file's text, the cache key next to the instance name."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _search(problem: Problem) -> int | None:
    """The optimal 4-op length, None if A* runs out of its node budget."""
    moves = optimal_moves(problem)
    return None if moves is None else 2 * len(moves)


def read_cache(path: Path, method: str = METHOD, key: str = "instances") -> dict[str, dict]:
    """A JSON cache's entries (its ``key`` field) when it was written by ``method``; empty if
    missing, unreadable or made another way (the optimum caches of this module and of
    `tamp.bench.fast_downward`)."""
    try:
        cached = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    if not isinstance(cached, dict) or cached.get("method") != method:
        return {}
    entries = cached.get(key)
    return entries if isinstance(entries, dict) else {}


def write_cache(
    path: Path, entries: dict[str, dict], method: str = METHOD, key: str = "instances"
) -> None:
    """Replace ``path`` atomically, so an interrupted run never leaves half a file."""
    text = json.dumps({"method": method, key: entries}, indent=1, sort_keys=True)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_name(f"{path.name}.partial")
        partial.write_text(text + "\n", encoding="utf-8")
        os.replace(partial, path)
    except OSError as exc:
        raise DataError(f"{path}: cannot write the optimum cache ({exc.strerror or exc})") from None


def _valid(entry: object, key: str) -> bool:
    if not isinstance(entry, dict) or entry.get("sha256") != key:
        return False
    optimal = entry.get("optimal")
    return optimal is None or (isinstance(optimal, int) and optimal >= 0)


def optimal_lengths(
    problems: Sequence[tuple[str, str, Problem]], cache_dir: str | Path | None = None
) -> list[int | None]:
    """Optimal 4-op lengths of ``(name, digest, problem)`` triples, in order.

    With ``cache_dir``, lengths whose name and digest are in its ``optimal_lengths.json`` are
    reused, the others searched and added (entries of other instances are kept). Without it,
    every length is searched and nothing is written.
    """
    path = None if cache_dir is None else Path(cache_dir) / CACHE_FILE
    entries = {} if path is None else read_cache(path)
    lengths = []
    changed = False
    for name, key, problem in problems:
        if not _valid(entries.get(name), key):
            entries[name] = {"sha256": key, "optimal": _search(problem)}
            changed = True
        lengths.append(entries[name]["optimal"])
    if path is not None and changed:
        write_cache(path, entries)
    return lengths
