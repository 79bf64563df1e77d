#!/usr/bin/env python3
"""The evaluation summary (`rthdist A B --eval`) against an independent
NumPy/SciPy computation on a seeded pair (issue 34, "Done when").

  /usr/bin/python3 tools/bench/eval_check.py [--n 10000000] [--seed 34]
      [--cli build/rthdist] [--work /tmp/rthdist-eval-check] [--out docs/bench/eval]

The pair (float32 binary PLY, written to --work):
  ground truth G: n area-uniform samples of a torus (R = 1, r = 0.35);
  reconstruction R: n other samples of the same torus, moved along the
    normal by Gaussian noise (sigma 1e-3), without a 20-degree sector of the
    ring (a hole the completeness sees), plus 0.2 % outliers uniform in the
    torus' box grown by 0.3 (what the cap drops).
rthdist runs `R.ply G.ply --eval TAUS --eval-cap CAP --json` (A the
reconstruction, B the ground truth; its CPU backend unless --backend).
The independent side: scipy.spatial.cKDTree(workers=-1) over the same
float32 coordinates in float64, both directions, then every metric as
include/rthdist/eval.hpp defines it (accuracy R -> G, completeness G -> R;
d < cap kept for means, medians, max and Chamfer; precision and recall
count d < tau over every distance; NumPy's median).
Compared:
  counts (count, kept, the number below each tau): exactly;
  precision, recall, F-score: exactly (the same counts, divided the same way);
  medians and maxima: to 2^-50 relative (each is one distance, or the mean of
    two; both sides take a distance as the square root of the sum of three
    squared differences in double, an ulp or two apart if they add in
    another order);
  means, mean squares and Chamfer: to kept * 2^-53 relative, the first-order
    bound of summing `kept` doubles one after the other, as rthdist does
    (eval.hpp: "sums in double, in point order"); the reference sums with
    math.fsum (exactly, one rounding), so the difference shown is rthdist's
    summation error (NumPy's pairwise mean is kept in results.json).
Both read the same float32 values, so the file's rounding of the generated
float64 geometry (relative ~6e-8) is common to both and no part of a
difference.
Writes --out/results.json and prints the Markdown table of
docs/bench/eval/README.md. Exit 1 when any metric is outside its tolerance.
"""
import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time

import numpy as np
import scipy
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ply_points import write_ply  # noqa: E402

R_MAJOR, R_MINOR = 1.0, 0.35
NOISE = 1e-3
OUTLIERS = 0.002
HOLE_DEGREES = 20.0
TAUS = [0.0005, 0.001, 0.002, 0.005]
CAP = 0.02
ELEMENT_TOL = 2.0 ** -50


def torus_samples(rng, n):
    """n area-uniform points on the torus and their unit normals (float64)."""
    out, normals, have = [], [], 0
    while have < n:  # rejection on the minor angle: density ~ R + r cos(v)
        m = int((n - have) * 1.6) + 1024
        u = rng.uniform(0.0, 2.0 * np.pi, m)
        v = rng.uniform(0.0, 2.0 * np.pi, m)
        keep = rng.uniform(0.0, R_MAJOR + R_MINOR, m) < R_MAJOR + R_MINOR * np.cos(v)
        u, v = u[keep], v[keep]
        nrm = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
        centre = np.column_stack([R_MAJOR * np.cos(u), R_MAJOR * np.sin(u), np.zeros_like(u)])
        out.append(centre + R_MINOR * nrm)
        normals.append(nrm)
        have += len(u)
    return np.concatenate(out)[:n], np.concatenate(normals)[:n]


