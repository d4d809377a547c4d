"""Planning benchmarks: plan a suite per (horizon, seed), validate every plan, summarise.

Each plan is converted to its domain's PDDL actions and checked by
`task.symbolic.validate.validate` against the instance's parsed PDDL problem (the official check,
independent of the planner's own crisp replay). Summaries follow the paper's table: valid out of
N, optimal as a share of the valid plans, inexecutable, non-goal-reaching, mean time per instance
and total wall time, one row per (horizon, seed), a mean over seeds, and rows per size (blocks,
packages, boxes).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, fields, replace

from pddl.core import Domain

from tamp.bench.suites import Suite, domain_of
from task.config import PlannerConfig
from task.domains import get_domain
from task.instances import Instance
from task.planner import plan_batch
from task.problem import Move, PlanResult, PlanStatus
from task.symbolic.validate import Validation, validate

STATUSES = ("valid", "inexecutable", "non_goal_reaching", "no_plan")


@dataclass(frozen=True)
class Row:
    """One instance planned with one (horizon, seed). ``length``: our PDDL actions or None;
    ``size``: the instance's size in its domain's units (blocks, packages, boxes, atoms)."""

    instance: str
    size: int
    optimal: int | None
    reference: int | None
    horizon: int
    seed: int
    length: int | None
    status: str
    time_s: float
    windows: int
    lama_length: int | None = None  # LAMA's first plan, PDDL actions (``--lama``; None: none)
    lama_s: float | None = None  # LAMA's wall seconds, translator and search
    us_length: int | None = None  # Slaney & Thiebaux's US, PDDL actions (``--baselines``)
    us_s: float | None = None  # US's seconds (None: US did not run)
    gn1_length: int | None = None  # their GN1, PDDL actions (None: not run, or invalid)
    gn1_s: float | None = None  # GN1's seconds


def _ours(row: Row) -> int | None:
    """Our plan's length in PDDL actions when it is valid, else None."""
    return row.length if row.status == "valid" else None


def best_known(row: Row) -> int | None:
    """The shortest plan known for ``row``'s instance, in PDDL actions: the least of its
    optimum, our valid plan and the peers' plans that ran (LAMA, US, GN1); None when none is
    known."""
    found = (row.optimal, _ours(row), row.lama_length, row.us_length, row.gn1_length)
    lengths = [k for k in found if k is not None]
    return min(lengths) if lengths else None


def beside_best(row: Row) -> dict:
    """``row``'s fields with `best_known` and ``x_best`` (our valid plan's length over it;
    None without a valid plan): `INSTANCE_COLUMNS`, one instances.csv row."""
    best, ours = best_known(row), _ours(row)
    ratio = None if ours is None or not best else ours / best
    return asdict(row) | {"best_known": best, "x_best": ratio}


INSTANCE_COLUMNS = (*(f.name for f in fields(Row)), "best_known", "x_best")


@dataclass(frozen=True)
class Run:
    """A whole suite planned in one `plan_batch` call; ``wall_s`` is that call's wall time."""

    horizon: int
    seed: int
    wall_s: float
    rows: tuple[Row, ...]

    def valid(self) -> int:
        return sum(r.status == "valid" for r in self.rows)


@dataclass(frozen=True)
class Speed:
    """The batched and the sequential path on the same first ``n`` instances."""

    n: int
    horizon: int
    seed: int
    batched_s: float
    sequential_s: float
    batched_valid: int
    sequential_valid: int
    latency_s: dict[str, float] | None = None  # one problem at a time: p50, p90, max seconds

    @property
    def speedup(self) -> float | None:
        """How many times faster the batched path ran (sequential / batched wall time)."""
        return self.sequential_s / self.batched_s if self.batched_s > 0 else None


