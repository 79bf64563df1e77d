"""DeepMind surface-distance (commit 1f805ce) recomputed from its definition
for oracle_masks.py: NumPy/SciPy only, written apart from src/masks.

Surfels: the 2x2x2 neighbour code of every corner of the voxel grid
(scipy.ndimage.correlate with DeepMind's kernel on the mask cropped to the
union's box and zero-padded by one voxel at the high end), codes other than
0 and 255. Areas: per code, the marching-cubes piece on the dual cube at
level 1/2 — the minority corners (the selected ones, the unselected when more
than four are selected), one polygon through the cut-edge midpoints around
each edge-connected group, each polygon triangulated for the largest area on
the unit cube (dynamic programming over sub-polygons), a triangle's area at
spacing s = |n * (s1 s2, s0 s2, s0 s1)| for its unit-cube area vector n.
Distances: distance_transform_edt of the other mask's non-surfels with
sampling = spacing. Statistics: DeepMind's formulas (sorted by (distance,
area), np.cumsum / np.sum, np.searchsorted).
"""
import itertools

import numpy as np
from scipy import ndimage as ndi

KERNEL = np.array([[[128, 64], [32, 16]], [[8, 4], [2, 1]]])
CORNERS = list(itertools.product(range(2), repeat=3))


def _groups(corners):
    """Edge-connected groups of a set of cube corners."""
    left, groups = set(corners), []
    while left:
        stack, group = [left.pop()], set()
        while stack:
            u = stack.pop()
            group.add(u)
            for v in list(left):
                if sum(abs(x - y) for x, y in zip(u, v)) == 1:
                    left.discard(v)
                    stack.append(v)
        groups.append(group)
    return groups


def _polygon(group):
    """Midpoints of the group's outgoing edges, ordered along the cube's faces."""
    links = {}
    for axis, side in itertools.product(range(3), range(2)):
        face = [c for c in CORNERS if c[axis] == side]
        cut = []
        for u, v in itertools.combinations(face, 2):
            if sum(abs(x - y) for x, y in zip(u, v)) == 1 and ((u in group) != (v in group)):
                cut.append(tuple((np.array(u) + np.array(v)) / 2.0))
        assert len(cut) in (0, 2)
        if cut:
            links.setdefault(cut[0], []).append(cut[1])
            links.setdefault(cut[1], []).append(cut[0])
    start = next(iter(links))
    ring, prev = [start], None
    while len(ring) < len(links):
        a, b = links[ring[-1]]
        nxt = a if a != prev else b
        prev = ring[-1]
        ring.append(nxt)
    return np.array(ring)


def _largest_triangulation(p):
    """Area vectors of the triangulation of polygon p with the largest area."""
    n = len(p)
    best = {}
    for length in range(2, n):
        for i in range(0, n - length):
            j = i + length
            options = []
            for k in range(i + 1, j):
                v = 0.5 * np.cross(p[k] - p[i], p[j] - p[i])
                left, right = best.get((i, k), (0.0, [])), best.get((k, j), (0.0, []))
                options.append((left[0] + right[0] + np.linalg.norm(v), left[1] + [v] + right[1]))
            top = max(o[0] for o in options)
            best[(i, j)] = next(o for o in options if o[0] >= top - 1e-12)
    return best[(0, n - 1)][1]


def _area_vectors():
    table = [[] for _ in range(256)]
    for code in range(1, 255):
        on = [c for c in CORNERS if code & KERNEL[c]]
        minority = on if len(on) <= 4 else [c for c in CORNERS if c not in on]
        for group in _groups(minority):
            table[code] += _largest_triangulation(_polygon(group))
    return table


AREA_VECTORS = _area_vectors()


def area_table(spacing):
    s0, s1, s2 = (float(x) for x in spacing)
    scale = np.array([s1 * s2, s0 * s2, s0 * s1])
    return np.array([sum(np.linalg.norm(np.array(n) * scale) for n in AREA_VECTORS[c]) for c in range(256)])


def neighbour_codes(mask):
    """Codes of every corner of the grid: shape + 1, corner c between voxels c - 1 and c."""
    padded = np.zeros(np.array(mask.shape) + 1, np.uint8)
    padded[:-1, :-1, :-1] = mask
    return ndi.correlate(padded, KERNEL, mode="constant", cval=0)


