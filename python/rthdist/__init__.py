"""rthdist: the exact Hausdorff distance between two 3-D point sets.

    >>> import numpy as np, rthdist
    >>> a = np.random.rand(10000, 3); b = np.random.rand(5000, 3)
    >>> r = rthdist.hausdorff(a, b)
    >>> r.distance, r.a_to_b.indices, r.timings["total"]

H(A, B) = max(h(A, B), h(B, A)), h(A, B) = max over a of min over b of |a - b|,
exact for the coordinates as given (float32 or float64): the value equals
(==) a brute force in double, proven by each answer's certificate, and the
reported index pairs realize it (README, Precision). Backends: "cpu" (exact,
multithreaded), "ray-query" and "rt-pipeline" (Vulkan ray tracing; Mesa's
lavapipe runs them on the CPU), "auto" (a hardware ray-tracing GPU when
there is one, else the CPU; rthdist.hausdorff of a pair of at most 2^18
points per host thread runs on the CPU, which answers it before a GPU has
opened its device: README, Usage).

Inputs (rthdist._points): (N, 3) array-likes of float32/float64 (C order
and row slices read in place; Fortran order copied), objects with .points
or .vertices (Open3D, trimesh), PyTorch/CuPy tensors (CPU without a copy,
CUDA copied to the host). docs/python.md has the guide.

Segmentation masks (rthdist._masks): rthdist.compare_masks(a, b, ...) on
3-D label arrays or nibabel images, in a named tool's convention, and a
MaskEngine for many comparisons on one device.
"""

import os as _os

from . import _rthdist
from ._device_owner import DeviceOwner as _DeviceOwner
from ._masks import CONVENTIONS, DirectedMask, MaskEngine, MaskResult, MaskVolume, PreparedReference, compare_masks
from ._points import as_points
from ._surface import _mesh, evaluate, hausdorff_to_surface, surface_hausdorff
from ._rthdist import (  # noqa: F401 - re-exported
    CancelledError,
    DeviceError,
    Directed,
    Error,
    HausdorffResult,
    InternalError,
    OutOfMemoryError,
    PreparedSet,
    list_devices,
)

__version__ = _rthdist.__version__
__all__ = [
    "hausdorff",
    "hausdorff_to_surface",
    "surface_hausdorff",
    "evaluate",
    "Engine",
    "load",
    "list_devices",
    "as_points",
    "HausdorffResult",
    "Directed",
    "PreparedSet",
    "Error",
    "DeviceError",
    "OutOfMemoryError",
    "InternalError",
    "CancelledError",
    "compare_masks",
    "MaskEngine",
    "MaskVolume",
    "PreparedReference",
    "MaskResult",
    "DirectedMask",
    "CONVENTIONS",
    "__version__",
]


def _progress_callable(progress):
    """progress as callable(stage, fraction): a callable as is, a tqdm bar adapted."""
    if progress is None or callable(progress):
        return progress
    if hasattr(progress, "update") and hasattr(progress, "n"):  # tqdm-like bar
        bar = progress
        if getattr(bar, "total", None) is None:
            bar.total = 100
        scale = bar.total

        def advance(stage, fraction):
            target = fraction * scale
            if target > bar.n:
                bar.update(target - bar.n)
            if hasattr(bar, "set_postfix_str"):
                bar.set_postfix_str(stage, refresh=False)

        return advance
    raise TypeError("progress must be a callable(stage, fraction) or a tqdm-like bar (with .update and .n)")


def hausdorff(a, b, *, directed=False, per_point=False, backend="auto", device=None, bits=0,
              radius_growth=2.0, threads=0, progress=None, validation=False):
    """H(A, B) of two point sets, with its witnesses: a HausdorffResult.

    a, b: (N, 3) point sets (see rthdist.as_points for what is accepted).
    directed: compute only h(A, B) (result.b_to_a is None).
    per_point: also every point's nearest distance and index (exact for
        float64 input; for float32, the float search's pair, at most a
        relative 2^-21 above the exact nearest: README "Per-point distances")
        (result.a_distances, a_nearest, b_distances, b_nearest) and the
        statistics (percentile, hd95, mean, rms, stats, histogram); slower.
    backend: "auto", "cpu", "ray-query" or "rt-pipeline" ("auto": a small
        pair, at most 2^18 points per host thread, on the CPU backend).
    device: Vulkan device index (rthdist.list_devices()); None = first usable.
    bits: index-space bit count 0..8 (0 = from the data).
    radius_growth: candidate-search radius factor 1.1..16.
    threads: host threads, the CPU backend's and the GPU backends' passes
        over the points (0 = all).
    progress: callable(stage, fraction) or a tqdm bar, called between stages.

    A temporary device is created per call; keep an Engine for repeated calls.
    The GIL is released while computing; Ctrl-C cancels the call.
    Raises ValueError (bad arrays: shape, dtype, NaN/Inf, empty; bad
    options), DeviceError (no device for the backend), OutOfMemoryError,
    InternalError.
    """
    pa = as_points(a, "a")
    pb = as_points(b, "b")
    return _rthdist._hausdorff(pa, pb, directed=bool(directed), per_point=bool(per_point), backend=str(backend),
                               device=device, bits=int(bits), radius_growth=float(radius_growth),
                               threads=int(threads), validation=bool(validation),
                               progress=_progress_callable(progress))


