"""Inputs as NumPy arrays the compiled core reads in place (rthdist.PointView).

The core reads point i's x, y, z as three adjacent float32 or float64 values
at a byte stride (a C-ordered (N, k >= 3) array, a row slice such as a[::2],
or columns 0..2 of a wider C array). as_points() returns such an array,
without a copy whenever the input already is one:

* NumPy float32/float64 arrays in C order, row slices, (N, k) with k > 3:
  no copy.
* Fortran-ordered or column-strided arrays (x, y, z not adjacent), negative
  or zero row strides: one C-ordered copy (np.ascontiguousarray).
* Integer dtypes: a float64 copy; float16: a float32 copy. Other dtypes
  (bool, complex, object, strings) are a ValueError.
* Objects with .points or .vertices (Open3D PointCloud, trimesh.Trimesh,
  trimesh.PointCloud, ...): that attribute through np.asarray (Open3D's
  Vector3dVector and trimesh's arrays are float64 buffers: no copy).
* DLPack producers (PyTorch, CuPy, JAX): CPU memory through np.from_dlpack or
  the array protocol, no copy; CUDA memory is copied to the host first
  (.cpu() for torch, .get() for CuPy): the Vulkan device does not import CUDA
  memory in this release.
"""

import numpy as np

_KEEP = (np.float32, np.float64)


def _is_cuda(obj):
    dev = getattr(obj, "__dlpack_device__", None)
    if dev is None:
        return False
    try:
        kind = int(dev()[0])
    except Exception:  # noqa: BLE001 - a producer without a usable device: not CUDA
        return False
    return kind in (2, 3, 13)  # kDLCUDA, kDLCUDAHost, kDLCUDAManaged


def _host_array(obj):
    """obj as a NumPy array in host memory (copied only from a GPU)."""
    if isinstance(obj, np.ndarray):
        return obj
    if not hasattr(obj, "__array_interface__") and not hasattr(obj, "__dlpack__"):
        for attr in ("points", "vertices"):
            inner = getattr(obj, attr, None)
            if inner is not None and not callable(inner):
                return _host_array(inner)
    if hasattr(obj, "detach") and hasattr(obj, "cpu"):  # torch.Tensor (also with requires_grad)
        return obj.detach().cpu().numpy()
    if _is_cuda(obj):
        if hasattr(obj, "get"):  # cupy.ndarray
            return obj.get()
        raise ValueError(f"points on a CUDA device of type {type(obj).__name__}: copy them to the host first")
    if hasattr(obj, "__dlpack__") and not hasattr(obj, "__array_interface__"):
        try:
            return np.from_dlpack(obj)
        except (TypeError, RuntimeError, BufferError):
            pass
    return np.asarray(obj)


def as_points(obj, name="points"):
    """obj as an (N, >=3) float32/float64 array the core reads without a copy."""
    try:
        arr = _host_array(obj)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not an (N, 3) array of points: {e}") from e
    if arr.dtype.kind == "f" and (not arr.dtype.isnative or arr.dtype.metadata) and arr.dtype.itemsize in (2, 4, 8):
        # Another byte order (">f8": FITS data, np.fromfile) or a dtype with
        # metadata: the same values in a native float copy.
        arr = arr.astype(np.float64 if arr.dtype.itemsize == 8 else np.float32)
    if arr.dtype not in _KEEP:
        if arr.dtype.kind in "iu":
            arr = arr.astype(np.float64)
        elif arr.dtype == np.float16:
            arr = arr.astype(np.float32)
        else:
            raise ValueError(f"{name}: expected float32 or float64 points, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] < 3:
        raise ValueError(f"{name}: expected an (N, 3) array of points, got shape {arr.shape}")
    item = arr.itemsize
    rows_ok = arr.shape[0] <= 1 or (arr.strides[0] >= 3 * item and arr.strides[0] % item == 0)
    if arr.shape[0] > 0 and (arr.strides[1] != item or not rows_ok):
        arr = np.ascontiguousarray(arr[:, :3])
    return arr
