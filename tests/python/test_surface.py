"""Triangle surfaces from Python (rthdist.hausdorff_to_surface,
surface_hausdorff, evaluate): NumPy vertex + face arrays of every accepted
dtype; point-to-surface values known in closed form (points over a flat
square: |z|); the per-point arrays (distances, triangles, surface points,
barycentrics) against a NumPy brute force over every triangle with its own
point-triangle rule, and refused on a GPU backend; surface-to-surface
bounds bracketing known values within the tolerance; the evaluation summary
against an independent NumPy brute force on a pair of a few thousand points
(fixed seed, conftest.SEED); bad faces and thresholds as ValueError naming
them."""

import numpy as np
import pytest

import rthdist

SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


@pytest.mark.parametrize("vdtype", [np.float32, np.float64])
@pytest.mark.parametrize("fdtype", [np.int32, np.int64, np.uint32])
def test_points_over_a_square_are_their_height(rng, vdtype, fdtype):
    pts = np.column_stack([rng.uniform(0, 1, 500), rng.uniform(0, 1, 500), rng.uniform(-1, 1, 500)])
    r = rthdist.hausdorff_to_surface(pts, SQUARE_V.astype(vdtype), SQUARE_F.astype(fdtype), per_point=True)
    assert r["hausdorff"] == np.abs(pts[:, 2]).max()
    assert r["query_index"] == int(np.argmax(np.abs(pts[:, 2])))
    np.testing.assert_array_equal(r["distances"], np.abs(pts[:, 2]))
    np.testing.assert_array_equal(r["surface_points"], np.column_stack([pts[:, 0], pts[:, 1], np.zeros(500)]))
    q = pts[r["query_index"]]
    assert r["surface_point"] == (q[0], q[1], 0.0)
    assert r["backend"] == "cpu"


def _closest_on_triangles(p, a, b, c):
    """Closest points of triangles (a, b, c) to points p, row by row: the
    Voronoi-region walk of Ericson's Real-Time Collision Detection 5.1.5 in
    NumPy float64 (an independent rule; degenerate triangles are not drawn
    here). Returns (distance, closest point, barycentric)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp = p - b
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    cp = p - c
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    n = len(p)
    bary = np.zeros((n, 3))
    done = np.zeros(n, dtype=bool)

    def take(mask, w0, w1, w2):
        m = mask & ~done
        bary[m] = np.column_stack([w0, w1, w2])[m]
        done[m] = True

    one, zero = np.ones(n), np.zeros(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        take((d1 <= 0) & (d2 <= 0), one, zero, zero)
        take((d3 >= 0) & (d4 <= d3), zero, one, zero)
        v = d1 / (d1 - d3)
        take((vc <= 0) & (d1 >= 0) & (d3 <= 0), 1 - v, v, zero)
        take((d6 >= 0) & (d5 <= d6), zero, zero, one)
        w = d2 / (d2 - d6)
        take((vb <= 0) & (d2 >= 0) & (d6 <= 0), 1 - w, zero, w)
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        take((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0), zero, 1 - w, w)
        denom = va + vb + vc
        v, w = vb / denom, vc / denom
        take(np.ones(n, dtype=bool), 1 - v - w, v, w)
    q = bary[:, :1] * a + bary[:, 1:2] * b + bary[:, 2:] * c
    return np.linalg.norm(p - q, axis=1), q, bary


def test_per_point_arrays_match_a_numpy_brute_force(rng):
    """Every point's distance, triangle, closest point and barycentric
    coordinates against a brute force over all triangles in NumPy (its own
    point-triangle rule): equal to rounding; the triangle is the brute
    force's or one within rounding of it (a near tie)."""
    tri = rng.uniform(-1, 1, (60, 3))
    v = np.concatenate([tri + rng.normal(0, 0.4, (60, 3)) for _ in range(3)])
    f = np.arange(180).reshape(3, 60).T.astype(np.int64)
    pts = rng.uniform(-1.5, 1.5, (400, 3))
    r = rthdist.hausdorff_to_surface(pts, v, f, per_point=True)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    dist = np.empty((len(pts), len(f)))
    for t in range(len(f)):
        dist[:, t] = _closest_on_triangles(pts, np.broadcast_to(a[t], pts.shape), np.broadcast_to(b[t], pts.shape),
                                           np.broadcast_to(c[t], pts.shape))[0]
    want = dist.min(axis=1)
    assert r["distances"].shape == (400,) and r["distances"].dtype == np.float64
    assert r["triangles"].shape == (400,) and r["triangles"].dtype == np.uint32
    assert r["surface_points"].shape == (400, 3) and r["barycentrics"].shape == (400, 3)
    for key in ("distances", "triangles", "surface_points", "barycentrics"):
        assert not r[key].flags.writeable, key
    np.testing.assert_allclose(r["distances"], want, rtol=1e-12, atol=1e-15)
    t = r["triangles"].astype(np.int64)
    assert (dist[np.arange(len(pts)), t] <= want + 1e-12).all()
    assert (t == dist.argmin(axis=1)).mean() > 0.99
    d_t, q_t, b_t = _closest_on_triangles(pts, a[t], b[t], c[t])
    np.testing.assert_allclose(r["surface_points"], q_t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r["barycentrics"], b_t, rtol=0, atol=1e-9)
    bary = r["barycentrics"]
    assert (bary >= 0).all() and np.allclose(bary.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bary[:, :1] * a[t] + bary[:, 1:2] * b[t] + bary[:, 2:] * c[t], r["surface_points"],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(pts - r["surface_points"], axis=1), r["distances"], rtol=1e-12)
    i = r["query_index"]
    assert r["hausdorff"] == r["distances"].max() == r["distances"][i]
    assert r["triangle"] == r["triangles"][i]
    assert r["surface_point"] == tuple(r["surface_points"][i])
    assert r["barycentric"] == tuple(r["barycentrics"][i])