def make_pair(n, seed):
    rng = np.random.default_rng(seed)
    truth, _ = torus_samples(rng, n)
    recon, normal = torus_samples(rng, n)
    recon += normal * rng.normal(0.0, NOISE, (n, 1))
    angle = np.degrees(np.arctan2(recon[:, 1], recon[:, 0]))
    recon = recon[~((angle >= 0.0) & (angle < HOLE_DEGREES))]
    k = int(n * OUTLIERS)
    grow = 0.3
    lo = np.array([-(R_MAJOR + R_MINOR) - grow, -(R_MAJOR + R_MINOR) - grow, -R_MINOR - grow])
    outliers = rng.uniform(lo, -lo, (k, 3))
    recon = np.concatenate([recon, outliers])
    return recon.astype(np.float32), truth.astype(np.float32)


def nearest(query, target):
    t0 = time.perf_counter()
    tree = cKDTree(target.astype(np.float64))
    t1 = time.perf_counter()
    d, _ = tree.query(query.astype(np.float64), k=1, workers=-1)
    return d, t1 - t0, time.perf_counter() - t1


def side(d, cap):
    kept = d[d < cap] if cap > 0 else d
    n = len(kept)
    return {"count": int(len(d)), "kept": int(n), "mean": math.fsum(kept.tolist()) / n,
            "median": float(np.median(kept)), "mean_squared": math.fsum((kept * kept).tolist()) / n,
            "max": float(kept.max()), "numpy_mean": float(kept.mean()),
            "numpy_mean_squared": float(np.mean(kept * kept))}


def reference(acc, comp, taus, cap):
    a, c = side(acc, cap), side(comp, cap)
    rows = []
    for t in taus:
        na, nc = int(np.count_nonzero(acc < t)), int(np.count_nonzero(comp < t))
        p, r = na / len(acc), nc / len(comp)
        rows.append({"threshold": t, "precision": p, "recall": r,
                     "fscore": 2 * p * r / (p + r) if p + r > 0 else 0.0, "below_a": na, "below_b": nc})
    chamfer = {"mean_of_means": (a["mean"] + c["mean"]) / 2, "sum_of_means": a["mean"] + c["mean"],
               "sum_of_mean_squares": a["mean_squared"] + c["mean_squared"]}
    return {"accuracy": a, "completeness": c, "chamfer": chamfer, "thresholds": rows}


def rel(got, want):
    if got == want:
        return 0.0
    return abs(got - want) / max(abs(want), 1e-300)


def compare(got, want, n_recon, n_truth):
    """Rows (metric, rthdist, scipy, difference, tolerance, ok)."""
    rows = []

    def exact(name, g, w):
        rows.append((name, g, w, "equal" if g == w else f"{g - w:+d}", "exact", g == w))

    def close(name, g, w, tol):
        r = rel(g, w)
        rows.append((name, g, w, "equal" if r == 0 else f"{r:.1e} rel", f"{tol:.1e} rel", r <= tol))

    sum_tol = {}
    for key in ("accuracy", "completeness"):
        g, w = got[key], want[key]
        exact(f"{key}.count", g["count"], w["count"])
        exact(f"{key}.kept", g["kept"], w["kept"])
        sum_tol[key] = w["kept"] * 2.0 ** -53
        close(f"{key}.mean", g["mean"], w["mean"], sum_tol[key])
        close(f"{key}.median", g["median"], w["median"], ELEMENT_TOL)
        close(f"{key}.mean_squared", g["mean_squared"], w["mean_squared"], sum_tol[key])
        close(f"{key}.max", g["max"], w["max"], ELEMENT_TOL)
    both = max(sum_tol.values())
    for m in ("mean_of_means", "sum_of_means", "sum_of_mean_squares"):
        close(f"chamfer.{m}", got["chamfer"][m], want["chamfer"][m], both)
    for g, w in zip(got["thresholds"], want["thresholds"]):
        t = w["threshold"]
        exact(f"tau {t:g}: accuracy d < tau", int(round(g["precision"] * n_recon)), w["below_a"])
        exact(f"tau {t:g}: completeness d < tau", int(round(g["recall"] * n_truth)), w["below_b"])
        for m in ("precision", "recall", "fscore"):
            r = rel(g[m], w[m])
            rows.append((f"tau {t:g}: {m}", g[m], w[m], "equal" if r == 0 else f"{r:.1e} rel", "exact", r == 0))
    return rows


