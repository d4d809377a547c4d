"""`tamp.bench.collision.threads`: the checker benchmark's one core, and the sphere checker
working on one thread whatever numpy's OpenBLAS pool holds."""

from __future__ import annotations

import os
import sys
import threading
import time

import numpy as np
import pytest

from motion.sphere_check.collision import CHUNK, SphereCollision
from tamp.bench.collision import scenes
from tamp.bench.collision.threads import (
    blas_pools,
    blas_threads,
    busy_threads,
    one_core,
    thread_times,
)

linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")


@pytest.fixture(scope="module")
def shelf():
    boxes = scenes.scene_boxes("shelf", 0)
    model = SphereCollision(margin=0.01)
    model.set_boxes(boxes)
    near = scenes.near(boxes, 400, seed=1, margin=0.01)
    q = np.concatenate([scenes.uniform(2 * CHUNK, seed=2), near])  # spans three chunks
    return model, q


def _spin(seconds: float, go: threading.Event, done: threading.Event) -> None:
    """Wait for ``go``, run ``seconds`` of this thread's own CPU time, set ``done`` and wait
    for ``go`` to be cleared (a thread that has ended is no longer listed)."""
    go.wait()
    start = time.thread_time()
    while time.thread_time() - start < seconds:
        pass
    done.set()
    while go.is_set():
        time.sleep(0.001)


@linux
@pytest.mark.parametrize("spin", [True, False])
def test_busy_threads_counts_a_thread_that_runs_and_not_one_that_waits(spin):
    go, done = threading.Event(), threading.Event()
    worker = threading.Thread(target=_spin, args=(0.02, go, done))
    worker.start()
    time.sleep(0.01)  # the worker waits for go
    me = threading.get_native_id()  # the main thread reads /proc: it runs
    before = thread_times()
    if spin:
        go.set()
        done.wait()
    else:
        time.sleep(0.02)
    after = {t: s for t, s in thread_times().items() if t != me}  # the worker still listed
    go.set()
    go.clear()
    worker.join()
    assert busy_threads(before, after) == (1 if spin else 0)


@linux
def test_one_core_pins_every_thread_caps_openblas_and_restores_both():
    pools = blas_pools()
    assert pools  # numpy's OpenBLAS is loaded
    counts = [getattr(lib, get)() for lib, get, _ in pools]
    cpus = os.sched_getaffinity(0)
    with one_core() as cpu:
        assert cpu == min(cpus)
        assert all(os.sched_getaffinity(t) == {cpu} for t in thread_times())
        assert all(getattr(lib, get)() == 1 for lib, get, _ in pools)
    assert os.sched_getaffinity(0) == cpus
    assert [getattr(lib, get)() for lib, get, _ in pools] == counts


def test_the_verdicts_do_not_change_under_the_thread_limit(shelf):
    model, q = shelf
    free = model.valid_batch(q)
    assert 0 < free.sum() < len(q)
    with one_core():
        assert np.array_equal(model.valid_batch(q), free)
    with blas_threads(1):
        assert np.array_equal(model.valid_batch(q), free)


@linux
def test_a_batch_check_works_on_one_thread_with_the_openblas_pool_left_as_it_is(shelf):
    """No BLAS call in the checker's path: the OpenBLAS workers numpy starts (one per CPU
    unless OPENBLAS_NUM_THREADS says otherwise) stay idle, with no cap and no pinning. The
    checker's old 26-DOP matrix product ran on two threads here on two CPUs."""
    model, q = shelf
    qs = np.resize(q, (20_000, q.shape[1]))
    model.valid_batch(qs)
    before = thread_times()
    model.valid_batch(qs)
    assert busy_threads(before, thread_times()) == 1
