#!/usr/bin/env python3
"""Oracle test of rthdist-masks: every convention recomputed here from its
definition (docs/masks.md; include/rthdist/masks.hpp) with NumPy/SciPy, on
synthetic masks and on the atlases of ../shared/data/nifti, compared with the
CLI's JSON to 1e-6 of the volume's world diagonal.

  oracle_masks.py --cli build/rthdist-masks --backend cpu [--data DIR] [--quick]

The oracles:
  boundary(m, c)  m AND NOT binary_erosion(m, generate_binary_structure(3, c'),
                  border_value=0)   (c' = 1, 2, 3 for connectivity 6, 18, 26)
  spacing metric  scipy.ndimage.distance_transform_edt(~Y, sampling=spacing)
                  read at X's voxels (MONAI, MedPy, plastimatch, ITK)
  world metric    cKDTree over voxel centres mapped by the affine (rthdist)
  percentiles     numpy.percentile (linear); nearest rank x[ceil(p n/100)-1];
                  plastimatch x[clamp(floor(p/100 n - 1))]
  deepmind        oracle_deepmind.py: surfels with marching-cubes areas, EDT
                  on the corner grid, DeepMind's area-weighted statistics
Exit status 0 when every value matches; otherwise every mismatch is printed.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import nibabel as nib
import numpy as np
from scipy import ndimage as ndi
from scipy.spatial import cKDTree

import oracle_deepmind

CONVENTIONS = ["rthdist", "monai", "medpy", "plastimatch", "itk", "deepmind"]
FAILURES = []


def boundary(m, conn):
    st = ndi.generate_binary_structure(3, {6: 1, 18: 2, 26: 3}[conn])
    return m & ~ndi.binary_erosion(m, structure=st, border_value=0)


def spacing_of(affine):
    return np.linalg.norm(affine[:3, :3], axis=0)


def edt_directed(x, y, spacing):
    """Distances of X's voxels to the nearest voxel of Y (spacing metric)."""
    return ndi.distance_transform_edt(~y, sampling=spacing)[x]


def world_directed(x, y, affine):
    px = nib.affines.apply_affine(affine, np.argwhere(x))
    py = nib.affines.apply_affine(affine, np.argwhere(y))
    d, _ = cKDTree(py).query(px)
    return d


def nearest_rank(s, p):
    n = len(s)
    r = min(max(math.ceil(p * n / 100.0), 1), n)
    return s[r - 1]


def torch_quantile(s, p):
    """MONAI's HD-p: the maximum for p = 0, else torch.quantile of a float32
    tensor (sorted s): rank float32(p / 100) * float32(n - 1) in float32,
    truncated; its float32 fraction the weight (interpolated here in double)."""
    if p == 0:
        return s[-1]
    n = len(s)
    rank = np.float32(p / 100.0) * np.float32(n - 1)
    lo = min(int(rank), n - 1)
    hi = min(int(np.ceil(rank)), n - 1)
    w = float(rank - np.float32(lo))
    a, b = s[lo], s[hi]
    return a + w * (b - a) if w < 0.5 else b - (b - a) * (1.0 - w)


def plastimatch_pct(s, p):
    k = int(min(max(math.floor(p / 100.0 * len(s) - 1.0), 0), len(s) - 1))
    return s[k]


