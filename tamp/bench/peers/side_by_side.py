"""Our planner and the classical peers on the same PDDL instances, one run side by side.

``run`` plans every instance with each peer in turn (one instance at a time, each within the same
``time_limit_s`` that ours had per instance); ``summarise`` gives one line per planner: instances
solved, mean plan length over what it solved, mean wall seconds over all instances (a timeout
counts at its limit), and the mean length over the instances every planner solved (the only fair
length comparison). Ours counts as solved only when its plan validates against the PDDL.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from tamp.bench import fast_downward
from tamp.bench.peers import gbf
from task.errors import DataError, one_of

PEERS = ("pyperplan", "lama")
LABELS = {"ours": "ours", "pyperplan": "pyperplan GBF+hFF", "lama": "FD LAMA (lama-first)"}
_DOMAIN_FILES = ("domain.pddl", "generated_domain.pddl")  # as `tamp.bench.suites` reads them


@dataclass(frozen=True)
class PeerRow:
    """One instance planned by one peer: ``status`` "solved" or why not, ``length`` in PDDL
    actions (None unless solved), ``seconds`` wall seconds (translation/grounding included)."""

    instance: str
    peer: str
    status: str
    length: int | None
    seconds: float


@dataclass(frozen=True)
class Line:
    """One planner on one domain: ``solved`` of ``n``; ``mean_length`` over its solved
    instances, ``mean_s`` over all ``n``; ``common_length`` over the ``common`` instances that
    every planner of the run solved (None when there are none)."""

    domain: str
    planner: str
    n: int
    solved: int
    mean_length: float | None
    mean_s: float
    common: int
    common_length: float | None


def parse(text: str) -> tuple[str, ...]:
    """``"pyperplan,lama"`` as a tuple of peer names; TampError listing the peers otherwise."""
    names = tuple(t.strip() for t in text.split(",") if t.strip())
    bad = [n for n in names if n not in PEERS]
    if bad or not names:
        raise DataError(f"--peers: unknown peer {one_of(bad[0] if bad else text, PEERS)}")
    return tuple(dict.fromkeys(names))


def require(peers: Sequence[str]) -> None:
    """One-line DataError naming the ``bench`` extra when a peer's package is missing."""
    for peer in peers:
        if peer == "pyperplan":
            gbf.require()
        elif peer == "lama" and not fast_downward.available():
            extra = f"pip install 'soft-tamp[bench]' (the package {fast_downward.PACKAGE})"
            raise DataError(f"--peers lama: Fast Downward is not installed, {extra}")


def files(source: str | Path, names: Sequence[str]) -> list[tuple[str, Path, Path]]:
    """``(name, domain file, problem file)`` of the instances ``names`` (file stems) of a folder
    of PDDL (`tamp.bench.suites.pddl_folder`'s layout)."""
    root = Path(source)
    domain = next((root / n for n in _DOMAIN_FILES if (root / n).is_file()), None)
    if domain is None:
        raise DataError(f"{root}: no domain.pddl")
    return [(name, domain, root / f"{name}.pddl") for name in names]


def solve(peer: str, domain: str, problem: str, time_limit_s: float) -> PeerRow:
    """One peer on the PDDL texts ``domain`` and ``problem`` (instance name left empty)."""
    start = time.perf_counter()
    if peer == "pyperplan":
        result = gbf.gbf_hff(domain, problem, time_limit_s)
    elif peer == "lama":
        result = fast_downward.lama_length(domain, problem, time_limit_s)
    else:
        raise DataError(f"unknown peer {one_of(peer, PEERS)}")
    return PeerRow("", peer, result.status, result.length, time.perf_counter() - start)


def run(
    instances: Sequence[tuple[str, Path, Path]],
    peers: Sequence[str],
    time_limit_s: float,
    progress: Callable[[int], None] | None = None,
) -> tuple[PeerRow, ...]:
    """Every ``(name, domain file, problem file)`` with every peer, one at a time;
    ``progress(1)`` after each (peer, instance)."""
    require(peers)
    report = progress or (lambda k: None)
    rows = []
    for peer in peers:
        for name, domain_path, problem_path in instances:
            domain = domain_path.read_text(encoding="utf-8")
            problem = problem_path.read_text(encoding="utf-8")
            row = solve(peer, domain, problem, time_limit_s)
            rows.append(PeerRow(name, peer, row.status, row.length, row.seconds))
            report(1)
    return tuple(rows)


def summarise(
    domain: str,
    ours: Sequence[tuple[str, int | None, float]],
    peers: Sequence[PeerRow],
) -> list[Line]:
    """Lines for ours (``(instance, length or None when not a valid plan, seconds)``) and each
    peer in ``peers``, in that order."""
    found = {"ours": {name: (length, s) for name, length, s in ours}}
    for row in peers:
        found.setdefault(row.peer, {})[row.instance] = (row.length, row.seconds)
    names = [name for name, _, _ in ours]
    common = [n for n in names if all(found[p].get(n, (None, 0))[0] is not None for p in found)]
    lines = []
    for planner, got in found.items():
        lengths = [got[n][0] for n in names if got.get(n, (None, 0))[0] is not None]
        times = [got[n][1] for n in names if n in got]
        shared = [got[n][0] for n in common]
        lines.append(
            Line(
                domain=domain,
                planner=planner,
                n=len(names),
                solved=len(lengths),
                mean_length=sum(lengths) / len(lengths) if lengths else None,
                mean_s=sum(times) / len(times) if times else 0.0,
                common=len(common),
                common_length=sum(shared) / len(shared) if shared else None,
            )
        )
    return lines


def table(lines: Sequence[Line]) -> str:
    """A plain-text table of `summarise` lines, one per planner and domain."""

    def num(x: float | None, fmt: str) -> str:
        return "-" if x is None else format(x, fmt)

    head = ("domain", "planner", "solved", "mean length", "mean s", "length on common")
    body = [
        (
            line.domain,
            LABELS.get(line.planner, line.planner),
            f"{line.solved}/{line.n}",
            num(line.mean_length, ".1f"),
            num(line.mean_s, ".2f"),
            f"{num(line.common_length, '.1f')} ({line.common})",
        )
        for line in lines
    ]
    widths = [max(len(r[k]) for r in (head, *body)) for k in range(len(head))]
    out = [
        "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip()
        for r in (head, *body)
    ]
    return "\n".join(out)