def _points_or_prepared(x, name):
    return x if isinstance(x, PreparedSet) else as_points(x, name)


class Engine(_DeviceOwner):
    """A backend's device and pipelines, kept between calls.

        with rthdist.Engine(backend="ray-query") as engine:
            ref = engine.prepare(reference)          # indexed once
            for scan in scans:
                print(engine.hausdorff(ref, scan).distance)

    Per-call settings (directed, per_point, bits, radius_growth, progress)
    never rebuild the device or a prepared set. One Engine serves one call at
    a time (calls from several threads wait for each other); give each thread
    its own Engine to run in parallel. close() (or leaving the with block)
    releases the device; prepared sets keep it alive until they go too.

    memory_budget: bytes one backend call may hold (0 = automatic: 3/4 of
    the device's memory budget on a GPU, none on the CPU backend). Larger
    pairs of arrays are computed exactly in query chunks and target tiles
    (README "Inputs larger than the device"; result counters query_chunks,
    target_tiles). Prepared sets are not split.

    devices: several GPUs (device indices, e.g. [0, 1]) for one computation
    of two arrays: each direction's queries are split over them and the
    result is the one-device result (README "Several GPUs"). Prepared sets
    live on the first. An index given twice opens that device twice.
    """

    def __init__(
        self, backend="auto", *, device=None, threads=0, validation=False, memory_budget=0, devices=None
    ):
        devices = [] if devices is None else [int(d) for d in devices]
        self._engine = _rthdist._Engine(
            str(backend), device, int(threads), bool(validation), int(memory_budget), devices
        )

    def prepare(self, points, *, bits=0, origin=None):
        """points indexed once on this Engine's device: a PreparedSet for any number of calls.

        bits: its index grid's bit count (0 = from the data). origin: the frame
        of a float64 set (subtracted before the float32 search); sets that
        will meet should share one (e.g. origin=reference.origin), else a call
        re-indexes both in their union's frame. Keeps a reference to the array
        (per-point statistics read its bounding box).
        """
        o = None if origin is None else tuple(float(v) for v in origin)
        return self._engine.prepare(as_points(points, "points"), bits=int(bits), origin=o)

    def hausdorff(self, a, b, *, directed=False, per_point=False, bits=0, radius_growth=2.0, progress=None):
        """H(A, B) on this Engine's device: as rthdist.hausdorff, without the device setup.

        a, b: point sets or PreparedSets of this Engine; an array against a
        PreparedSet is prepared for this call in the prepared set's frame.
        """
        pa = _points_or_prepared(a, "a")
        pb = _points_or_prepared(b, "b")
        return self._engine.hausdorff(pa, pb, directed=bool(directed), per_point=bool(per_point), bits=int(bits),
                                      radius_growth=float(radius_growth), progress=_progress_callable(progress))

    def hausdorff_to_surface(self, points, vertices, faces=None, *, per_point=False):
        """h(points, surface) on this Engine: as rthdist.hausdorff_to_surface, without the device setup.

        The Engine keeps its device (a GPU backend) or its last mesh's tree
        (the CPU backend: a call with the same mesh, compared exactly, skips
        its build), so repeated calls against one mesh pay the search alone.
        """
        v, f = _mesh(vertices, faces, "surface")
        return self._engine.hausdorff_to_surface(as_points(points, "points"), v, f, per_point=bool(per_point))

    def hausdorff_many(self, sets, pairs, *, directed=False, per_point=False, bits=0, radius_growth=2.0,
                       progress=None):
        """[H(sets[i], sets[j]) for (i, j) in pairs] in one call (PreparedSets of this Engine).

        Raises the first failing pair's error.
        """
        return self._engine.hausdorff_many(list(sets), [(int(i), int(j)) for i, j in pairs],
                                           directed=bool(directed), per_point=bool(per_point), bits=int(bits),
                                           radius_growth=float(radius_growth), progress=_progress_callable(progress))



def load(path, *, las_classes=None):
    """The points of a file as an (N, 3) NumPy array in the file's precision.

    Formats as the CLI: .ply, .xyz/.txt, .obj, .gltf/.glb, .stl, .off, .pcd,
    .las (optionally .gz). Decimal text and double/integer binary come back
    float64, float files float32 (README, Precision). las_classes: keep only
    these LAS classification values.
    Raises FileNotFoundError (no such file), ValueError (unreadable or
    malformed file: the message names the file and the place).
    """
    path = _os.fspath(path)
    if isinstance(path, bytes):
        path = _os.fsdecode(path)
    if not _os.path.exists(path):
        raise FileNotFoundError(2, "No such file or directory", path)
    if _os.path.isdir(path):
        raise IsADirectoryError(21, "Is a directory", path)
    return _rthdist._load(path, list(las_classes or []))