def oracle(conv, a, b, affine, percentiles, conn, tol):
    """Expected numbers of one convention (None where the convention has none)."""
    sp = spacing_of(affine)
    na, nb = int(a.sum()), int(b.sum())
    if na == 0 or nb == 0:
        # Both sides' points all the same: voxels (itk) or boundary voxels.
        c = 6 if conv not in ("rthdist", "medpy") else conn
        pa, pb = (na, nb) if conv == "itk" else (int(boundary(a, c).sum()), int(boundary(b, c).sum()))
        return {"status": "both_empty" if na == nb else ("a_empty" if na == 0 else "b_empty"),
                "a_points": pa, "b_points": pb}
    if conv == "itk":
        da, db = edt_directed(a, b, sp), edt_directed(b, a, sp)
    else:
        c = conn if conv in ("rthdist", "medpy") else 6
        ea, eb = boundary(a, c), boundary(b, c)
        if conv == "rthdist":
            da, db = world_directed(ea, eb, affine), world_directed(eb, ea, affine)
        else:
            da, db = edt_directed(ea, eb, sp), edt_directed(eb, ea, sp)
    sa, sb = np.sort(da), np.sort(db)
    out = {"status": "ok", "hd": max(sa[-1], sb[-1]), "a_hd": sa[-1], "b_hd": sb[-1],
           "a_points": len(sa), "b_points": len(sb), "msd": 0.5 * (sa.mean() + sb.mean())}
    if conv == "monai":
        # MONAI's distances are float32: d counts when float32(d) <= float32(tol), exactly.
        t32 = np.float32(tol)
        ca, cb = np.count_nonzero(sa.astype(np.float32) <= t32), np.count_nonzero(sb.astype(np.float32) <= t32)
        out["assd"] = (sa.sum() + sb.sum()) / (len(sa) + len(sb))
        out["surface_dice"] = (ca + cb) / (len(sa) + len(sb))
        out["surface_dice_range"] = (out["surface_dice"], out["surface_dice"])
        out["a_overlap_range"] = (ca / len(sa),) * 2
        out["b_overlap_range"] = (cb / len(sb),) * 2
        out["hd_percentile"] = [max(torch_quantile(sa, p), torch_quantile(sb, p)) for p in percentiles]
    elif conv != "itk":
        out["assd"] = (sa.sum() + sb.sum()) / (len(sa) + len(sb))
        out["surface_dice"] = (np.count_nonzero(sa <= tol) + np.count_nonzero(sb <= tol)) / (len(sa) + len(sb))
        # Distances within rounding of the tolerance may fall either side (an
        # oblique affine makes exact 1.0 mm distances 1.0 +- 1e-16): the range.
        e = 1e-9 * max(1.0, tol)
        out["surface_dice_range"] = (
            (np.count_nonzero(sa <= tol - e) + np.count_nonzero(sb <= tol - e)) / (len(sa) + len(sb)),
            (np.count_nonzero(sa <= tol + e) + np.count_nonzero(sb <= tol + e)) / (len(sa) + len(sb)))
        for side, s in (("a", sa), ("b", sb)):
            out[side + "_overlap_range"] = (np.count_nonzero(s <= tol - e) / len(s), np.count_nonzero(s <= tol + e) / len(s))
        hp = []
        for p in percentiles:
            if conv == "rthdist":
                hp.append(max(nearest_rank(sa, p), nearest_rank(sb, p)))
            elif conv == "medpy":
                hp.append(np.percentile(np.concatenate([sa, sb]), p))
            else:
                hp.append(0.5 * (plastimatch_pct(sa, p) + plastimatch_pct(sb, p)))
        out["hd_percentile"] = hp
    return out


EMPTY_VALUES = {  # what each convention itself reports (status both_empty / one empty)
    "rthdist": ("undefined", "undefined"), "monai": ("nan", "inf"), "medpy": ("error", "error"),
    "plastimatch": ("0", "undefined"), "itk": ("undefined", "undefined"),
}


def diagonal(shape, affine):
    corners = np.array([[i, j, k] for i in (0, shape[0] - 1) for j in (0, shape[1] - 1) for k in (0, shape[2] - 1)])
    w = nib.affines.apply_affine(affine, corners)
    return float(np.linalg.norm(w.max(0) - w.min(0)))


def close(name, got, want, tol):
    if got is None or want is None or not (abs(got - want) <= tol):
        FAILURES.append(f"{name}: got {got}, expected {want} (tolerance {tol:.3g})")


