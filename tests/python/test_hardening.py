"""Issue 36 from Python: coordinates past the float search's limits are a
ValueError naming the set, the point and the limit (they crashed the process
or returned a wrong value); a prepared set's origin must be finite; another
thread's writes into the input arrays during a call (the GIL is released)
cannot crash it (the call reads its own copy: docs/python.md, "Threads")."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import rthdist


def test_past_float_range_after_the_shift_is_a_value_error(backend):
    far = np.array([[1e308, 0, 0], [0.1, 0, 0]])
    near = np.array([[0.0, 0, 0], [1, 0, 0]])
    with pytest.raises(ValueError, match=r"point set A: point 0 has x = 1e\+308.*3\.40282347e\+38"):
        rthdist.hausdorff(far, near, backend=backend)
    with pytest.raises(ValueError, match=r"float32's largest value"):
        rthdist.hausdorff(far, far, backend=backend)
    with rthdist.Engine(backend) as engine:
        with pytest.raises(ValueError, match=r"point set B: point 0 has x = 1e\+308"):
            engine.hausdorff(near, far)
        with pytest.raises(ValueError, match=r"point set to prepare"):
            engine.prepare(far)


def test_far_but_small_is_exact(backend):
    a = np.array([[1e300, 0, 0], [1e300, 1, 0]])
    b = np.array([[1e300, 4, 0]])
    assert rthdist.hausdorff(a, b, backend=backend).distance == 4.0


def test_below_float_normals_is_a_value_error(backend):
    tiny = np.array([[1e-160, 0, 0], [0, 2e-160, 0]])
    zero = np.zeros((1, 3))
    with pytest.raises(ValueError, match=r"point sets A and B: .*1\.17549435e-38"):
        rthdist.hausdorff(tiny, zero, backend=backend)
    same = np.array([[1e-200, 0, 0], [1e-200, 0, 0]])
    assert rthdist.hausdorff(same, same, backend=backend).distance == 0.0


@pytest.mark.parametrize("origin", [(float("nan"), 0, 0), (0, float("inf"), 0), (0, 0, -float("inf"))])
def test_prepare_refuses_a_non_finite_origin(backend, origin):
    with rthdist.Engine(backend) as engine:
        with pytest.raises(ValueError, match=r"PrepareOptions::origin: coordinate [xyz] is"):
            engine.prepare(np.random.default_rng(1).random((10, 3)), origin=origin)


# The race in a child process: a crash there is a failed test, not a dead pytest.
_RACE = textwrap.dedent(
    """
    import sys, threading
    import numpy as np
    import rthdist

    backend, dtype = sys.argv[1], np.dtype(sys.argv[2])
    rng = np.random.default_rng(7)
    a = rng.random((8000, 3)).astype(dtype)
    b = rng.random((6000, 3)).astype(dtype)
    keep = a.copy()
    stop = False

    def writer():  # NaN, inf and huge values in and out of a, as fast as it can
        i = 0
        while not stop:
            rows = slice(i % 7500, i % 7500 + 500)
            a[rows] = (np.nan, np.inf, 1e30)[i % 3]
            a[rows] = keep[rows]
            i += 1

    t = threading.Thread(target=writer)
    t.start()
    outcomes = set()
    try:
        with rthdist.Engine(backend) as engine:
            for k in range(12):
                for call in (lambda: rthdist.hausdorff(a, b, backend=backend),
                             lambda: engine.hausdorff(a, b),
                             lambda: engine.hausdorff(engine.prepare(a), b)):
                    try:
                        h = call().distance
                        assert np.isfinite(h) and h >= 0, h
                        outcomes.add("value")
                    except ValueError as e:
                        assert "NaN or infinite" in str(e) or "point set" in str(e), e
                        outcomes.add("refused")
    finally:
        stop = True
        t.join()
    print(sorted(outcomes))
    """
)


@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_another_threads_writes_cannot_crash_a_call(backend, dtype):
    run = subprocess.run([sys.executable, "-c", _RACE, backend, dtype], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"exit {run.returncode}\n{run.stdout}\n{run.stderr}"


def test_devices_list_is_bounded(backend):
    with pytest.raises(ValueError, match=r"devices lists 17 devices; at most 16"):
        rthdist.Engine(backend, devices=[0] * 17)
