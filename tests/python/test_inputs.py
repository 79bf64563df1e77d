"""What hausdorff() accepts: layouts read in place or copied, other containers, and the errors."""

import numpy as np
import pytest

import rthdist
from conftest import check_result


def shares(view, base):
    return np.shares_memory(view, base)


def test_c_order_and_row_slices_are_not_copied(rng):
    a = rng.random((1000, 3))
    assert rthdist.as_points(a) is a
    wide = rng.random((1000, 5)).astype(np.float32)  # x, y, z + 2 attributes per point
    assert shares(rthdist.as_points(wide), wide) and rthdist.as_points(wide).shape == (1000, 5)
    cols = wide[:, 1:4]  # columns 1..3 of a wider C array: a byte offset and a stride
    assert shares(rthdist.as_points(cols), wide)
    rows = a[::3]
    assert shares(rthdist.as_points(rows), a)


def test_layouts_agree(backend, rng):
    base = rng.random((900, 6))
    b = rng.random((700, 3))
    layouts = {
        "c": np.ascontiguousarray(base[:, :3]),
        "fortran": np.asfortranarray(base[:, :3]),
        "wide": base,
        "columns-1-3": base[:, 1:4],
        "row-slice": base[::2, :3],
        "negative-stride": base[::-1, :3],
        "transposed": np.ascontiguousarray(base[:, :3].T).T,
    }
    for name, a in layouts.items():
        r = rthdist.hausdorff(a, b, backend=backend)
        try:
            check_result(r, a, b)
        except AssertionError as e:
            raise AssertionError(f"layout {name}: {e}") from e
    assert not shares(rthdist.as_points(layouts["fortran"]), base)  # Fortran order: one copy (documented)


def test_other_dtypes_and_containers(rng):
    a = rng.random((300, 3))
    b = rng.random((200, 3))
    ref = rthdist.hausdorff(a, b, backend="cpu").distance
    assert rthdist.hausdorff(a.tolist(), b, backend="cpu").distance == ref
    ints = (a * 1000).astype(np.int32)
    r = rthdist.hausdorff(ints, b * 1000, backend="cpu")
    check_result(r, ints.astype(np.float64), b * 1000)
    r16 = rthdist.hausdorff(a.astype(np.float16), b.astype(np.float16), backend="cpu")
    check_result(r16, a.astype(np.float16), b.astype(np.float16))
    # Big-endian floats (FITS data, np.fromfile(">f8")) and dtypes with metadata: the same values.
    assert rthdist.hausdorff(a.astype(">f8"), b, backend="cpu").distance == ref
    f32 = rthdist.hausdorff(a.astype(np.float32), b, backend="cpu").distance
    assert rthdist.hausdorff(a.astype(">f4"), b, backend="cpu").distance == f32
    assert rthdist.hausdorff(a.astype(np.dtype(np.float64, metadata={"unit": "m"})), b, backend="cpu").distance == ref


class WithPoints:  # Open3D's PointCloud shape: .points is a buffer of (N, 3) doubles
    def __init__(self, p):
        self.points = p


class WithVertices:  # trimesh.Trimesh / trimesh.PointCloud
    def __init__(self, v):
        self.vertices = v


class DLPackOnly:  # a producer with only the DLPack protocol (CPU memory)
    def __init__(self, arr):
        self._arr = arr

    def __dlpack__(self, stream=None):
        return self._arr.__dlpack__()

    def __dlpack_device__(self):
        return self._arr.__dlpack_device__()


def test_points_vertices_and_dlpack(rng):
    a = rng.random((400, 3))
    b = rng.random((300, 3)).astype(np.float32)
    ref = rthdist.hausdorff(a, b, backend="cpu").distance
    assert rthdist.hausdorff(WithPoints(a), WithVertices(b), backend="cpu").distance == ref
    assert rthdist.hausdorff(DLPackOnly(a), DLPackOnly(b), backend="cpu").distance == ref
    assert shares(rthdist.as_points(DLPackOnly(a)), a)


def test_open3d_point_cloud(rng):
    o3d = pytest.importorskip("open3d")  # python3-open3d on the dev machine; not a CI package
    a = rng.random((500, 3))
    b = rng.random((300, 3))
    pa = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(a))
    pb = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(b))
    assert rthdist.hausdorff(pa, pb, backend="cpu").distance == rthdist.hausdorff(a, b, backend="cpu").distance


@pytest.mark.parametrize(
    "bad, match",
    [
        (np.zeros((10, 2)), "shape"),
        (np.zeros((10,)), "shape"),
        (np.zeros((2, 3, 3)), "shape"),
        (np.zeros((0, 3)), "empty|at least one"),
        (np.array([[0.0, np.nan, 0.0]]), "NaN|finite|nan"),
        (np.array([[0.0, np.inf, 0.0]]), "NaN|finite|inf|Inf"),
        (np.zeros((10, 3), dtype=np.complex128), "dtype"),
        (np.zeros((10, 3), dtype=bool), "dtype"),
        (np.array([["a", "b", "c"]]), "dtype"),
        ("not points", "dtype|shape"),
        (None, "dtype|shape"),
    ],
)
def test_bad_arrays_are_value_errors(backend, bad, match):
    good = np.zeros((5, 3))
    with pytest.raises(ValueError, match=match):
        rthdist.hausdorff(bad, good, backend=backend)
    with pytest.raises(ValueError, match=match):
        rthdist.hausdorff(good, bad, backend=backend)


@pytest.mark.parametrize(
    "kwargs",
    [dict(backend="gpu"), dict(bits=9), dict(bits=-1), dict(radius_growth=1.0), dict(threads=-1), dict(device=-2),
     dict(device=5000)],
)
def test_bad_options_are_value_errors(kwargs):
    a = np.zeros((5, 3))
    with pytest.raises(ValueError):
        rthdist.hausdorff(a, a, **kwargs)


def test_missing_device_is_a_device_error():
    a = np.zeros((5, 3))
    with pytest.raises(rthdist.DeviceError) as e:
        rthdist.hausdorff(a, a, backend="ray-query", device=1000)
    assert isinstance(e.value, RuntimeError) and str(e.value)


def test_progress_callable_and_tqdm_like(backend, rng):
    a = rng.random((3000, 3))
    b = rng.random((2000, 3))
    seen = []
    rthdist.hausdorff(a, b, backend=backend, progress=lambda stage, f: seen.append((stage, f)))
    assert seen and all(0.0 <= f <= 1.0 for _, f in seen)
    assert [f for _, f in seen] == sorted(f for _, f in seen)

    class Bar:  # the parts of tqdm.tqdm the adapter uses
        def __init__(self):
            self.n, self.total, self.postfix = 0, None, None

        def update(self, k):
            self.n += k

        def set_postfix_str(self, s, refresh=True):
            self.postfix = s

    bar = Bar()
    rthdist.hausdorff(a, b, backend=backend, progress=bar)
    assert bar.total == 100 and 0 < bar.n <= 100 and bar.postfix
    with pytest.raises(TypeError):
        rthdist.hausdorff(a, b, progress=3)


def test_progress_exception_and_interrupt_propagate(backend, rng):
    a = rng.random((3000, 3))
    b = rng.random((2000, 3))

    def boom(stage, fraction):
        raise ZeroDivisionError("from progress")

    with pytest.raises(ZeroDivisionError, match="from progress"):
        rthdist.hausdorff(a, b, backend=backend, progress=boom)

    def interrupt(stage, fraction):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        rthdist.hausdorff(a, b, backend=backend, progress=interrupt)
    # The library is still usable afterwards.
    assert rthdist.hausdorff(a, b, backend=backend).distance > 0