def check_witness(name, d, x_set, y_set, affine, conv, expect_hd, tol):
    """The reported voxels realize the directed HD and belong to the right sets."""
    v, nv = tuple(d["voxel"]), tuple(d["nearest_voxel"])
    if not x_set[v] or not y_set[nv]:
        if expect_hd > 0:
            FAILURES.append(f"{name}: witness voxels {v} -> {nv} not in the point sets")
        return
    if conv == "rthdist":
        dist = np.linalg.norm(nib.affines.apply_affine(affine, np.array(v)) - nib.affines.apply_affine(affine, np.array(nv)))
    else:
        dist = np.linalg.norm((np.array(v) - np.array(nv)) * spacing_of(affine))
    close(name + " witness distance", dist, expect_hd, tol)
    w = nib.affines.apply_affine(affine, np.array(v))
    close(name + " witness point", float(np.linalg.norm(np.array(d["point"]) - w)), 0.0, tol)


def within(name, got, options, eps):
    """options = (value just below the threshold, at it, just above): rthdist
    recomputes DeepMind's distances with SciPy's arithmetic and sums areas in
    NumPy's order, so it must give the value at the threshold itself."""
    if got is None or not abs(got - options[1]) <= eps:
        FAILURES.append(f"{name}: got {got}, expected {options[1]} (+- {eps:.3g}; just below / above the "
                        f"threshold: {options[0]} / {options[2]})")


def check_deepmind(tag, row, xa, xb, affine, percentiles, tol, eps, offset=(0, 0, 0)):
    """One deepmind row against oracle_deepmind (xa, xb: the masks, cropped by `offset` voxels)."""
    sp = spacing_of(affine)
    want = oracle_deepmind.expected(xa, xb, sp, percentiles, tol)
    if row["status"] != want["status"]:
        FAILURES.append(f"{tag}: status {row['status']}, expected {want['status']}")
        return
    if want["status"] != "ok":
        if row["convention_value"] != want["text"] or row["hd"] is not None:
            FAILURES.append(f"{tag}: empty values {row['convention_value']} / hd {row['hd']}, expected {want['text']}")
        if row["a_to_b"]["points"] != want["a_points"] or row["b_to_a"]["points"] != want["b_points"]:
            FAILURES.append(f"{tag}: points {row['a_to_b']['points']}/{row['b_to_a']['points']}, "
                            f"expected {want['a_points']}/{want['b_points']}")
        return
    for key in ("hd", "msd", "assd"):
        close(f"{tag} {key}", row[key], want[key], eps)
    within(tag + " surface_dice", row["surface_dice"], want["surface_dice"], 1e-12)
    for got, exp in zip(row["hd_percentile"], want["hd_percentile"]):
        within(tag + f" hd{got['p']:g}", got["value"], exp, eps)
    for side, x, y in (("a", xa, xb), ("b", xb, xa)):
        d = row[side + "_to_b" if side == "a" else "b_to_a"]
        if d["points"] != want[side + "_points"]:
            FAILURES.append(f"{tag}: {side} surfels {d['points']}, expected {want[side + '_points']}")
        close(f"{tag} {side} hd", d["hd"], want[side + "_hd"], eps)
        close(f"{tag} {side} mean", d["mean"], want[side + "_mean"], eps)
        close(f"{tag} {side} area", d["area_mm2"], want[side + "_area"], 1e-9 * want[side + "_area"])
        within(f"{tag} {side} surface_overlap", d["surface_overlap"], want[side + "_overlap"], 1e-12)
        # The witness: a surfel of X, a surfel of Y, at the directed HD; its world point.
        c, nc = np.array(d["corner"]) - offset, np.array(d["nearest_corner"]) - offset
        bx, by = oracle_deepmind.border_corners(x), oracle_deepmind.border_corners(y)
        if not bx[tuple(c)] or not by[tuple(nc)]:
            FAILURES.append(f"{tag} {side}: witness corners {d['corner']} -> {d['nearest_corner']} are not surfels")
            continue
        close(f"{tag} {side} witness distance", float(np.linalg.norm((c - nc) * sp)), want[side + "_hd"], eps)
        w = nib.affines.apply_affine(affine, c - 0.5)
        close(f"{tag} {side} witness point", float(np.linalg.norm(np.array(d["point"]) - w)), 0.0, eps)


