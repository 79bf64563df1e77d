"""No leaks over 1,000 calls: Python allocations (tracemalloc) and the process's RSS stay bounded."""

import gc
import sys
import tracemalloc

import numpy as np

import rthdist


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def calls(fn, n):
    for _ in range(n):
        fn()
    gc.collect()


def bounded(fn, n=1000, rss_limit=16 << 20, traced_limit=256 << 10):
    calls(fn, 100)  # warm-up: caches, allocator pools, the device's first pipelines
    tracemalloc.start()
    base_traced = tracemalloc.get_traced_memory()[0]
    base_rss = rss_bytes()
    calls(fn, n)
    traced = tracemalloc.get_traced_memory()[0] - base_traced
    tracemalloc.stop()
    grown = rss_bytes() - base_rss
    assert traced < traced_limit, f"Python allocations grew by {traced} bytes over {n} calls"
    assert grown < rss_limit, f"RSS grew by {grown} bytes over {n} calls"


def test_one_shot_cpu_calls_do_not_leak():
    rng = np.random.default_rng(7)
    a = rng.random((500, 3))
    b = rng.random((400, 3)).astype(np.float32)

    def one():
        r = rthdist.hausdorff(a, b, backend="cpu", per_point=True)
        assert r.hd95 <= r.distance
        r.a_distances.sum()

    before = (sys.getrefcount(a), sys.getrefcount(b))
    bounded(one)
    assert (sys.getrefcount(a), sys.getrefcount(b)) == before


def test_engine_calls_do_not_leak():
    rng = np.random.default_rng(8)
    a = rng.random((300, 3)).astype(np.float32)
    b = rng.random((200, 3))
    with rthdist.Engine("ray-query") as engine:
        bounded(lambda: engine.hausdorff(a, b, per_point=True).b_nearest.max())


def test_errors_do_not_leak():
    bad = np.array([[0.0, np.nan, 0.0]])

    def one():
        try:
            rthdist.hausdorff(bad, bad, backend="cpu")
        except ValueError:
            pass

    bounded(one)


def test_result_keeps_its_arrays_alive():
    a = np.random.default_rng(9).random((100, 3))
    r = rthdist.hausdorff(a, a[::-1] + 1, backend="cpu", per_point=True)
    d = r.a_distances
    del r
    gc.collect()
    assert d.shape == (100,) and np.all(d > 0)