def fmt(v):
    if isinstance(v, int):
        return str(v)
    return f"{v:.17g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--seed", type=int, default=34)
    ap.add_argument("--cli", default="build/rthdist")
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--work", default="/tmp/rthdist-eval-check")
    ap.add_argument("--out", default="docs/bench/eval")
    args = ap.parse_args()

    os.makedirs(args.work, exist_ok=True)
    t0 = time.perf_counter()
    recon, truth = make_pair(args.n, args.seed)
    path_r = os.path.join(args.work, f"recon_{args.n}_{args.seed}.ply")
    path_g = os.path.join(args.work, f"truth_{args.n}_{args.seed}.ply")
    write_ply(path_r, recon)
    write_ply(path_g, truth)
    gen_s = time.perf_counter() - t0
    print(f"pair: {len(recon)} reconstruction, {len(truth)} ground-truth points ({gen_s:.1f} s)", flush=True)

    cmd = [args.cli, path_r, path_g, "--eval", ",".join(f"{t:g}" for t in TAUS), "--eval-cap", f"{CAP:g}",
           "--json", "--backend", args.backend, "--quiet"]
    t0 = time.perf_counter()
    run = subprocess.run(cmd, capture_output=True, text=True)
    rthdist_s = time.perf_counter() - t0
    if run.returncode != 0:
        sys.exit(f"rthdist failed ({run.returncode}): {run.stderr}")
    doc = json.loads(run.stdout)
    got = doc["eval"]
    print(f"rthdist: {rthdist_s:.1f} s", flush=True)

    acc, build_a, query_a = nearest(recon, truth)
    comp, build_c, query_c = nearest(truth, recon)
    want = reference(acc, comp, TAUS, CAP)
    scipy_s = build_a + query_a + build_c + query_c
    print(f"cKDTree: {scipy_s:.1f} s", flush=True)

    rows = compare(got, want, len(recon), len(truth))
    ok = all(r[-1] for r in rows)
    print("\n| metric | rthdist | NumPy/SciPy (cKDTree, float64; sums by math.fsum) | difference | tolerance |")
    print("|---|---|---|---|---|")
    for name, g, w, diff, tol, good in rows:
        print(f"| {name} | {fmt(g)} | {fmt(w)} | {diff}{'' if good else ' FAIL'} | {tol} |")
    print(f"\n{'all metrics within tolerance' if ok else 'MISMATCH'}; rthdist {rthdist_s:.1f} s "
          f"(evaluate {doc['timings_ms']['evaluate'] / 1000:.1f} s), cKDTree builds {build_a + build_c:.1f} s "
          f"+ queries {query_a + query_c:.1f} s")

    os.makedirs(args.out, exist_ok=True)
    record = {
        "command": " ".join(["/usr/bin/python3", "tools/bench/eval_check.py", "--n", str(args.n), "--seed",
                             str(args.seed), "--backend", args.backend]),
        "rthdist_command": " ".join(cmd),
        "n": args.n, "seed": args.seed, "points": {"a": len(recon), "b": len(truth)},
        "taus": TAUS, "cap": CAP, "noise": NOISE, "outliers": OUTLIERS, "hole_degrees": HOLE_DEGREES,
        "rthdist": {"version": doc["version"], "eval": got, "timings_ms": doc["timings_ms"], "wall_s": rthdist_s},
        "reference": {"eval": want, "scipy": scipy.__version__, "numpy": np.__version__,
                      "ckdtree_build_s": build_a + build_c, "ckdtree_query_s": query_a + query_c},
        "rows": [{"metric": r[0], "rthdist": r[1], "reference": r[2], "difference": r[3], "tolerance": r[4],
                  "ok": r[5]} for r in rows],
        "ok": ok,
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version()},
    }
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump(record, f, indent=1)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
