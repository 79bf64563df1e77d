"""Exactness against cKDTree on random and degenerate sets, float32 and float64, every backend."""

import math

import numpy as np
import pytest

import rthdist
from conftest import check_result, directed_reference


def random_sets(rng, dtype, n=3000, m=2000):
    return rng.random((n, 3)).astype(dtype), (rng.random((m, 3)) * 1.3 - 0.1).astype(dtype)


def degenerate_cases(rng, dtype):
    line = np.zeros((500, 3))
    line[:, 0] = np.linspace(0, 1, 500)
    plane = np.column_stack([rng.random(800), rng.random(800), np.zeros(800)])
    cluster = np.vstack([rng.random((400, 3)) * 1e-3, [[5.0, 5.0, 5.0]]])
    utm = np.column_stack([5.12e5 + rng.random(600) * 200, 5.4e6 + rng.random(600) * 200, rng.random(600) * 30])
    cases = {
        "one-point-each": (np.array([[0.0, 0.0, 0.0]]), np.array([[1.0, 2.0, 2.0]])),
        "one-vs-many": (np.array([[0.5, 0.5, 0.5]]), rng.random((300, 3))),
        "identical": (plane, plane.copy()),
        "duplicates": (np.repeat(rng.random((20, 3)), 30, axis=0), rng.random((50, 3))),
        "all-same-point": (np.ones((100, 3)), np.ones((70, 3))),
        "collinear": (line, line[::3] + [0.0, 0.01, 0.0]),
        "coplanar": (plane, plane[:200] + [0.0, 0.0, 0.05]),
        "cluster-and-outlier": (cluster, rng.random((300, 3)) * 1e-3),
        "far-apart": (rng.random((200, 3)), rng.random((150, 3)) + 1e4),
        "negative": (rng.random((400, 3)) - 10.0, rng.random((300, 3)) - 9.5),
    }
    if dtype == np.float64:
        cases["utm"] = (utm, utm[::4] + [0.01, -0.02, 0.005])
    return {k: (np.asarray(a, dtype=dtype), np.asarray(b, dtype=dtype)) for k, (a, b) in cases.items()}


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_random_sets(backend, rng, dtype):
    a, b = random_sets(rng, dtype)
    r = rthdist.hausdorff(a, b, backend=backend)
    assert r.backend == backend
    check_result(r, a, b)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_directed(backend, rng, dtype):
    a, b = random_sets(rng, dtype, 1500, 900)
    r = rthdist.hausdorff(a, b, directed=True, backend=backend)
    assert r.directed and r.b_to_a is None
    check_result(r, a, b, directed=True)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_degenerate_sets(backend, rng, dtype):
    for name, (a, b) in degenerate_cases(rng, dtype).items():
        r = rthdist.hausdorff(a, b, backend=backend)
        try:
            check_result(r, a, b)
        except AssertionError as e:
            raise AssertionError(f"case {name}: {e}") from e


@pytest.mark.parametrize("bits", [1, 4, 8])
def test_fixed_bits(backend, rng, bits):
    a, b = random_sets(rng, np.float32, 1000, 800)
    r = rthdist.hausdorff(a, b, backend=backend, bits=bits)
    assert r.counters["a_to_b"]["bits"] == bits
    check_result(r, a, b)


def test_per_point_matches_ckdtree(backend, rng):
    a, b = random_sets(rng, np.float64, 1200, 700)
    r = rthdist.hausdorff(a, b, backend=backend, per_point=True)
    check_result(r, a, b)
    _, da = directed_reference(a, b)
    _, db = directed_reference(b, a)
    np.testing.assert_allclose(r.a_distances, da, rtol=0, atol=1e-9)
    np.testing.assert_allclose(r.b_distances, db, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(a - b[r.a_nearest], axis=1), r.a_distances, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(b - a[r.b_nearest], axis=1), r.b_distances, rtol=0, atol=1e-12)
    assert r.a_distances.dtype == np.float64 and r.a_nearest.dtype == np.uint32
    assert not r.a_distances.flags.writeable


def test_auto_backend_and_device(rng):
    a, b = random_sets(rng, np.float32, 500, 400)
    r = rthdist.hausdorff(a, b)
    assert r.backend in ("cpu", "ray-query", "rt-pipeline")
    check_result(r, a, b)
    devices = rthdist.list_devices()
    usable = [d for d in devices if d["ray_query"]]
    assert usable, f"no Vulkan device with ray queries: {devices}"
    r = rthdist.hausdorff(a, b, backend="ray-query", device=usable[0]["index"])
    assert r.device == usable[0]["name"]
    check_result(r, a, b)


def _nearest_double(q, t):
    """Every query's nearest distance and index in double, the smallest index on a tie, as the library
    measures it (sqrt(dx*dx + dy*dy + dz*dz))."""
    best = np.full(len(q), np.inf)
    index = np.zeros(len(q), dtype=np.int64)
    for k in range(len(t)):
        d = q - t[k]
        dist = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
        better = dist < best
        best[better] = dist[better]
        index[better] = k
    return best, index


