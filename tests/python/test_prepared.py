"""Engine.prepare / PreparedSet / hausdorff_many, and cancellation by Ctrl-C (SIGINT)."""

import os
import signal

import numpy as np
import pytest

import rthdist
from conftest import check_result


def test_prepared_sets(backend, rng):
    a = rng.random((3000, 3))
    b = (rng.random((2000, 3)) * 1.2).astype(np.float32)
    c = rng.random((1000, 3)) + 0.3
    with rthdist.Engine(backend) as engine:
        pa = engine.prepare(a)
        pb = engine.prepare(b, origin=pa.origin)
        pc = engine.prepare(c, bits=4, origin=pa.origin)
        assert len(pa) == 3000 and pc.bits == 4 and pa.points is a
        check_result(engine.hausdorff(pa, pb), a, b)
        check_result(engine.hausdorff(pb, pa, directed=True), b, a, directed=True)
        check_result(engine.hausdorff(pa, c), a, c)  # array against a prepared set
        check_result(engine.hausdorff(b, pc), b, c)
        r = engine.hausdorff(pa, pc, per_point=True)
        check_result(r, a, c)
        assert r.a_distances.shape == (3000,) and r.hd95 <= r.distance
        many = engine.hausdorff_many([pa, pb, pc], [(0, 1), (1, 2), (2, 0)])
        for res, (x, y) in zip(many, [(a, b), (b, c), (c, a)]):
            check_result(res, x, y)
        with rthdist.Engine("cpu") as other:
            with pytest.raises(ValueError, match="another Engine"):
                other.hausdorff(pa, a)
        with pytest.raises(ValueError, match="index"):
            engine.hausdorff_many([pa], [(0, 1)])
        with pytest.raises(ValueError):
            engine.prepare(np.zeros((0, 3)))
    # A prepared set outlives its Engine (it keeps the device alive).
    assert pa.size == 3000


def sigint_at_first_progress(engine, a, b):
    """Ctrl-C as the user would press it: SIGINT during the call, from the call's own thread."""
    seen = []

    def progress(stage, fraction):
        seen.append(fraction)
        if len(seen) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        engine.hausdorff(a, b, per_point=True, progress=progress)
    return seen


def test_ctrl_c_cancels_the_call(backend):
    rng = np.random.default_rng(3)
    a = rng.random((60000, 3))
    b = rng.random((60000, 3)) + [0.3, 0.0, 0.0]
    with rthdist.Engine(backend) as engine:
        seen = sigint_at_first_progress(engine, a, b)
        assert max(seen) < 1.0, f"the call ran to the end: {seen}"
        # The Engine stays usable after a cancelled call.
        check_result(engine.hausdorff(a[:2000], b[:2000]), a[:2000], b[:2000])
