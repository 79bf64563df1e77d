#!/usr/bin/python3
"""HD95 on segmentation masks: rthdist-masks against the SciPy-EDT
implementation of the MONAI convention, same machine, same run.

  masks_bench.py --cli build/rthdist-masks [--itk build-masks-itk/itk-hausdorff]
                 [--out docs/bench/masks/results.json] [--data ../shared/data/nifti]
                 [--runs 3] [--size 512,512,300]

Cases (written once as uncompressed .nii into --work):
  organ   512 x 512 x 300, spacing 0.8 x 0.8 x 2.5 mm: a smooth organ-like
          blob (an ellipsoid with low-frequency bumps) against a deformed,
          shifted copy (a realistic prediction)
  noisy   the same reference against the prediction with a ragged boundary
          (voxels flipped in a 3-voxel band) and scattered false positives
          (0.02 % of the volume, fixed seed)
  atlas   aal.nii.gz (181 x 217 x 181, 1 mm): a large label against its
          2-voxel dilation, and two neighbouring labels
Timings, each the median of --runs:
  rthdist     the library's time inside rthdist-masks (label selection,
              boundary extraction, both directions with per-point distances,
              percentiles) for a volume already in host memory, from its JSON:
              each process compares the pair 5 times on one Engine
              (--repeat 5), the median of the warm comparisons is reported,
              with the first comparison of a process (buffers allocated
              then) beside it
  scipy-monai the MONAI convention written with NumPy/SciPy from arrays in
              memory: crop to the union's box (MONAI's get_mask_edges),
              edges = m XOR binary_erosion(m), distance_transform_edt of each
              edge complement with the spacing, read at the other's edges,
              numpy.percentile 95 per direction, max. MONAI itself is not
              installed here (no PyTorch); this is its algorithm. One run
              when the first takes over 10 s.
  itk         ITK 5.2's HausdorffDistanceImageFilter (tools/bench/masks_itk,
              Debian libinsighttoolkit5-dev): filter->Update() with the images
              in memory. It computes HD and the average HD, no percentile; its
              values are checked against rthdist-masks --convention itk.
Both HD95 values are printed so that agreement can be checked (they must be
equal to 1e-6 of the diagonal).
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time

import nibabel as nib
import numpy as np
from scipy import ndimage as ndi


def organ(shape, spacing, centre, radii, bumps, seed):
    """Smooth blob: ellipsoid level set plus low-frequency sinusoidal bumps (in mm)."""
    rng = np.random.default_rng(seed)
    axes = [(np.arange(n, dtype=np.float32) - c) * s for n, c, s in zip(shape, centre, spacing)]
    x, y, z = axes[0][:, None, None], axes[1][None, :, None], axes[2][None, None, :]
    f = (x / radii[0]) ** 2 + (y / radii[1]) ** 2 + (z / radii[2]) ** 2
    for _ in range(bumps):
        k = rng.uniform(0.02, 0.06, 3).astype(np.float32)
        ph = rng.uniform(0, 2 * np.pi, 3).astype(np.float32)
        f = f + np.float32(0.08) * (np.sin(k[0] * x + ph[0]) * np.sin(k[1] * y + ph[1]) * np.sin(k[2] * z + ph[2]))
    return f <= 1.0


def make_cases(work, size):
    os.makedirs(work, exist_ok=True)
    spacing = (0.8, 0.8, 2.5)
    aff = np.diag(list(spacing) + [1.0])
    paths = {}
    names = ["organ_ref", "organ_pred", "noisy_pred"]
    if all(os.path.exists(os.path.join(work, n + ".nii")) for n in names):
        return {n: os.path.join(work, n + ".nii") for n in names}, spacing
    c = [size[0] / 2, size[1] / 2, size[2] / 2]
    ref = organ(size, spacing, c, (110.0, 80.0, 180.0), 6, 1)
    pred = organ(size, spacing, [c[0] + 3, c[1] - 2, c[2] + 1], (112.0, 77.0, 176.0), 6, 2)
    rng = np.random.default_rng(3)
    band = ndi.binary_dilation(pred, iterations=3) & ~ndi.binary_erosion(pred, iterations=3)
    flip = band & (rng.random(size, dtype=np.float32) < 0.3)
    noisy = pred ^ flip
    speck = rng.random(size, dtype=np.float32) < 0.0002
    noisy |= speck
    for n, m in zip(names, [ref, pred, noisy]):
        p = os.path.join(work, n + ".nii")
        nib.save(nib.Nifti1Image(m.astype(np.uint8), aff), p)
        paths[n] = p
    return paths, spacing


def scipy_monai_hd95(a, b, spacing):
    """MONAI's compute_hausdorff_distance(percentile=95) with SciPy, arrays in memory."""
    idx = np.argwhere(a | b)
    lo, hi = idx.min(0), idx.max(0) + 1
    s = tuple(slice(l, h) for l, h in zip(lo, hi))
    a, b = a[s], b[s]
    ea = a ^ ndi.binary_erosion(a)
    eb = b ^ ndi.binary_erosion(b)
    da = ndi.distance_transform_edt(~eb, sampling=spacing)[ea]
    db = ndi.distance_transform_edt(~ea, sampling=spacing)[eb]
    return max(np.percentile(da, 95), np.percentile(db, 95))


