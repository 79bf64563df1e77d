"""pytest setup for the rthdist Python package (tests/python, docs/python.md).

The package under test is the installed one (tools/test.sh installs it into
build-python/venv). BACKENDS are every backend: on CI the Vulkan ones run on
Mesa's lavapipe, and a missing device is a failure (DeviceError), never a skip.
The oracle is SciPy's cKDTree over the inputs converted to float64.
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

BACKENDS = ["cpu", "ray-query", "rt-pipeline"]
SEED = 20250612


def pytest_report_header(config):
    import rthdist

    return f"rthdist {rthdist.__version__} from {rthdist.__file__}; seed {SEED}"


@pytest.fixture(params=BACKENDS)
def backend(request):
    return request.param


@pytest.fixture
def rng():
    return np.random.default_rng(SEED)


def directed_reference(q, t):
    """(h(Q,T), per-point distances of Q to T) in double: the brute-force truth."""
    d, _ = cKDTree(np.asarray(t, dtype=np.float64)[:, :3]).query(np.asarray(q, dtype=np.float64)[:, :3])
    return float(d.max()), d


def tolerance(a, b, h):
    """The library's contract: 1e-6 of the union's bbox diagonal (+ float ulps of H for far sets)."""
    u = np.vstack([np.asarray(a, dtype=np.float64)[:, :3], np.asarray(b, dtype=np.float64)[:, :3]])
    diag = float(np.linalg.norm(u.max(axis=0) - u.min(axis=0)))
    return 1e-6 * diag + 8 * 2.0**-24 * h + 1e-300


def check_result(r, a, b, directed=False):
    """r against cKDTree, with its witness pairs realizing the reported distances."""
    a64 = np.asarray(a, dtype=np.float64)[:, :3]
    b64 = np.asarray(b, dtype=np.float64)[:, :3]
    hab, _ = directed_reference(a64, b64)
    tol = tolerance(a64, b64, hab)
    assert abs(r.a_to_b.distance - hab) <= tol, (r.a_to_b.distance, hab, tol)
    qi, ti = r.a_to_b.indices
    assert abs(np.linalg.norm(a64[qi] - b64[ti]) - r.a_to_b.distance) <= tol
    np.testing.assert_array_equal(r.a_to_b.query_point, a64[qi])
    np.testing.assert_array_equal(r.a_to_b.target_point, b64[ti])
    # The certificate (issue 32): confirmed, and its witness is the result's.
    for d in (r.a_to_b,) if directed else (r.a_to_b, r.b_to_a):
        c = d.certificate
        assert c["confirmed"], c
        assert (c["query"], c["nearest"]) == d.indices
        assert c["distance"] == d.distance
    assert r.certificate["a_to_b"] == r.a_to_b.certificate
    if directed:
        assert r.b_to_a is None
        assert abs(r.distance - hab) <= tol
        return
    hba, _ = directed_reference(b64, a64)
    tol = tolerance(a64, b64, max(hab, hba))
    assert abs(r.b_to_a.distance - hba) <= tol, (r.b_to_a.distance, hba, tol)
    qi, ti = r.b_to_a.indices
    assert abs(np.linalg.norm(b64[qi] - a64[ti]) - r.b_to_a.distance) <= tol
    assert abs(r.distance - max(hab, hba)) <= tol