def run_cli(cli, backend, a_path, b_path, extra):
    cmd = [cli, a_path, b_path, "--json", "--convention", "all", "--backend", backend, "--percentile", "95",
           "--percentile", "50", "--percentile", "100"] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        FAILURES.append(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()}")
        return None
    return json.loads(p.stdout)


def check_device_extraction(name, cli, backend, a_path, b_path, extra, out):
    """--device-extraction --repeat 2 gives every row of `out` (the default: the
    host's extraction) unchanged (the compute pass and the host find the same
    voxels, in the same order), says where each extraction ran, and lists both
    runs' times."""
    again = run_cli(cli, backend, a_path, b_path, extra + ["--device-extraction", "--repeat", "2"])
    if again is None:
        return
    timing_keys = {"timings_ms", "engine_ms", "extraction", "repeat_total_ms"}
    for row, other in zip(out["results"], again["results"]):
        tag = f"{name} label {row['label']} {row['convention']}"
        if {k: v for k, v in row.items() if k not in timing_keys} != \
                {k: v for k, v in other.items() if k not in timing_keys}:
            FAILURES.append(f"{tag}: --device-extraction changed the row")
        # With --device-extraction, GPU backends run the compute pass for
        # every convention but deepmind (surfels), also when it finds a mask
        # empty; without it, the host extracts.
        device = backend != "cpu" and row["convention"] != "deepmind"
        if other.get("extraction") != ("device" if device else "host") or \
                len(other.get("repeat_total_ms", [])) != 2:
            FAILURES.append(f"{tag}: --device-extraction --repeat 2 reported {other.get('extraction')}, "
                            f"{other.get('repeat_total_ms')} on {backend}")
        if row.get("extraction") != "host":
            FAILURES.append(f"{tag}: extraction {row.get('extraction')} on {backend} by default")
    if len(out["results"]) != len(again["results"]):
        FAILURES.append(f"{name}: --device-extraction gave {len(again['results'])} rows, not {len(out['results'])}")


