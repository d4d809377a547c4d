"""Sweeps of independent items (benchmark episodes) in this process, a process pool or on Ray.

`run_items(fn, items, workers, ray_address, on_result)` applies a picklable module-level
``fn(item)`` to every item and returns the results in item order, whatever order they finish
in, calling ``on_result(index, result)`` as each one does (progress bars):

- ``workers=1`` and no Ray: a plain loop in this process, the sweep as it always ran;
- ``workers=N > 1``: a pool of N spawned processes (`concurrent.futures.ProcessPoolExecutor`);
- ``ray_address``: the items as Ray tasks (`ray.remote`), Ray imported only then (the optional
  extra ``soft-tamp[ray]``). ``"auto"``: the running cluster this machine belongs to (started
  with ``ray start``); ``"local"``: a fresh Ray instance on this machine only; ``"HOST:6379"``:
  that cluster's head. Ray is shut down at the end only when this call started it.

Determinism lives in the items: each carries its own seed (episode ``k`` of a benchmark uses
``seed * 100_003 + k``), so the results are the same whatever the number of workers. Pool and
Ray workers compute on one thread each: the processes are the parallelism (Ray's workers run
with ``OMP_NUM_THREADS=1`` too).

`torch_threads(n)`: a block run with ``n`` torch intra-op threads (one small problem: thread
hand-offs cost more than they give, and on a busy machine they wait for cores). The setting is
the process's, so only the edges choose it (the commands of `tamp.cli` and the benchmarks'
item functions, around the episodes they run); the library leaves it to its caller.

"""

from __future__ import annotations

import multiprocessing
import os
import sys
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import contextmanager
from typing import Any

from task.errors import TampError

RAY_MISSING = "--ray needs Ray: pip install 'soft-tamp[ray]'"


@contextmanager
def torch_threads(n: int):
    """Run the block with ``n`` torch intra-op threads, then restore the previous setting."""
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def run_items(
    fn: Callable[[Any], Any],
    items: Iterable,
    workers: int = 1,
    ray_address: str | None = None,
    on_result: Callable[[int, Any], None] | None = None,
) -> list:
    """``[fn(item) for item in items]``, in item order; ``on_result(index, result)`` as each
    finishes. ``workers``: processes (1: this one); ``ray_address`` (see the module docstring)
    overrides it. ``fn`` and the items must pickle unless both are 1/None. A worker's exception
    is raised here (the items not started yet are cancelled)."""
    items = list(items)
    if workers < 1:
        raise TampError(f"workers must be at least 1, got {workers}")
    if ray_address is not None:
        return _on_ray(fn, items, ray_address, on_result)
    if workers == 1:
        results = []
        for k, item in enumerate(items):
            results.append(fn(item))
            if on_result is not None:
                on_result(k, results[-1])
        return results
    return _in_pool(fn, items, workers, on_result)


def _one_thread() -> None:
    """A pool process's initializer: torch (and BLAS) on one thread, read when torch loads."""
    os.environ["OMP_NUM_THREADS"] = "1"
    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(1)


def _in_pool(fn: Callable, items: list, workers: int, on_result: Callable | None) -> list:
    results: list = [None] * len(items)
    context = multiprocessing.get_context("spawn")  # fork would copy torch's and a sim's state
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_one_thread)
    try:
        index = {pool.submit(fn, item): k for k, item in enumerate(items)}
        pending = set(index)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=index.__getitem__):
                k = index[future]
                results[k] = future.result()
                if on_result is not None:
                    on_result(k, results[k])
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return results


def _on_ray(fn: Callable, items: list, address: str, on_result: Callable | None) -> list:
    try:
        import ray
    except ImportError:
        raise TampError(RAY_MISSING) from None
    started = not ray.is_initialized()
    if started:  # worker logs stay out of this process's stdout (--json)
        ray.init(address=address or None, log_to_driver=False)
    try:
        task = ray.remote(fn)
        refs = [task.remote(item) for item in items]
        index = {ref: k for k, ref in enumerate(refs)}
        pending = list(refs)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            k = index[done[0]]
            if on_result is not None:
                on_result(k, ray.get(done[0]))
        return ray.get(refs)  # in item order
    finally:
        if started:
            ray.shutdown()