@pytest.mark.parametrize("gpu", ["ray-query", "rt-pipeline"])
def test_per_point_on_a_gpu_backend_is_within_its_tolerance(gpu):
    rng = np.random.default_rng(3483)
    pts = rng.uniform([-0.5, -0.5, -1.0], [1.5, 1.5, 1.0], size=(400, 3))
    cpu = rthdist.hausdorff_to_surface(pts, SQUARE_V, SQUARE_F, per_point=True, backend="cpu")
    r = rthdist.hausdorff_to_surface(pts, SQUARE_V, SQUARE_F, per_point=True, backend=gpu)
    assert r["backend"] == gpu and cpu["tolerance"] == 0.0
    assert 0.0 < r["tolerance"] < 1e-3
    assert r["hausdorff"] == cpu["hausdorff"] and r["query_index"] == cpu["query_index"]
    assert (r["distances"] >= cpu["distances"]).all()
    assert (r["distances"] <= cpu["distances"] + r["tolerance"]).all()
    np.testing.assert_allclose(np.linalg.norm(pts - r["surface_points"], axis=1), r["distances"], rtol=1e-12)


@pytest.mark.parametrize("backend", ["cpu", "ray-query", "rt-pipeline"])
def test_an_engine_keeps_its_device_or_tree_for_surface_calls(backend):
    rng = np.random.default_rng(3485)
    pts = rng.uniform([-0.5, -0.5, -1.0], [1.5, 1.5, 1.0], size=(300, 3))
    with rthdist.Engine(backend=backend) as engine:
        for per_point in (False, True, True):
            r = engine.hausdorff_to_surface(pts, SQUARE_V, SQUARE_F, per_point=per_point)
            want = rthdist.hausdorff_to_surface(pts, SQUARE_V, SQUARE_F, per_point=per_point, backend=backend)
            assert r["backend"] == backend
            assert r["hausdorff"] == want["hausdorff"] and r["query_index"] == want["query_index"]
            assert r["surface_point"] == want["surface_point"]
            if per_point:
                np.testing.assert_array_equal(r["distances"], want["distances"])
                assert r["tolerance"] == want["tolerance"]
    with pytest.raises(ValueError, match="closed"):
        engine.hausdorff_to_surface(pts, SQUARE_V, SQUARE_F)


def test_triangle_and_its_offset_copy():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
    f = np.array([[0, 1, 2]], dtype=np.int32)
    r = rthdist.surface_hausdorff(v, f, v + [0, 0, 0.25], f, tolerance=1e-9)
    lower, upper = r["bounds"]
    assert lower <= 0.25 <= upper and upper - lower <= 1e-9
    assert r["a_to_b"]["distance"] == 0.25
    assert r["a_to_b"]["to_point"][2] == 0.25
    d = rthdist.surface_hausdorff(v, f, v + [0, 0, 0.25], f, directed=True)
    assert d["directed"] and d["b_to_a"] is None


@pytest.mark.parametrize("gpu", ["ray-query", "rt-pipeline"])
def test_surface_to_surface_on_a_gpu_backend(gpu):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
    f = np.array([[0, 1, 2]], dtype=np.int32)
    r = rthdist.surface_hausdorff(v, f, v + [0, 0, 0.25], f, tolerance=1e-3, backend=gpu)
    lower, upper = r["bounds"]
    assert r["backend"] == gpu
    assert lower <= 0.25 <= upper and upper - lower <= 1e-3
    assert r["a_to_b"]["distance"] == 0.25
    # Below the float search's floor (2^-14 here): a ValueError naming it.
    with pytest.raises(ValueError, match="floor 6.103515625e-05"):
        rthdist.surface_hausdorff(v, f, v + [0, 0, 0.25], f, tolerance=1e-5, backend=gpu)