def check_case(name, cli, backend, tmp, a, b, affine, conn=6, tol=1.0, label_volumes=None, npy=False,
               npy_affine=False, more_percentiles=()):
    """Writes the pair (label volumes or binary masks), runs every convention, compares."""
    percentiles = [95.0, 50.0, 100.0] + [float(p) for p in more_percentiles]
    va = label_volumes[0] if label_volumes else a.astype(np.uint8)
    vb = label_volumes[1] if label_volumes else b.astype(np.uint8)
    if npy:
        a_path, b_path = os.path.join(tmp, name + "_a.npy"), os.path.join(tmp, name + "_b.npy")
        np.save(a_path, va)
        np.save(b_path, np.asfortranarray(vb))  # one C-order, one Fortran-order array
        if npy_affine:
            extra = ["--affine", ",".join(repr(float(x)) for x in affine[:3, :].ravel())]
        else:
            sp = spacing_of(affine)
            extra = ["--spacing", f"{sp[0]!r},{sp[1]!r},{sp[2]!r}"]
    else:
        a_path, b_path = os.path.join(tmp, name + "_a.nii.gz"), os.path.join(tmp, name + "_b.nii.gz")
        nib.save(nib.Nifti1Image(va, affine), a_path)
        nib.save(nib.Nifti1Image(vb, affine), b_path)
        # NIfTI stores the sform in float32: compare against what the file holds.
        affine = nib.load(a_path).affine
        extra = []
    extra += ["--connectivity", str(conn), "--tolerance", repr(tol)]
    for p in more_percentiles:
        extra += ["--percentile", repr(float(p))]
    if label_volumes:
        extra += ["--labels", "all"]
    out = run_cli(cli, backend, a_path, b_path, extra)
    if out is None:
        return
    check_device_extraction(f"[{backend}] {name}", cli, backend, a_path, b_path, extra, out)
    eps = 1e-6 * diagonal(a.shape, affine)
    for row in out["results"]:
        conv = row["convention"]
        if label_volumes:
            lab = int(row["label"])
            xa, xb = label_volumes[0] == lab, label_volumes[1] == lab
        else:
            xa, xb = a, b
        if conv == "deepmind":
            check_deepmind(f"[{backend}] {name} label {row['label']} deepmind", row, xa, xb, affine, percentiles,
                           tol, eps)
            continue
        want = oracle(conv, xa, xb, affine, percentiles, conn, tol)
        tag = f"[{backend}] {name} label {row['label']} {conv}"
        if row["status"] != want["status"]:
            FAILURES.append(f"{tag}: status {row['status']}, expected {want['status']}")
            continue
        if want["status"] != "ok":
            both, one = EMPTY_VALUES[conv]
            expect = both if want["status"] == "both_empty" else one
            if row["convention_value"]["hd"] != expect or row["hd"] is not None:
                FAILURES.append(f"{tag}: empty value {row['convention_value']} / hd {row['hd']}, expected {expect}")
            if row["a_to_b"]["points"] != want["a_points"] or row["b_to_a"]["points"] != want["b_points"]:
                FAILURES.append(f"{tag}: points {row['a_to_b']['points']}/{row['b_to_a']['points']}, "
                                f"expected {want['a_points']}/{want['b_points']}")
            continue
        close(tag + " hd", row["hd"], want["hd"], eps)
        close(tag + " a_to_b hd", row["a_to_b"]["hd"], want["a_hd"], eps)
        close(tag + " b_to_a hd", row["b_to_a"]["hd"], want["b_hd"], eps)
        close(tag + " msd", row["msd"], want["msd"], eps)
        if row["a_to_b"]["points"] != want["a_points"] or row["b_to_a"]["points"] != want["b_points"]:
            FAILURES.append(f"{tag}: points {row['a_to_b']['points']}/{row['b_to_a']['points']}, "
                            f"expected {want['a_points']}/{want['b_points']}")
        if conv != "itk":
            close(tag + " assd", row["assd"], want["assd"], eps)
            lo, hi = want["surface_dice_range"]
            if not (lo - 1e-12 <= row["surface_dice"] <= hi + 1e-12):
                FAILURES.append(f"{tag} surface_dice: got {row['surface_dice']}, expected {want['surface_dice']} "
                                f"(range {lo}..{hi} for distances within rounding of the tolerance)")
            for got, exp in zip(row["hd_percentile"], want["hd_percentile"]):
                close(tag + f" hd{got['p']:g}", got["value"], exp, eps)
            for side, key in (("a", "a_to_b"), ("b", "b_to_a")):
                lo, hi = want[side + "_overlap_range"]
                if not (lo - 1e-12 <= row[key]["surface_overlap"] <= hi + 1e-12):
                    FAILURES.append(f"{tag} {key} surface_overlap: got {row[key]['surface_overlap']}, expected {lo}..{hi}")
            c = conn if conv in ("rthdist", "medpy") else 6
            sa, sb = boundary(xa, c), boundary(xb, c)
        else:
            if row["hd_percentile"]:
                FAILURES.append(f"{tag}: itk reports no percentile")
            sa, sb = xa, xb
        check_witness(tag + " a_to_b", row["a_to_b"], sa, sb, affine, conv, want["a_hd"], eps)
        check_witness(tag + " b_to_a", row["b_to_a"], sb, sa, affine, conv, want["b_hd"], eps)
    print(f"{name}: {len(out['results'])} rows checked")


def ball(shape, centre, radius, spacing=(1, 1, 1)):
    g = np.indices(shape).astype(float)
    d2 = sum(((g[i] - centre[i]) * spacing[i]) ** 2 for i in range(3))
    return d2 <= radius * radius


def rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def synthetic_cases(cli, backend, tmp, quick):
    aniso = np.diag([0.5, 0.7, 3.0, 1.0])
    shape = (40, 36, 12)
    sp = (0.5, 0.7, 3.0)
    a = ball(shape, (19, 17, 6), 7.0, sp)
    b = ball(shape, (21, 16, 5.5), 8.5, sp)
    check_case("spheres_aniso", cli, backend, tmp, a, b, aniso)
    shell = ball(shape, (20, 18, 6), 9.0, sp) & ~ball(shape, (20, 18, 6), 6.0, sp)
    check_case("shell_vs_sphere", cli, backend, tmp, shell, b, aniso, tol=2.0)
    oblique = np.eye(4)
    oblique[:3, :3] = rotation(0.3, -0.5, 1.1) @ np.diag(sp)
    oblique[:3, 3] = [-12.25, 40.5, 7.0]
    check_case("spheres_oblique", cli, backend, tmp, a, b, oblique)
    thin_a = np.zeros(shape, bool)
    thin_a[5:35, 18, 6] = True  # a one-voxel line
    thin_b = np.zeros(shape, bool)
    thin_b[8:30, 10:26, 7] = True  # a one-voxel plate
    check_case("thin_structures", cli, backend, tmp, thin_a, thin_b, aniso)
    # MONAI's float32: slabs 3 voxels apart at 0.8 mm are 2.4000000000000004
    # mm apart in double, 2.4f in float32 (inside a 2.4 mm tolerance); a cube
    # and the cube plus a voxel 24 mm away: the HD-99.9 rank 0.999 * 488 in
    # float32, and p = 0 (MONAI: the maximum; the others: the least).
    slab_a, slab_b = np.zeros((20, 20, 20), bool), np.zeros((20, 20, 20), bool)
    slab_a[:, :, 5:12] = True
    slab_b[:, :, 8:15] = True
    check_case("slabs_0.8mm_tol2.4", cli, backend, tmp, slab_a, slab_b, np.diag([0.8, 0.8, 0.8, 1.0]), tol=2.4,
               more_percentiles=(0, 99.9))
    cube = np.zeros((40, 16, 16), bool)
    cube[2:12, 2:12, 2:12] = True
    island = cube.copy()
    island[35, 7, 7] = True
    check_case("cube_island", cli, backend, tmp, island, cube, np.eye(4), more_percentiles=(0, 99.9))
    one_a = np.zeros(shape, bool)
    one_a[3, 4, 5] = True
    one_b = np.zeros(shape, bool)
    one_b[30, 20, 9] = True
    check_case("one_voxel", cli, backend, tmp, one_a, one_b, aniso)
    check_case("one_voxel_vs_sphere", cli, backend, tmp, one_a, b, aniso)
    empty = np.zeros(shape, bool)
    check_case("both_empty", cli, backend, tmp, empty, empty, aniso)
    check_case("a_empty", cli, backend, tmp, empty, b, aniso)
    check_case("b_empty", cli, backend, tmp, a, empty, aniso)
    rng = np.random.default_rng(13)
    noisy_a = (rng.random((20, 18, 16)) < 0.35) | ball((20, 18, 16), (10, 9, 8), 5)
    noisy_b = (rng.random((20, 18, 16)) < 0.05) | ball((20, 18, 16), (9, 9, 7), 6)
    check_case("noisy", cli, backend, tmp, noisy_a, noisy_b, np.diag([0.8, 0.8, 2.5, 1.0]))
    check_case("spheres_conn26", cli, backend, tmp, a, b, aniso, conn=26)
    if not quick:
        check_case("noisy_conn18", cli, backend, tmp, noisy_a, noisy_b, np.diag([0.8, 0.8, 2.5, 1.0]), conn=18)
        check_case("spheres_npy", cli, backend, tmp, a, b, aniso, npy=True)
        check_case("spheres_npy_oblique", cli, backend, tmp, a, b, oblique, npy=True, npy_affine=True)
    # Several labels, one row per label; label 3 only in A (b_empty).
    la = np.zeros(shape, np.int16)
    lb = np.zeros(shape, np.int16)
    la[a] = 1
    lb[b] = 1
    la[ball(shape, (8, 8, 3), 3.0, (1, 1, 1))] = 2
    lb[ball(shape, (9, 7, 3), 3.5, (1, 1, 1))] = 2
    la[30:33, 28:31, 9:11] = 3
    check_case("labels_all", cli, backend, tmp, la > 0, lb > 0, aniso, label_volumes=(la, lb))


