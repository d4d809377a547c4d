"""Run a planning benchmark from Python and read its table.

`tamp.api.benchmark` plans a whole suite per horizon and seed in one batched tensor program and
validates every plan, as ``tamp bench random|pddl|planbench`` do; each summary row is the
paper's table row: valid out of N, optimal as a share of the valid plans, inexecutable,
non-goal-reaching, seconds per instance. Suites: `api.random_suite` (seeded, optima from A*),
`api.folder_suite` (a folder of PDDL problems), `api.planbench_suite` (the official sets).
Run: ``python examples/benchmark.py`` (about 10 s).
"""

from __future__ import annotations

from tamp import api


def main() -> None:
    suite = api.random_suite(blocks=(3, 4), n=2, seed=0)  # 4 problems, optima from A*
    result = api.benchmark(suite, seeds=(0,), horizons=(1, 3))  # the window ablation
    print(f"{suite.name}: {len(suite.instances)} instances ({suite.source})")
    for row in result.summary:
        seed = "mean" if row.seed is None else f"seed {row.seed}"
        optimal = "-" if row.optimal_pct is None else f"{row.optimal_pct:.1f}%"
        print(
            f"T={row.horizon} {seed}: valid {row.valid:g}/{row.n}, optimal {optimal}, "
            f"inexecutable {row.inexecutable:g}, {row.time_s:.3f} s/instance"
        )
    for r in result.bench.rows()[:3]:
        print(f"  {r.instance}: {r.status}, {r.length} actions (optimal {r.optimal})")
    assert all(row.valid == row.n for row in result.summary)


if __name__ == "__main__":
    main()
