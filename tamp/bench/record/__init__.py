"""tamp.bench.record: the record of results (``tamp bench record``), one typed record per
benchmark run and BENCHMARKS.md generated from them.

- ``records``: `Record`, its `Family` and the figures each family keeps, read from a
  benchmark's results folder, written to and loaded from ``results/current/``;
- ``markdown``: the "Current results" block, the families without a record yet, the
  experiments index, BENCHMARKS.md whole and the README's block, rendered from the records.
"""
