"""Benchmarks in `tamp.api`: the suites (`random_suite`, `folder_suite`, `planbench_suite`),
`benchmark` (a suite planned per horizon and seed and every plan validated, as
`PlanningBenchmark`) and `benchmark_motion` (one closed-loop episode per instance); the only
functions of the entry layer that import `tamp.bench`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from tamp.api.args import INT, INTS, LOOP_CONFIG, PATH, PLANNER_CONFIG, SUITE, TEXT, TEXTS, checked
from tamp.api.episodes import loop_config
from task.config import PlannerConfig

if TYPE_CHECKING:  # heavy modules load when a function needs them
    from tamp.bench.motion import MotionBench
    from tamp.bench.planning import Bench
    from tamp.bench.suites import Suite
    from tamp.bench.summary import Summary
    from tamp.loop import LoopConfig


@dataclass(frozen=True)
class PlanningBenchmark:
    """A planning benchmark's measurements: ``bench`` (every instance's row: status, length,
    optimum, seconds) and ``summary``, the paper's table rows (`tamp.bench.summary.Summary`:
    valid, optimal share, inexecutable, non-goal-reaching, seconds per instance), one per
    horizon and seed, then the mean over seeds."""

    bench: Bench
    summary: tuple[Summary, ...] = field(default=())


@checked(blocks=INTS, n=INT, seed=INT)
def random_suite(blocks: Sequence[int] = (3, 4), n: int = 5, seed: int = 0) -> Suite:
    """``n`` seeded random Blocksworld problems per block count, with optimal lengths from A*
    (``tamp bench random``)."""
    from tamp.bench.suites import generated

    return generated(tuple(blocks), n, seed)


@checked(folder=PATH, limit=INT.optional(), rules=TEXT.optional())
def folder_suite(folder: str | Path, limit: int | None = None, rules: str | None = None) -> Suite:
    """Every problem file of a folder holding ``domain.pddl`` and problems (``tamp bench pddl``);
    ``limit``: a spread of that many; ``rules``: as `load_problem`."""
    from tamp.bench.suites import pddl_folder

    return pddl_folder(folder, limit, rules=rules)


@checked(data_dir=PATH, domain=TEXT, limit=INT.optional())
def planbench_suite(
    data_dir: str | Path, domain: str = "blocksworld", limit: int | None = None
) -> Suite:
    """An official PlanBench set (``blocksworld``: the 600; ``logistics``; ``sokoban``) from a
    checkout laid out as ``../shared/data/planbench/<domain>`` (``tamp bench planbench``);
    ``limit``: a spread of that many instances over the sizes."""
    from tamp.bench.suites import planbench

    return planbench(data_dir, limit, domain=domain)


@checked(suite=SUITE, config=PLANNER_CONFIG.optional(), seeds=INTS, horizons=INTS.optional())
def benchmark(
    suite: Suite,
    config: PlannerConfig | None = None,
    seeds: Sequence[int] = (0,),
    horizons: Sequence[int] | None = None,
) -> PlanningBenchmark:
    """Plan every instance of ``suite`` per horizon and seed in one batched tensor program and
    validate every plan (``tamp bench planbench|pddl|random`` without the printing).
    ``config``: None gives the suite's domain defaults; ``horizons``: the window lengths T
    (default ``config.horizon``)."""
    from tamp.bench import planning, summary
    from tamp.bench.suites import domain_of

    config = PlannerConfig.for_domain(domain_of(suite)) if config is None else config
    bench = planning.run(suite, config, seeds, horizons)
    return PlanningBenchmark(bench, tuple(summary.main_rows(bench)))


@checked(suite=SUITE, sims=TEXTS, config=LOOP_CONFIG.optional(), seed=INT, workers=INT)
def benchmark_motion(
    suite: Suite,
    sims: Sequence[str] = ("pybullet",),
    *,
    config: LoopConfig | None = None,
    seed: int = 0,
    workers: int = 1,
) -> MotionBench:
    """One closed-loop episode per instance in each simulator (``tamp bench motion``): the
    result's ``summary[sim]`` has episodes, goal_reached, moves, moves_ok, failures by kind,
    replans, disturbed stacks, seconds per move; ``reports`` every `EpisodeReport`. Episode k
    uses seed ``seed * 100003 + k``; ``workers`` runs them in that many local processes."""
    from tamp.bench.motion import run

    return run(suite, loop_config(config, None), tuple(sims), seed, workers=workers)