def crop_pair(a, b, margin=2):
    """Crops both masks to their union's box plus a background margin (the
    boundaries and distances are unchanged: outside counts as background)."""
    idx = np.argwhere(a | b)
    lo = np.maximum(idx.min(0) - margin, 0)
    hi = idx.max(0) + margin + 1
    s = tuple(slice(l, h) for l, h in zip(lo, hi))
    return a[s], b[s], lo


def atlas_cases(cli, backend, tmp, data):
    aal_path = os.path.join(data, "aal.nii.gz")
    img = nib.load(aal_path)
    lab = np.asarray(img.dataobj)
    aff = img.affine
    st = ndi.generate_binary_structure(3, 1)
    pairs = [("aal_l1_vs_dilated", lab == 1, ndi.binary_dilation(lab == 1, st, iterations=2)),
             ("aal_l37_vs_eroded", lab == 37, ndi.binary_erosion(lab == 37, st)),
             ("aal_l1_vs_l2", lab == 1, lab == 2)]
    for name, a, b in pairs:
        a_path, b_path = os.path.join(tmp, name + "_a.nii.gz"), os.path.join(tmp, name + "_b.nii.gz")
        nib.save(nib.Nifti1Image(a.astype(np.uint8), aff, img.header), a_path)
        nib.save(nib.Nifti1Image(b.astype(np.uint8), aff, img.header), b_path)
        out = run_cli(cli, backend, a_path, b_path, [])
        if out is None:
            continue
        ca, cb, lo = crop_pair(a, b)
        shifted = aff.copy()
        shifted[:3, 3] = nib.affines.apply_affine(aff, lo)
        eps = 1e-6 * diagonal(lab.shape, aff)
        for row in out["results"]:
            conv = row["convention"]
            tag = f"[{backend}] {name} {conv}"
            if conv == "deepmind":
                check_deepmind(tag, row, ca, cb, shifted, [95.0, 50.0, 100.0], 1.0, eps, offset=lo)
                continue
            want = oracle(conv, ca, cb, shifted, [95.0, 50.0, 100.0], 6, 1.0)
            close(tag + " hd", row["hd"], want["hd"], eps)
            close(tag + " msd", row["msd"], want["msd"], eps)
            if conv != "itk":
                close(tag + " assd", row["assd"], want["assd"], eps)
                close(tag + " surface_dice", row["surface_dice"], want["surface_dice"], 1e-12)
                for got, exp in zip(row["hd_percentile"], want["hd_percentile"]):
                    close(tag + f" hd{got['p']:g}", got["value"], exp, eps)
        print(f"{name}: {len(out['results'])} rows checked")
    # Grids that differ: same dims, flipped x axis (HarvardOxford vs JHU), and other dims (aal vs JHU).
    for x, y, what in [("HarvardOxford-cort-maxprob-thr0-1mm.nii.gz", "JHU-WhiteMatter-labels-1mm.nii.gz", "affine"),
                       ("aal.nii.gz", "JHU-WhiteMatter-labels-1mm.nii.gz", "voxels")]:
        p = subprocess.run([cli, os.path.join(data, x), os.path.join(data, y), "--backend", backend],
                           capture_output=True, text=True)
        if p.returncode != 3 or "different grids" not in p.stderr or what not in p.stderr or x not in p.stderr:
            FAILURES.append(f"grid mismatch {x} vs {y}: exit {p.returncode}, stderr {p.stderr.strip()!r}")
        else:
            print(f"grid mismatch {x} vs {y}: exit 3, {p.stderr.strip()}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "nifti"))
    ap.add_argument("--quick", action="store_true", help="fewer synthetic cases, no atlas")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="rthdist_masks_") as tmp:
        synthetic_cases(args.cli, args.backend, tmp, args.quick)
        if not args.quick:
            if os.path.isdir(args.data):
                atlas_cases(args.cli, args.backend, tmp, args.data)
            else:
                FAILURES.append(f"atlas directory {args.data} not found")
    if FAILURES:
        print(f"{len(FAILURES)} mismatches:")
        for f in FAILURES[:200]:
            print("  " + f)
        return 1
    print("all conventions match the oracle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