def test_square_split_both_ways_is_zero():
    other = np.array([[0, 1, 3], [1, 2, 3]], dtype=np.uint32)
    r = rthdist.surface_hausdorff(SQUARE_V, SQUARE_F, SQUARE_V, other, tolerance=1e-3)
    assert r["bounds"][0] == 0.0 and r["bounds"][1] <= 1e-3


def _nearest(q, t):
    """Every row of q's distance to its nearest row of t: NumPy, in blocks."""
    out = np.empty(len(q))
    for i in range(0, len(q), 500):
        d2 = ((q[i:i + 500, None, :] - t[None, :, :]) ** 2).sum(axis=2)
        out[i:i + 500] = np.sqrt(d2.min(axis=1))
    return out


def _expected(acc, comp, taus, cap):
    def side(d):
        kept = d[d < cap] if cap > 0 else d
        return {"count": len(d), "kept": len(kept), "mean": kept.mean(), "median": np.median(kept),
                "mean_squared": (kept ** 2).mean(), "max": kept.max()}
    a, c = side(acc), side(comp)
    rows = []
    for t in taus:
        p, r = (acc < t).mean(), (comp < t).mean()
        rows.append({"threshold": t, "precision": p, "recall": r, "fscore": 2 * p * r / (p + r) if p + r else 0.0})
    return a, c, rows


@pytest.mark.parametrize("cap", [0.0, 0.08])
def test_evaluation_matches_numpy(rng, cap):
    def sphere(n, noise):
        v = rng.normal(size=(n, 3))
        return v / np.linalg.norm(v, axis=1)[:, None] * (1 + rng.uniform(-noise, noise, (n, 1)))
    recon, truth = sphere(3000, 0.05), sphere(2500, 0.0)
    truth[truth[:, 2] > 0.8] *= 1.3  # a part the reconstruction misses
    taus = [0.01, 0.05, 0.2]
    s = rthdist.evaluate(recon, truth, taus, cap=cap, backend="cpu")
    a, c, rows = _expected(_nearest(recon, truth), _nearest(truth, recon), taus, cap)
    for got, want in ((s["accuracy"], a), (s["completeness"], c)):
        assert got["count"] == want["count"] and got["kept"] == want["kept"]
        for key in ("mean", "median", "mean_squared", "max"):
            assert got[key] == pytest.approx(want[key], rel=1e-12), key
    assert s["chamfer"]["mean_of_means"] == pytest.approx((a["mean"] + c["mean"]) / 2, rel=1e-12)
    assert s["chamfer"]["sum_of_means"] == pytest.approx(a["mean"] + c["mean"], rel=1e-12)
    assert s["chamfer"]["sum_of_mean_squares"] == pytest.approx(a["mean_squared"] + c["mean_squared"], rel=1e-12)
    for got, want in zip(s["thresholds"], rows):
        assert got == pytest.approx(want, rel=1e-12)
    assert s["cap"] == (cap if cap > 0 else None)
    if cap > 0:
        assert s["completeness"]["kept"] < s["completeness"]["count"]


def test_evaluation_to_a_surface():
    recon = np.array([[0.5, 0.5, 1.0], [0.0, 0.0, 0.0]])
    s = rthdist.evaluate(recon, SQUARE_V, 0.5, faces=SQUARE_F)
    assert s["accuracy"]["mean"] == 0.5 and s["accuracy"]["max"] == 1.0
    assert s["completeness"]["count"] == 4 and s["completeness"]["median"] == 1.0
    assert s["thresholds"][0]["recall"] == 0.25


def test_bad_faces_and_thresholds_are_value_errors():
    with pytest.raises(ValueError, match="face 1: vertex index 4 out of range"):
        rthdist.hausdorff_to_surface(SQUARE_V, SQUARE_V, np.array([[0, 1, 2], [0, 2, 4]]))
    with pytest.raises(ValueError, match="face 0: vertex index -1"):
        rthdist.hausdorff_to_surface(SQUARE_V, SQUARE_V, np.array([[0, 1, -1]], dtype=np.int32))
    with pytest.raises(ValueError, match="faces"):
        rthdist.hausdorff_to_surface(SQUARE_V, SQUARE_V, SQUARE_F.astype(np.float32))
    with pytest.raises(ValueError, match=r"\(F, 3\)"):
        rthdist.surface_hausdorff(SQUARE_V, SQUARE_F.ravel(), SQUARE_V, SQUARE_F)
    with pytest.raises(ValueError, match="evaluation threshold 0"):
        rthdist.evaluate(SQUARE_V, SQUARE_V, [0.0])
    with pytest.raises(ValueError, match="tolerance"):
        rthdist.surface_hausdorff(SQUARE_V, SQUARE_F, SQUARE_V, SQUARE_F, tolerance=-1.0)
