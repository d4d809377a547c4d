"""``tamp bench ...``: options in, `tamp.bench` runs, tables out. One module per kind of
benchmark: `planning` (planbench, pddl, random), `vision` (perception, latplan, poses,
segmentation), `arm` (motion, executability), `geo` (tamp), `checker` (the sphere collision
checker) and `record` (BENCHMARKS.md and the README's results block); `options` holds the
option groups of the benchmarks that sweep episodes or images (the parser's, imported without
torch).

Each handler turns options into configs, runs its benchmark from `tamp.bench` with a progress
bar on stderr, prints its table (``--json``: ``results.json``'s content), and with ``--out DIR``
writes its artefacts (`tamp.bench.results`). Exit 0 whatever the scores; 2 on bad input.
``motion`` and ``executability`` sweep many independent episodes: ``--workers N`` runs them in N
processes of this machine, ``--ray ADDRESS`` as Ray tasks on a cluster (`tamp.sweep.run_items`);
each episode has its own seed, so the rows are the same either way. Ctrl-C in a benchmark keeps
what is done: results.json marked ``partial`` (how many of how many) and the rows so far."""

from __future__ import annotations

import sys
from contextlib import contextmanager


@contextmanager
def bar(total: int, desc: str, enabled: bool, unit: str = "plan"):
    """A tqdm bar on stderr; yields ``update(k)``, the `plan_batch` progress callback."""
    from tqdm import tqdm  # when a benchmark runs: the parser imports `tamp.cli.bench.options`

    with tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=not enabled) as progress:
        yield progress.update


def interrupted(out, done: int, total: int, what: str) -> int:
    """After Ctrl-C in a benchmark: say what was kept (exit 130)."""
    kept = (
        f"wrote the {done} done to {out}, marked partial" if out else "nothing written (no --out)"
    )
    print(f"tamp: interrupted after {done} of {total} {what}; {kept}", file=sys.stderr)
    return 130
