"""Summary rows of a benchmark in the paper's format, computed from its per-instance rows.

A `Summary` covers one horizon and either one seed or the mean over seeds (``seed`` None), over
all instances or one size (block count, packages, boxes). Counts of a mean row are means over
seeds (e.g. 598.3 valid).
"Optimal" counts valid plans as long as the known optimum (`is_optimal`, the one definition
every benchmark uses); its percentage is taken over the valid plans whose instance has a known
optimum (``known`` says how many instances have one). Where the data give a reference plan that
need not be optimal (PlanBench Logistics), ``at_most_ref`` counts valid plans no longer than it
and ``shorter_than_ref`` those strictly shorter.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields

from tamp.bench.planning import STATUSES, Bench, Row, best_known, percentiles
from task.errors import TampError


@dataclass(frozen=True)
class Summary:
    horizon: int
    seed: int | None  # None: mean over seeds
    size: int | None  # None: every size
    n: int  # instances
    known: int  # instances with a known optimal length
    valid: float
    optimal: float  # valid plans of optimal length (among instances with a known optimum)
    optimal_pct: float | None  # 100 * optimal / valid plans with a known optimum
    inexecutable: float
    non_goal_reaching: float
    no_plan: float
    time_s: float  # mean planning time per instance
    wall_s: float | None  # wall time of the whole batch (None for a block-count row)
    windows: float  # mean replanning windows per instance
    with_ref: int = 0  # instances with a reference length
    at_most_ref: float = 0.0  # valid plans no longer than the reference
    at_most_ref_pct: float | None = None  # 100 * at_most_ref / valid plans with a reference
    shorter_than_ref: float = 0.0  # valid plans shorter than the reference
    length: float | None = None  # mean length of the valid plans (PDDL actions)
    ratio: float | None = None  # mean length / optimum over valid plans with a known optimum
    lama: float | None = None  # instances LAMA solved (None: LAMA did not run)
    lama_length: float | None = None  # mean length of LAMA's plans (PDDL actions)
    lama_ratio: float | None = None  # mean LAMA length / optimum where the optimum is known
    lama_s: float | None = None  # LAMA's mean wall seconds per instance
    vs_lama: float | None = None  # mean our length / LAMA's, where both have a plan
    us: float | None = None  # instances with a valid US plan (None: US did not run)
    us_length: float | None = None  # mean length of US's plans (PDDL actions)
    us_ratio: float | None = None  # mean US length / optimum where the optimum is known
    us_s: float | None = None  # US's mean seconds per instance
    vs_us: float | None = None  # mean our length / US's, where both have a plan
    gn1: float | None = None  # the same for GN1 (`tamp.bench.peers.slaney`)
    gn1_length: float | None = None
    gn1_ratio: float | None = None
    gn1_s: float | None = None
    vs_gn1: float | None = None
    best: float | None = None  # valid plans as short as the best known (`best_known`; None:
    # nothing to compare with: no optimum known and no peer ran)
    vs_best: float | None = None  # mean our length / the best known, over valid plans

    def asdict(self) -> dict:
        return asdict(self)


def is_optimal(length: int, optimal: int, instance: str) -> bool:
    """Whether a *valid* plan of ``length`` 4-op actions is optimal: as long as the known
    optimum. A valid plan shorter than the optimum raises TampError naming ``instance``: the
    optimum or the validator is wrong, and no benchmark may count that as a success."""
    if length < optimal:
        raise TampError(
            f"{instance}: a valid plan of {length} actions is shorter than its known optimum "
            f"{optimal}; the optimum or the validator is wrong"
        )
    return length == optimal


def _fmean(values: Sequence[float]) -> float:
    return statistics.fmean(values) if values else 0.0


def _mean(values: Sequence[float]) -> float | None:
    """The mean, or None when there is nothing to average."""
    return statistics.fmean(values) if values else None


def summarise(
    rows: Sequence[Row], horizon: int, seed: int | None, size: int | None, wall: float | None
) -> Summary:
    """The summary of one seed's ``rows``."""
    count = {s: sum(r.status == s for r in rows) for s in STATUSES}
    scored = [r for r in rows if r.status == "valid" and r.optimal is not None]
    optimal = sum(is_optimal(r.length, r.optimal, r.instance) for r in scored)
    refs = [r for r in rows if r.status == "valid" and r.reference is not None]
    at_most = sum(r.length <= r.reference for r in refs)
    valid = [r for r in rows if r.status == "valid"]
    lama = [r for r in rows if r.lama_length is not None]
    ran = any(r.lama_s is not None for r in rows)
    return Summary(
        horizon=horizon,
        seed=seed,
        size=size,
        n=len(rows),
        known=sum(r.optimal is not None for r in rows),
        valid=count["valid"],
        optimal=optimal,
        optimal_pct=100.0 * optimal / len(scored) if scored else None,
        inexecutable=count["inexecutable"],
        non_goal_reaching=count["non_goal_reaching"],
        no_plan=count["no_plan"],
        time_s=_fmean([r.time_s for r in rows]),
        wall_s=wall,
        windows=_fmean([r.windows for r in rows]),
        with_ref=sum(r.reference is not None for r in rows),
        at_most_ref=at_most,
        at_most_ref_pct=100.0 * at_most / len(refs) if refs else None,
        shorter_than_ref=sum(r.length < r.reference for r in refs),
        length=_mean([r.length for r in valid]),
        ratio=_mean([r.length / r.optimal for r in scored]),
        lama=len(lama) if ran else None,
        lama_length=_mean([r.lama_length for r in lama]),
        lama_ratio=_mean([r.lama_length / r.optimal for r in lama if r.optimal]),
        lama_s=_mean([r.lama_s for r in rows if r.lama_s is not None]),
        vs_lama=_mean([r.length / r.lama_length for r in valid if r.lama_length]),
        **_baseline("us", rows, valid),
        **_baseline("gn1", rows, valid),
        **_beside_best(rows, valid),
    )


