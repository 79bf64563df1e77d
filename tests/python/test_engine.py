"""rthdist.Engine: kept devices, per-call settings, closing, and several Python threads."""

import threading

import numpy as np
import pytest

import rthdist
from conftest import check_result


def test_engine_reuse_and_call_settings(backend, rng):
    a = rng.random((1500, 3)).astype(np.float32)
    b = rng.random((1000, 3))
    with rthdist.Engine(backend) as engine:
        assert engine.backend == backend and engine.device and not engine.closed
        assert backend in repr(engine)
        r1 = engine.hausdorff(a, b)
        check_result(r1, a, b)
        r2 = engine.hausdorff(a, b, directed=True, bits=5)
        check_result(r2, a, b, directed=True)
        assert r2.counters["a_to_b"]["bits"] == 5
        r3 = engine.hausdorff(b, a, per_point=True)
        check_result(r3, b, a)
        assert r3.a_distances.shape == (len(b),)
        assert r1.timings["setup"] >= 0.0
    assert engine.closed
    with pytest.raises(ValueError, match="closed"):
        engine.hausdorff(a, b)
    engine.close()  # idempotent


def test_memory_budget_splits_with_the_same_result(backend, rng):
    a = rng.random((6000, 3)).astype(np.float32)
    b = rng.random((5000, 3)).astype(np.float32) + 0.25
    with rthdist.Engine(backend) as whole, rthdist.Engine(backend, memory_budget=2000 * 128) as split:
        want = whole.hausdorff(a, b)
        got = split.hausdorff(a, b)
    check_result(got, a, b)
    assert got.distance == pytest.approx(want.distance, rel=1e-6)
    for d in ("a_to_b", "b_to_a"):
        assert want.counters[d]["query_chunks"] * want.counters[d]["target_tiles"] == 1
        assert got.counters[d]["query_chunks"] > 1 and got.counters[d]["target_tiles"] > 1
    with pytest.raises(ValueError, match="memory_budget"):
        rthdist.Engine("cpu", memory_budget=-1)


def test_two_devices_give_the_one_device_result(backend, rng):
    a = rng.random((3000, 3)).astype(np.float32)
    b = rng.random((2500, 3)) + 0.25
    if backend == "cpu":
        with pytest.raises(ValueError, match="GPU backend"):
            rthdist.Engine(backend, devices=[0, 0])
        return
    # Out of core (a budget of 2000 points per call), so that both devices take chunks.
    with rthdist.Engine(backend) as one, rthdist.Engine(backend, devices=[0, 0], memory_budget=2000 * 128) as two:
        want = one.hausdorff(a, b)
        got = two.hausdorff(a, b)
        assert " + " in two.device
    check_result(got, a, b)
    assert got.distance == pytest.approx(want.distance, rel=1e-6)
    for d in ("a_to_b", "b_to_a"):
        assert got.counters[d]["query_chunks"] >= 2
    with pytest.raises(ValueError, match="devices"):
        rthdist.Engine(backend, devices=[-1])


def test_engine_errors():
    with pytest.raises(ValueError):
        rthdist.Engine("nope")
    with pytest.raises(rthdist.DeviceError):
        rthdist.Engine("rt-pipeline", device=1000)
    with rthdist.Engine("cpu") as engine:
        with pytest.raises(ValueError):
            engine.hausdorff(np.zeros((0, 3)), np.zeros((3, 3)))
        assert engine.hausdorff(np.zeros((1, 3)), np.ones((1, 3))).distance == pytest.approx(3**0.5)


def run_threads(target, count):
    errors = []

    def guarded(i):
        try:
            target(i)
        except BaseException as e:  # noqa: BLE001 - reported by the main thread
            errors.append(e)

    threads = [threading.Thread(target=guarded, args=(i,)) for i in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]


def test_separate_engines_in_threads(backend):
    sets = [(np.random.default_rng(i).random((2000, 3)), np.random.default_rng(100 + i).random((1500, 3)))
            for i in range(4)]
    expected = [rthdist.hausdorff(a, b, backend="cpu").distance for a, b in sets]
    results = [None] * 4

    def work(i):
        with rthdist.Engine(backend, threads=1) as engine:
            for _ in range(3):
                results[i] = engine.hausdorff(*sets[i]).distance

    run_threads(work, 4)
    assert results == expected


def test_one_engine_shared_by_threads_is_serialized(backend, rng):
    a = rng.random((1500, 3))
    b = rng.random((1000, 3))
    with rthdist.Engine(backend) as engine:
        expected = engine.hausdorff(a, b).distance
        got = []
        run_threads(lambda i: got.extend(engine.hausdorff(a, b).distance for _ in range(3)), 3)
    assert got == [expected] * 9
