"""One core for the checker benchmark: every thread of the process on one CPU, the thread pools
capped at one thread, and a count of the threads that did work.

`sched_setaffinity(0, ...)` pins only the calling thread on Linux, so a pool started earlier
(numpy's OpenBLAS starts one worker per CPU when numpy is imported) kept running on the other
CPU: `one_core` pins every thread the process has (``/proc/self/task``), caps OpenBLAS (found
among the loaded libraries, called through ctypes, as threadpoolctl does) and, when torch is
loaded, torch's intra-op pool (`tamp.sweep.torch_threads`) at one thread, and restores all of
it afterwards. `thread_times` reads each thread's CPU time, so a benchmark can count how many
threads worked while it timed something (`busy_threads`).
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path

TASKS = Path("/proc/self/task")
# (get, set) thread-count functions of the OpenBLAS builds numpy and scipy ship
BLAS_CALLS = (
    ("openblas_get_num_threads", "openblas_set_num_threads"),
    ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
    ("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
    ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
)


def thread_times() -> dict[int, float]:
    """CPU seconds each thread of this process has run ({thread id: s}), from the scheduler's
    nanosecond count (``schedstat``) or else from ``stat``'s clock ticks; {} where the
    platform has no ``/proc``."""
    out = {}
    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    for task in TASKS.glob("*") if TASKS.is_dir() else ():
        try:
            sched = task / "schedstat"
            if sched.exists():
                out[int(task.name)] = int(sched.read_text().split()[0]) / 1e9
            else:
                fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
                out[int(task.name)] = (int(fields[11]) + int(fields[12])) / tick
        except (OSError, ValueError, IndexError):  # the thread ended meanwhile
            continue
    return out


def busy_threads(before: dict[int, float], after: dict[int, float]) -> int | None:
    """How many of the threads listed ``after`` ran at all since ``before`` (two `thread_times`
    readings; a thread asleep throughout adds nothing), None where ``after`` is empty (no
    ``/proc``). A thread that ended in between is not listed."""
    if not after:
        return None
    return sum(after[t] > before.get(t, 0.0) for t in after)


def blas_pools() -> list[tuple[ctypes.CDLL, str, str]]:
    """The OpenBLAS libraries loaded in this process, each with its (get, set) function names
    (`BLAS_CALLS`); [] where none is loaded or there is no ``/proc/self/maps``."""
    try:
        maps = Path("/proc/self/maps").read_text().splitlines()
    except OSError:
        return []
    paths = sorted({line.split()[-1] for line in maps if "openblas" in line.rsplit("/", 1)[-1]})
    out = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for get, set_ in BLAS_CALLS:
            if hasattr(lib, get) and hasattr(lib, set_):
                out.append((lib, get, set_))
                break
    return out


@contextmanager
def blas_threads(n: int) -> Iterator[list[int]]:
    """The block with every loaded OpenBLAS capped at ``n`` threads; yields their previous
    counts and restores them afterwards."""
    pools = blas_pools()
    before = [int(getattr(lib, get)()) for lib, get, _ in pools]
    for lib, _, set_ in pools:
        getattr(lib, set_)(n)
    try:
        yield before
    finally:
        for (lib, _, set_), count in zip(pools, before, strict=True):
            getattr(lib, set_)(count)


@contextmanager
def pinned(cpu: int) -> Iterator[None]:
    """Every thread of the process on ``cpu`` for the block (threads started inside inherit
    it from the thread that starts them), each put back on its own CPUs afterwards."""
    before = {t: os.sched_getaffinity(t) for t in thread_times() or {0: 0.0}}
    for tid in before:
        try:
            os.sched_setaffinity(tid, {cpu})
        except OSError:  # ended meanwhile
            continue
    try:
        yield
    finally:
        for tid, cpus in before.items():
            try:
                os.sched_setaffinity(tid, cpus)
            except OSError:
                continue


@contextmanager
def one_core() -> Iterator[int | None]:
    """The process on one of its CPUs (the lowest it may use) with one thread per pool (see
    the module docstring); yields that CPU, or None where the platform cannot pin (the pools
    are capped all the same)."""
    with ExitStack() as stack:
        stack.enter_context(blas_threads(1))
        if "torch" in sys.modules:  # never imported for this
            from tamp.sweep import torch_threads

            stack.enter_context(torch_threads(1))
        if not hasattr(os, "sched_setaffinity"):
            yield None
            return
        cpu = min(os.sched_getaffinity(0))
        stack.enter_context(pinned(cpu))
        yield cpu