def time_scipy(a, b, spacing, runs):
    times, value = [], None
    for _ in range(runs):
        t = time.perf_counter()
        value = scipy_monai_hd95(a, b, spacing)
        times.append(time.perf_counter() - t)
        if times[0] > 10.0:
            break
    return statistics.median(times), float(value)


def run_itk(itk, cli, a_path, b_path, runs, threads):
    p = subprocess.run([itk, a_path, b_path, "--runs", str(runs), "--threads", threads], capture_output=True,
                       text=True, check=True)
    peer = json.loads(p.stdout)
    q = subprocess.run([cli, a_path, b_path, "--json", "--convention", "itk", "--backend", "cpu"],
                       capture_output=True, text=True, check=True)
    row = json.loads(q.stdout)["results"][0]
    return {"s": peer["ms"] / 1000.0, "hd": peer["hd"], "average_hd": peer["average_hd"],
            "rthdist_itk_hd": row["hd"], "rthdist_itk_average_hd": row["msd"],
            "rthdist_itk_s": row["timings_ms"]["total"] / 1000.0}


def time_rthdist(cli, a_path, b_path, runs, backend, extra, repeat=5):
    """`runs` processes, each comparing the pair `repeat` times on one Engine
    (--repeat): lib_s is the median of the warm comparisons (each process's
    later ones), first_s the median of each process's first comparison
    (device and scratch memory allocated during it), wall_s the median
    process time (file reading and --repeat comparisons included)."""
    warm, first, wall, value, out = [], [], [], None, None
    for _ in range(runs):
        t = time.perf_counter()
        p = subprocess.run([cli, a_path, b_path, "--json", "--convention", "monai", "--backend", backend,
                            "--repeat", str(repeat)] + extra, capture_output=True, text=True, check=True)
        wall.append(time.perf_counter() - t)
        out = json.loads(p.stdout)
        row = out["results"][0]
        totals = row.get("repeat_total_ms", [row["timings_ms"]["total"]])
        first.append(totals[0] / 1000.0)
        warm.extend(x / 1000.0 for x in totals[1:])
        value = row["hd_percentile"][0]["value"]
    row = out["results"][0]
    return {"lib_s": statistics.median(warm or first), "first_s": statistics.median(first),
            "wall_s": statistics.median(wall), "repeat": repeat, "hd95": value,
            "points": [row["a_to_b"]["points"], row["b_to_a"]["points"]],
            "extract_ms": row["timings_ms"]["extract"], "distance_ms": row["timings_ms"]["distance"],
            "extraction": row.get("extraction"), "backend": out["backend"], "device": out["device"]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--out", default="docs/bench/masks/results.json")
    ap.add_argument("--work", default="/tmp/rthdist_masks_bench")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "nifti"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--size", default="512,512,300")
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--threads", default="0")
    ap.add_argument("--itk", default="", help="itk-hausdorff binary (tools/bench/masks_itk)")
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split(","))
    t = time.perf_counter()
    paths, spacing = make_cases(args.work, size)
    print(f"cases ready in {time.perf_counter() - t:.1f} s", file=sys.stderr)

    cases = [("organ", paths["organ_ref"], paths["organ_pred"], []),
             ("noisy", paths["organ_ref"], paths["noisy_pred"], [])]
    aal = os.path.join(args.data, "aal.nii.gz")
    img = nib.load(aal)
    lab = np.asarray(img.dataobj)
    for name, a, b in [("atlas_l2_vs_dilated", lab == 2, ndi.binary_dilation(lab == 2, iterations=2)),
                       ("atlas_l1_vs_l2", lab == 1, lab == 2)]:
        pa, pb = os.path.join(args.work, name + "_a.nii"), os.path.join(args.work, name + "_b.nii")
        nib.save(nib.Nifti1Image(a.astype(np.uint8), img.affine), pa)
        nib.save(nib.Nifti1Image(b.astype(np.uint8), img.affine), pb)
        cases.append((name, pa, pb, []))

    rows = []
    load_before = os.getloadavg()
    for name, pa, pb, extra in cases:
        ia, ib = nib.load(pa), nib.load(pb)
        a = np.asarray(ia.dataobj) > 0
        b = np.asarray(ib.dataobj) > 0
        sp = tuple(float(v) for v in ia.header.get_zooms()[:3])
        r = time_rthdist(args.cli, pa, pb, args.runs, args.backend, extra + ["--threads", args.threads])
        s_time, s_value = time_scipy(a, b, sp, args.runs)
        diag = float(np.linalg.norm((np.array(a.shape) - 1) * np.array(sp)))
        row = {"case": name, "shape": list(a.shape), "spacing": list(sp), "voxels_a": int(a.sum()),
               "voxels_b": int(b.sum()), "rthdist": r, "scipy_monai": {"s": s_time, "hd95": s_value},
               "speedup_lib": s_time / r["lib_s"], "speedup_first": s_time / r["first_s"],
               "agree": abs(s_value - r["hd95"]) <= 1e-6 * diag}
        print(f"{name:22s} rthdist {r['lib_s'] * 1000:9.1f} ms (first {r['first_s'] * 1000:8.1f} ms)  "
              f"scipy-monai {s_time * 1000:9.1f} ms  x{row['speedup_lib']:.1f}  HD95 {r['hd95']:.6f} vs {s_value:.6f}"
              f"  agree {row['agree']}", file=sys.stderr)
        if args.itk:
            threads = args.threads if args.threads != "0" else str(os.cpu_count())
            k = run_itk(args.itk, args.cli, pa, pb, args.runs, threads)
            row["itk"] = k
            row["speedup_itk"] = k["s"] / r["lib_s"]
            row["agree"] = row["agree"] and abs(k["hd"] - k["rthdist_itk_hd"]) <= 1e-6 * diag and \
                abs(k["average_hd"] - k["rthdist_itk_average_hd"]) <= 1e-6 * diag
            print(f"{'':22s} itk {k['s'] * 1000:9.1f} ms  x{row['speedup_itk']:.1f}  HD {k['hd']:.6f} vs "
                  f"{k['rthdist_itk_hd']:.6f}  avg {k['average_hd']:.6f} vs {k['rthdist_itk_average_hd']:.6f}",
                  file=sys.stderr)
        rows.append(row)
    result = {"machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                          "processor": platform.processor(), "loadavg_after": os.getloadavg()},
              "loadavg_before": load_before, "numpy": np.__version__, "scipy": __import__("scipy").__version__, "runs": args.runs,
              "cases": rows}
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    return 0 if all(r["agree"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