def _beside_best(rows: Sequence[Row], valid: Sequence[Row]) -> dict:
    """``best`` and ``vs_best``: our valid plans against the shortest plan known for each
    instance (`tamp.bench.planning.best_known`); None when no peer ran and no optimum is
    known (the best known would be our own plan)."""
    peers = any(
        r.optimal is not None or r.lama_s is not None or r.us_s is not None or r.gn1_s is not None
        for r in rows
    )
    if not peers or not valid:
        return {"best": None, "vs_best": None}
    best = [best_known(r) for r in valid]
    return {
        "best": sum(r.length == b for r, b in zip(valid, best, strict=True)),
        "vs_best": _mean([r.length / b for r, b in zip(valid, best, strict=True)]),
    }


def _baseline(name: str, rows: Sequence[Row], valid: Sequence[Row]) -> dict:
    """The Summary fields of baseline ``name`` ("us", "gn1"): its count of valid plans (None
    when it did not run), mean length, mean length / optimum, mean seconds, ours / its."""
    length = [getattr(r, f"{name}_length") for r in rows]
    seconds = [getattr(r, f"{name}_s") for r in rows if getattr(r, f"{name}_s") is not None]
    found = [(r, k) for r, k in zip(rows, length, strict=True) if k is not None]
    return {
        name: sum(1 for _ in found) if seconds else None,
        f"{name}_length": _mean([k for _, k in found]),
        f"{name}_ratio": _mean([k / r.optimal for r, k in found if r.optimal]),
        f"{name}_s": _mean(seconds),
        f"vs_{name}": _mean(
            [r.length / getattr(r, f"{name}_length") for r in valid if getattr(r, f"{name}_length")]
        ),
    }


def mean_over_seeds(per_seed: Sequence[Summary]) -> Summary:
    """Field-wise mean of the summaries of several seeds (same horizon and instances)."""
    first = per_seed[0]
    values = {}
    for f in fields(Summary):
        if f.name in ("horizon", "size", "n", "known", "with_ref"):
            values[f.name] = getattr(first, f.name)
        elif f.name == "seed":
            values[f.name] = None
        else:
            present = [getattr(s, f.name) for s in per_seed if getattr(s, f.name) is not None]
            values[f.name] = _fmean(present) if present else None
    return Summary(**values)


def main_rows(bench: Bench) -> list[Summary]:
    """A row per (horizon, seed) over all instances, then their mean when there are seeds > 1."""
    out = []
    for h in bench.horizons:
        runs = [r for r in bench.runs if r.horizon == h]
        per_seed = [summarise(r.rows, h, r.seed, None, r.wall_s) for r in runs]
        out += per_seed
        if len(per_seed) > 1:
            out.append(mean_over_seeds(per_seed))
    return out


def size_rows(bench: Bench) -> list[Summary]:
    """A row per (horizon, size), each the mean over seeds."""
    counts = sorted({r.size for r in bench.rows()})
    out = []
    for h in bench.horizons:
        runs = [r for r in bench.runs if r.horizon == h]
        for b in counts:
            per_seed = [
                summarise([x for x in r.rows if x.size == b], h, r.seed, b, None) for r in runs
            ]
            out.append(mean_over_seeds(per_seed))
    return out


def latency_rows(bench: Bench) -> list[dict]:
    """Per (horizon, size): planning latency percentiles over every instance and seed, in s
    (`planning.percentiles`). Meaningful when each instance was planned alone
    (``batched=False``); [] for a batched run, whose per-instance times are shares of a batch."""
    if bench.config.batched:
        return []
    out = []
    for h in bench.horizons:
        rows = [r for run in bench.runs if run.horizon == h for r in run.rows]
        for b in sorted({r.size for r in rows}):
            times = [r.time_s for r in rows if r.size == b]
            out.append({"horizon": h, "size": b, "n": len(times), **percentiles(times)})
    return out