def surface_distances(mask_gt, mask_pred, spacing):
    """DeepMind's compute_surface_distances, as published (crop, correlate, EDT, sort)."""
    areas = area_table(spacing)
    both = mask_gt | mask_pred
    if not both.any():
        e = np.array([])
        return {"distances_gt_to_pred": e, "distances_pred_to_gt": e, "surfel_areas_gt": e, "surfel_areas_pred": e}
    idx = np.argwhere(both)
    lo, hi = idx.min(0), idx.max(0)
    box = tuple(slice(a, b + 1) for a, b in zip(lo, hi))
    code_gt, code_pred = neighbour_codes(mask_gt[box]), neighbour_codes(mask_pred[box])
    border_gt = (code_gt != 0) & (code_gt != 255)
    border_pred = (code_pred != 0) & (code_pred != 255)
    dist_gt = ndi.distance_transform_edt(~border_gt, sampling=spacing) if border_gt.any() else np.full(code_gt.shape, np.inf)
    dist_pred = (ndi.distance_transform_edt(~border_pred, sampling=spacing) if border_pred.any()
                 else np.full(code_pred.shape, np.inf))
    out = {}
    for name, d, a in (("gt_to_pred", dist_pred[border_gt], areas[code_gt][border_gt]),
                       ("pred_to_gt", dist_gt[border_pred], areas[code_pred][border_pred])):
        if len(d):
            s = np.array(sorted(zip(d, a)))
            d, a = s[:, 0], s[:, 1]
        out["distances_" + name] = d
        out["surfel_areas_" + name.split("_")[0]] = a
    return out


def robust_directed(d, a, percent):
    if len(d) == 0:
        return np.inf
    cum = np.cumsum(a) / np.sum(a)
    return d[min(np.searchsorted(cum, percent / 100.0), len(d) - 1)]


def expected(mask_a, mask_b, spacing, percentiles, tol):
    """The numbers rthdist-masks reports for A = pred, B = gt (None where DeepMind gives none)."""
    sd = surface_distances(mask_b, mask_a, spacing)
    da, aa = sd["distances_pred_to_gt"], sd["surfel_areas_pred"]
    db, ab = sd["distances_gt_to_pred"], sd["surfel_areas_gt"]
    na, nb = int(mask_a.sum()), int(mask_b.sum())
    if na == 0 or nb == 0:
        status = "both_empty" if na == nb else ("a_empty" if na == 0 else "b_empty")
        with np.errstate(invalid="ignore", divide="ignore"):
            dice = (np.sum(aa[da <= tol]) + np.sum(ab[db <= tol])) / (np.sum(aa) + np.sum(ab))
            mean_a, mean_b = np.sum(da * aa) / np.sum(aa), np.sum(db * ab) / np.sum(ab)
            assd = (np.sum(da * aa) + np.sum(db * ab)) / (np.sum(aa) + np.sum(ab))
            over_a = np.sum(aa[da <= tol]) / np.sum(aa)
            over_b = np.sum(ab[db <= tol]) / np.sum(ab)
        hd = max(robust_directed(da, aa, 100), robust_directed(db, ab, 100))

        def directed(d, a, mean, overlap):
            return {"hd": f"{robust_directed(d, a, 100):g}", "mean": f"{mean:g}", "surface_overlap": f"{overlap:g}",
                    "percentiles": [{"p": p, "value": f"{robust_directed(d, a, p):g}"} for p in percentiles]}
        hp = [{"p": p, "value": f"{max(robust_directed(da, aa, p), robust_directed(db, ab, p)):g}"}
              for p in percentiles]
        return {"status": status, "a_points": len(da), "b_points": len(db),
                "text": {"hd": f"{hd:g}", "hd_percentile": hp, "assd": f"{assd:g}",
                         "msd": f"{0.5 * (mean_a + mean_b):g}", "surface_dice": f"{dice:g}",
                         "a_to_b": directed(da, aa, mean_a, over_a), "b_to_a": directed(db, ab, mean_b, over_b)}}
    out = {"status": "ok", "a_points": len(da), "b_points": len(db), "a_area": np.sum(aa), "b_area": np.sum(ab),
           "a_hd": robust_directed(da, aa, 100), "b_hd": robust_directed(db, ab, 100)}
    out["hd"] = max(out["a_hd"], out["b_hd"])
    mean_a, mean_b = np.sum(da * aa) / np.sum(aa), np.sum(db * ab) / np.sum(ab)
    out["msd"] = 0.5 * (mean_a + mean_b)
    out["assd"] = (np.sum(da * aa) + np.sum(db * ab)) / (np.sum(aa) + np.sum(ab))
    out["a_mean"], out["b_mean"] = mean_a, mean_b
    # Percentiles and the tolerance: (just below, at, just above) the threshold
    # (1e-9 relative); the value at it is the expected one, the others show in
    # a mismatch's message how close a distance or a cumulative fraction came.
    out["hd_percentile"] = [tuple(max(robust_directed(da, aa, q), robust_directed(db, ab, q))
                                  for q in (p - 1e-7, p, p + 1e-7)) for p in percentiles]
    e = 1e-9 * max(1.0, tol)
    out["surface_dice"] = [(np.sum(aa[da <= t]) + np.sum(ab[db <= t])) / (np.sum(aa) + np.sum(ab))
                           for t in (tol - e, tol, tol + e)]
    out["a_overlap"] = [np.sum(aa[da <= t]) / np.sum(aa) for t in (tol - e, tol, tol + e)]
    out["b_overlap"] = [np.sum(ab[db <= t]) / np.sum(ab) for t in (tol - e, tol, tol + e)]
    return out


def border_corners(mask):
    c = neighbour_codes(mask)
    return (c != 0) & (c != 255)
