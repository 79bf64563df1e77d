"""Triangle surfaces (rthdist/surface.hpp, rthdist/eval.hpp; README "Point to surface").

Vertices: (V, 3) float32/float64 arrays (rthdist.as_points: read in place,
copied only when x, y, z are not adjacent). Faces: (F, 3) int32, int64 or
uint32 arrays; every index in [0, V) (a ValueError names the face). Objects
with .vertices and .faces (trimesh.Trimesh) are accepted as a mesh.
"""

import numpy as np

from . import _rthdist
from ._points import as_points

_FACE_TYPES = (np.int32, np.int64, np.uint32)


def _faces(faces, name):
    arr = np.asarray(faces)
    if arr.dtype not in _FACE_TYPES:
        if arr.dtype.kind in "iu":
            arr = arr.astype(np.int64)
        else:
            raise ValueError(f"{name}: expected int32, int64 or uint32 faces, got dtype {arr.dtype}")
    return np.ascontiguousarray(arr)


def _mesh(vertices, faces, name):
    if faces is None:
        faces = getattr(vertices, "faces", None)
        if faces is None:
            raise ValueError(f"{name}: faces are needed (an (F, 3) array), or an object with .vertices and .faces")
        vertices = vertices.vertices
    return as_points(vertices, f"{name} vertices"), _faces(faces, f"{name} faces")


def hausdorff_to_surface(points, vertices, faces=None, *, per_point=False, backend="auto", threads=0):
    """h(points, surface): every point's exact distance to the triangles.

    Returns a dict: hausdorff, query_index, triangle, query_point,
    surface_point (the closest point), barycentric, backend; with per_point
    also every point's values as read-only NumPy arrays in point order:
    distances (N,) float64, triangles (N,) uint32 (the nearest triangle, the
    smallest index on a tie), surface_points (N, 3) float64 (its closest
    point) and barycentrics (N, 3) float64 (of that point w.r.t. the
    triangle's vertices in face order), and tolerance. Exact as
    rthdist.hausdorff is: equal to a brute force in double over every
    triangle (README "Point to surface"). backend: "auto" or "cpu" (tolerance
    0: every per-point value exact), or "ray-query" / "rt-pipeline" (a
    Vulkan device's float search; hausdorff and its witness still exact,
    each per-point distance the exact distance to the triangle the device
    found, at most `tolerance` above the nearest: 2^-15 of the inputs' frame,
    e.g. 3.8e-6 m for the Stanford bunny).
    """
    v, f = _mesh(vertices, faces, "surface")
    return _rthdist._hausdorff_to_surface(as_points(points, "points"), v, f, per_point=bool(per_point),
                                          backend=str(backend), threads=int(threads))


def surface_hausdorff(vertices_a, faces_a, vertices_b, faces_b, *, tolerance=0.0, directed=False,
                      backend="auto", threads=0):
    """Certified bounds on H between two triangle surfaces (every point of them).

    Returns a dict: bounds (lower, upper) with lower <= H <= upper and
    upper - lower <= tolerance (absolute; 0: 1e-4 of the diagonal of both
    meshes' box), tolerance, slack, directed, a_to_b and b_to_a (None with
    directed=True), each with its own bounds and the witness of its lower
    bound: from_point on from_triangle, its closest point to_point on
    `triangle` of the other surface, and distance; backend and device, the
    ones that ran. backend: "auto" or "cpu" (the CPU backend's BVH), or
    "ray-query" / "rt-pipeline" (each round's queries on a Vulkan device,
    each round's maximum proven on the host: bounds certified alike; the
    tolerance must then be at least 2^-14 of the meshes' largest coordinate
    around the centre of their box, rounded up to a power of two, else
    ValueError naming that floor). design.md §12.
    """
    va, fa = _mesh(vertices_a, faces_a, "surface a")
    vb, fb = _mesh(vertices_b, faces_b, "surface b")
    return _rthdist._surface_hausdorff(va, fa, vb, fb, tolerance=float(tolerance), directed=bool(directed),
                                       backend=str(backend), threads=int(threads))


def evaluate(reconstruction, ground_truth, thresholds, *, faces=None, cap=0.0, backend="auto", threads=0):
    """The reconstruction-evaluation summary (the CLI's --eval; rthdist/eval.hpp).

    reconstruction: (N, 3) points. ground_truth: (M, 3) points, or a mesh's
    vertices with faces= (a surface target: accuracy to its triangles,
    completeness from its used vertices). thresholds: a sequence of tau > 0.
    cap > 0 drops distances >= cap from the means, medians and Chamfer (DTU).
    Returns the dict of the CLI's JSON "eval": accuracy and completeness
    {count, kept, mean, median, mean_squared, max}, chamfer {mean_of_means,
    sum_of_means, sum_of_mean_squares}, thresholds [{threshold, precision,
    recall, fscore}] (precision = share of accuracy distances < tau). Where
    the JSON has null (nothing kept under the cap), the dict holds NaN
    (rthdist/eval.hpp); an empty thresholds sequence gives no rows (the CLI
    refuses an empty --eval).
    """
    if np.isscalar(thresholds):
        thresholds = [thresholds]
    f = None if faces is None else _faces(faces, "faces")
    return _rthdist._evaluate(as_points(reconstruction, "reconstruction"), as_points(ground_truth, "ground_truth"),
                              f, thresholds=[float(t) for t in thresholds], cap=float(cap), backend=str(backend),
                              threads=int(threads))