@dataclass(frozen=True)
class Bench:
    """Everything one benchmark invocation measured; ``size_name``: what a row's size counts."""

    suite: str
    source: str
    n: int
    config: PlannerConfig
    seeds: tuple[int, ...]
    horizons: tuple[int, ...]
    runs: tuple[Run, ...]
    speed: Speed | None = None
    size_name: str = "blocks"

    def rows(self) -> tuple[Row, ...]:
        return tuple(r for run in self.runs for r in run.rows)


def replay(domain: Domain, instance: Instance, moves: Sequence[Move]) -> Validation:
    """``moves`` as the domain's PDDL actions, replayed by `validate` from the instance's PDDL
    initial state to its PDDL goal. An illegal move is translated as it stands, so the
    validator names the first step that fails."""
    problem = instance.problem
    actions = get_domain(problem.domain).to_actions(problem, moves, strict=False)
    return validate(domain, instance.pddl, actions)


def check(domain: Domain, instance: Instance, result: PlanResult) -> tuple[str, int | None]:
    """``(status, PDDL length)`` of a planner result, validated against the instance's PDDL.

    Every plan the planner returns is replayed (`replay`), an inexecutable one too; only a
    window budget that ran out is ``no_plan``."""
    if result.status in (PlanStatus.NO_PLAN, PlanStatus.UNSOLVABLE):
        return "no_plan", None
    validation = replay(domain, instance, result.plan.moves)
    return validation.status.value, validation.length


def run_once(
    suite: Suite,
    config: PlannerConfig,
    seed: int,
    progress: Callable[[int], None] | None = None,
    instances: Sequence[Instance] | None = None,
    on_row: Callable[[Row], None] | None = None,
) -> Run:
    """Plan ``instances`` (default: the whole suite) with one config and seed; validate all.
    ``on_row(row)`` as each instance's row is final (`plan_batch`'s ``on_result``: what
    Ctrl-C keeps of a run not complete)."""
    chosen = tuple(suite.instances if instances is None else instances)
    start = time.perf_counter()

    def row(instance: Instance, result: PlanResult, wall: float) -> Row:
        status, length = check(suite.domain, instance, result)
        return Row(
            instance=instance.name,
            size=instance.size,
            optimal=instance.optimal,
            reference=instance.reference,
            horizon=config.horizon,
            seed=seed,
            length=length,
            status=status,
            time_s=float(result.stats.get("time_s", wall / max(len(chosen), 1))),
            windows=int(result.stats.get("windows", 0)),
        )

    kept: dict[int, Row] = {}

    def final(i: int, result: PlanResult) -> None:
        kept[i] = row(chosen[i], result, time.perf_counter() - start)
        if on_row is not None:
            on_row(kept[i])

    plan_batch([i.problem for i in chosen], config, seed, progress, on_result=final)
    wall = time.perf_counter() - start
    return Run(config.horizon, seed, wall, tuple(kept[i] for i in range(len(chosen))))


def run(
    suite: Suite,
    config: PlannerConfig,
    seeds: Sequence[int] = (0,),
    horizons: Sequence[int] | None = None,
    sequential: int = 0,
    progress: Callable[[int], None] | None = None,
    on_run: Callable[[Run], None] | None = None,
    on_row: Callable[[Row], None] | None = None,
) -> Bench:
    """Plan the suite for every horizon and seed (horizons default to ``config.horizon``);
    ``on_run(run)`` as each (horizon, seed) run is complete, ``on_row(row)`` as each of its
    rows is (what Ctrl-C keeps).

    With ``sequential > 0`` the first ``sequential`` instances are also planned once batched and
    once with ``PlannerConfig(batched=False)`` (first horizon, first seed) to time batching.
    A one-window, one-step plan of the first instance runs untimed first (torch warm-up).
    """
    horizons = tuple(horizons or (config.horizon,))
    seeds = tuple(seeds)
    if suite.instances:  # untimed warm-up: torch's one-time start-up cost
        warm = replace(config, iters=1, max_windows=1)
        plan_batch([suite.instances[0].problem], warm, seeds[0])
    runs = []
    for h in horizons:
        for s in seeds:
            runs.append(run_once(suite, replace(config, horizon=h), s, progress, on_row=on_row))
            if on_run is not None:
                on_run(runs[-1])
    runs = tuple(runs)
    speed = None
    if sequential > 0:
        subset = suite.instances[:sequential]
        cfg = replace(config, horizon=horizons[0])
        fast = run_once(suite, replace(cfg, batched=True), seeds[0], progress, subset)
        slow = run_once(suite, replace(cfg, batched=False), seeds[0], progress, subset)
        latency = percentiles([r.time_s for r in slow.rows])
        speed = Speed(
            n=len(subset),
            horizon=horizons[0],
            seed=seeds[0],
            batched_s=fast.wall_s,
            sequential_s=slow.wall_s,
            batched_valid=fast.valid(),
            sequential_valid=slow.valid(),
            latency_s=latency,
        )
    n = len(suite.instances)
    size_name = get_domain(domain_of(suite)).size_name
    return Bench(
        suite=suite.name,
        source=suite.source,
        n=n,
        config=config,
        seeds=seeds,
        horizons=horizons,
        runs=runs,
        speed=speed,
        size_name=size_name,
    )