def test_per_point_exact_for_doubles_beside_far_strays(backend):
    """Double points in two 1 mm cubes kilometres apart at UTM coordinates (no core of all but a few
    points to narrow the search to): the float search's pairs are often not the nearest (e ~ 2^-20 of
    the frame), so the exact pass mends them; every entry equals the brute force in double (README
    "Per-point distances")."""
    at = np.array([512345.125, 5412345.5, 100.0])
    r1, r2 = np.random.default_rng(81), np.random.default_rng(82)
    a = np.vstack([at + r1.random((750, 3)) * 1e-3, at + [2500.0, -2500.0, 1250.0] + r1.random((750, 3)) * 1e-3])
    b = np.vstack([at + r2.random((500, 3)) * 1e-3, at + [3100.0, -3100.0, 1550.0] + r2.random((500, 3)) * 1e-3])
    r = rthdist.hausdorff(a, b, per_point=True, backend=backend)
    for got_d, got_i, (want_d, want_i), key in (
        (r.a_distances, r.a_nearest, _nearest_double(a, b), "a_to_b"),
        (r.b_distances, r.b_nearest, _nearest_double(b, a), "b_to_a"),
    ):
        np.testing.assert_array_equal(got_d, want_d)
        np.testing.assert_array_equal(got_i, want_i)
        assert r.counters[key]["per_point_mended"] > 0


def test_per_point_searches_the_clusters_of_strays_of_their_own(backend):
    """A double cluster beside a km stray in each set: per point, the clusters are searched together in
    their own frame (narrowed targets), the strays against every target; every entry is exact."""
    at = np.array([512345.125, 5412345.5, 100.0])
    r1, r2 = np.random.default_rng(83), np.random.default_rng(84)
    a = np.vstack([at + r1.random((1500, 3)) * 1e-3, at + [2500.0, -2500.0, 1250.0]])
    b = np.vstack([at + r2.random((1000, 3)) * 1e-3, at + [3100.0, -3100.0, 1550.0]])
    r = rthdist.hausdorff(a, b, per_point=True, backend=backend)
    for got_d, got_i, (want_d, want_i), key, kept in (
        (r.a_distances, r.a_nearest, _nearest_double(a, b), "a_to_b", 1000),
        (r.b_distances, r.b_nearest, _nearest_double(b, a), "b_to_a", 1500),
    ):
        np.testing.assert_array_equal(got_d, want_d)
        np.testing.assert_array_equal(got_i, want_i)
        assert r.counters[key]["narrowed_targets"] == kept


def test_statistics_of_doubles_keep_their_diagonals(backend):
    """stats()'s diagonals are those of the float64 inputs as given (they were taken from float32
    copies: two points 1 cm apart at UTM coordinates measured a diagonal of 0), and histogram() is the
    stats' histogram, a dict of its own (it was an accessor into a freed dict: reading it crashed)."""
    a = np.array([[500000.0, 5400000.0, 100.0], [500000.01, 5400000.01, 100.0]])
    b = a + [0.0, 0.0, 0.003]
    r = rthdist.hausdorff(a, b, per_point=True, backend=backend)
    s = r.stats(bins=5)

    def diagonal(p):
        d = p.max(axis=0) - p.min(axis=0)
        return float(np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]))

    assert s["diagonal_a"] == diagonal(a) > 0.0
    assert s["diagonal_b"] == diagonal(b) > 0.0
    assert s["diagonal"] == diagonal(np.vstack([a, b]))
    h = r.histogram(bins=5)
    del s
    np.testing.assert_array_equal(h["edges"], r.stats(bins=5)["histogram"]["edges"])
    assert h["a_to_b"].sum() == len(a) and h["b_to_a"].sum() == len(b)


def test_prepared_float_valued_doubles_are_exact(backend):
    """float64 arrays whose values are float32 values are searched as they are; on prepared sets too
    their per-point entries are the brute force's in double (they were the float pairs: 13 entries of
    a differential campaign off, e.g. 5422039.905629439 for 5422039.870868671)."""
    a = np.array([[502598.625, 5398696.0, 1155.53076171875], [500000.125, 5400000.5, 100.78900146484375]])
    b = np.array([[0.375, 0.75, 0.125], [0.75, 0.75, 0.125]])
    want_d, want_i = _nearest_double(a, b)
    with rthdist.Engine(backend) as engine:
        pa, pb = engine.prepare(a), engine.prepare(b)
        for r in (engine.hausdorff(pa, pb, per_point=True), engine.hausdorff(pa, b, per_point=True),
                  engine.hausdorff_many([pa, pb], [(0, 1)], per_point=True)[0]):
            np.testing.assert_array_equal(r.a_distances, want_d)
            np.testing.assert_array_equal(r.a_nearest, want_i)


@pytest.mark.parametrize(
    "bad", [(0.0, math.inf), (-math.inf, 1.0), (math.nan, 1.0), (0.0, math.nan), (0.5, 0.5), (0.5, 0.1),
            (0.0, 0.0)]
)
def test_histogram_range_must_be_finite_and_non_empty(bad):
    """stats() and histogram() refuse a non-finite or empty range with a ValueError naming it, as every
    other option (range=(0, inf) gave edges [nan, inf, ...] and every count in bin 0)."""
    rng = np.random.default_rng(7)
    r = rthdist.hausdorff(rng.random((50, 3)), rng.random((40, 3)), per_point=True, backend="cpu")
    with pytest.raises(ValueError, match=r"^range: expected finite \(lo, hi\) with lo < hi"):
        r.histogram(bins=4, range=bad)
    with pytest.raises(ValueError, match=r"^range: "):
        r.stats(bins=4, range=bad)
    h = r.histogram(bins=4, range=(0.0, 0.5))
    np.testing.assert_array_equal(h["edges"], [0.0, 0.125, 0.25, 0.375, 0.5])
    assert h["a_to_b"].sum() + h["below"]["a_to_b"] + h["above"]["a_to_b"] == 50
