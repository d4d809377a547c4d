"""tamp.bench: every benchmark of the project, one home.

- ``suites``: what is benchmarked (PlanBench Blocksworld-600, seeded random problems);
- ``planning``: plan a suite per (horizon, seed) and validate every plan (``bench planbench``,
  ``bench random``); ``summary``: its rows in the paper's format;
- ``motion``: closed-loop episodes in the simulators (``bench motion``);
- ``perception``: planning from rendered images (``bench perception``);
- ``latplan``: LatPlan-40 planned from its true states and its images (``bench latplan``);
- ``poses``: block poses from RGB-D images against the true poses (``bench poses``);
- ``fast_downward``: optimal plan lengths from Fast Downward (the ``bench`` extra,
  benchmark-only) for sets whose data lack them, cached by the PDDL texts' digest;
- ``results``: the one results writer (output folder, machine record, JSON, CSV, plots);
- ``tables``: the one table printer;
- ``record``: ``bench record``, the typed records of results (``records``) and BENCHMARKS.md
  rendered from them (``markdown``).

The command-line handlers that call these live in `tamp.cli.bench` (one module per kind).
"""