def with_lama(
    bench: Bench,
    suite: Suite,
    time_limit_s: float = 60.0,
    progress: Callable[[int], None] | None = None,
) -> Bench:
    """``bench`` with LAMA's plan length and wall time on every row (`fast_downward.lama_length`
    on each instance's PDDL, the domain's own text; benchmark-only, needs the ``bench`` extra).
    LAMA runs once per instance, one instance at a time; ``progress(1)`` after each."""
    from tamp.bench import fast_downward

    report = progress or (lambda k: None)
    found = {}
    for instance in suite.instances:
        rules = get_domain(instance.problem.domain)
        start = time.perf_counter()
        result = fast_downward.lama_length(
            rules.pddl_domain_text(), rules.to_pddl(instance.problem), time_limit_s
        )
        found[instance.name] = (result.length, time.perf_counter() - start)
        report(1)
    runs = tuple(
        replace(
            run,
            rows=tuple(
                replace(r, lama_length=found[r.instance][0], lama_s=found[r.instance][1])
                for r in run.rows
            ),
        )
        for run in bench.runs
    )
    return replace(bench, runs=runs)


def with_baselines(
    bench: Bench, suite: Suite, names: Sequence[str], progress: Callable[[int], None] | None = None
) -> Bench:
    """``bench`` with the plan length (validated against the instance's PDDL, `replay`; None
    when invalid) and seconds of each Slaney & Thiebaux baseline in ``names`` ("us", "gn1",
    `tamp.bench.peers.slaney`) on every row. Each runs once per instance; ``progress(1)``
    after each instance."""
    from tamp.bench.peers import slaney

    report = progress or (lambda k: None)
    found: dict[str, dict] = {}
    for instance in suite.instances:
        found[instance.name] = {}
        for name in names:
            planned = slaney.run(name, instance.problem)
            validation = replay(suite.domain, instance, planned.moves)
            length = validation.length if validation.valid else None
            found[instance.name] |= {f"{name}_length": length, f"{name}_s": planned.seconds}
        report(1)
    runs = tuple(
        replace(run, rows=tuple(replace(r, **found[r.instance]) for r in run.rows))
        for run in bench.runs
    )
    return replace(bench, runs=runs)


def percentiles(times: Sequence[float]) -> dict[str, float]:
    """p50, p90 and max of per-problem planning times (s): a percentile is the sorted time at
    index floor(f * count)."""
    t = sorted(times)
    cut = {q: t[min(len(t) - 1, int(f * len(t)))] for q, f in (("p50", 0.5), ("p90", 0.9))}
    return cut | {"max": t[-1]}


def total(n: int, seeds: int, horizons: int, sequential: int = 0) -> int:
    """How many plans `run` makes: a progress bar's total (``progress`` counts them)."""
    return n * seeds * horizons + 2 * min(sequential, n)
