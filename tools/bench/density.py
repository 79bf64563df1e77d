#!/usr/bin/python3
"""The "density" benchmark family (issue 17): inputs whose density is far from
even, timed for rthdist and SciPy's cKDTree in the same run.

  /usr/bin/python3 tools/bench/density.py --data ../shared/data --bench build-density/rthdist-bench \\
      --out docs/bench/density [--rows a,b] [--backends cpu,ray-query] [--gpu-max-points 1000000]
  /usr/bin/python3 tools/bench/density.py --report docs/bench/density/results.json   (re-render only)

Rows (fixed seeds, both sets written once as float32 binary PLY under --work):
  cluster-200k/1M/5M  N points uniform in a 1 mm cube at the origin per set
                      (seeds 1 and 2) + one common point at (1000, 1000, 1000) m,
                      1.7 km away: the whole cluster falls into one grid cell
  cauchy-200k/1M      N points per set, each coordinate standard Cauchy
                      (seeds 3 and 4)
  lidar-fsite8-stray  FSite8_orig vs FSite8_red1 (airborne LiDAR, UTM, float32)
                      + the same 10 stray points 5 km from the site's centre in
                      both sets (seed 5)
  dragon-far-vertex   Dragon (437,645) vs its decimation res2 (100,250) + the
                      same far vertex 1 km away in both sets
Issue 33's rows (not run by default: --rows far-..., or --rows extra for all):
  far-S-one/both      300,000 points per set uniform in an S cube at the origin
                      (S = 0.1, 1, 10 mm; seeds 6 and 7) + 10 strays 1-10 km
                      away in random directions in A only (seed 8), or each
                      set its own (seeds 8 and 9): the far-cluster family
  crowded-200k/2M     a noisy sphere of radius 0.05 (noise 2e-5) at the
                      centre of the unit box, the box's corners 0 and 1 in
                      each set (seeds 10 and 11; scale_gen's "crowded")
Timing: rthdist-bench (median of --runs timed calls after one warm-up, stage
medians, the process's own Engine, all hardware threads); cKDTree as in
peers.py (two trees, two query() calls with workers=-1, builds included,
median of --runs). A run over its cap is killed and reported as "> cap".
Growth: the exponent of t ~ n^p fitted on log t vs log n over the cluster
rows, beside the exponent n log n itself has over the same sizes.
"""
import argparse
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
PY = "/usr/bin/python3"
sys.path.insert(0, HERE)
from ply_points import read_ply, write_ply  # noqa: E402

OUTLIER = (1000.0, 1000.0, 1000.0)
ROWS = ["cluster-200k", "cluster-1M", "cluster-5M", "cauchy-200k", "cauchy-1M", "lidar-fsite8-stray",
        "dragon-far-vertex"]
FAR_ROWS = ["far-%smm-%s" % (side, where) for side in ("0.1", "1", "10") for where in ("one", "both")]
EXTRA_ROWS = FAR_ROWS + ["crowded-200k", "crowded-2M"]
SIZES = {"200k": 200_000, "1M": 1_000_000, "2M": 2_000_000, "5M": 5_000_000}


def log(msg):
    print("[density %s] %s" % (time.strftime("%H:%M:%S"), msg), file=sys.stderr, flush=True)


FAR_N = 300_000


def strays(seed):
    """10 points 1-10 km from the origin in random directions."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(10, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(1000.0, 10000.0, (10, 1))


def crowded(n, seed):
    """The scale suite's crowded case (tools/bench/scale_gen.cpp) in NumPy."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    p = 0.5 + 0.05 * d / np.linalg.norm(d, axis=1, keepdims=True) + 2e-5 * rng.normal(size=(n, 3))
    p[0], p[1] = 0.0, 1.0
    return p


def make_row(name, data):
    """(a, b, description) as float32 arrays."""
    if name.startswith("cluster-"):
        n = SIZES[name.split("-")[1]]
        a = np.random.default_rng(1).uniform(0.0, 1e-3, (n, 3))
        b = np.random.default_rng(2).uniform(0.0, 1e-3, (n, 3))
        far = np.array([OUTLIER])
        return (np.vstack([a, far]).astype(np.float32), np.vstack([b, far]).astype(np.float32),
                "%d points in a 1 mm cube + one common point 1.7 km away, per set" % n)
    if name.startswith("far-"):
        # far-<side>mm-<one|both>: issue 33's far-cluster family (see the docstring).
        _, side, where = name.split("-")
        side = float(side[:-2]) * 1e-3
        a = np.random.default_rng(6).uniform(0.0, side, (FAR_N, 3))
        b = np.random.default_rng(7).uniform(0.0, side, (FAR_N, 3))
        a = np.vstack([a, strays(8)])
        if where == "both":
            b = np.vstack([b, strays(9)])
        return (a.astype(np.float32), b.astype(np.float32),
                "%d points per set in a %g mm cube at the origin + 10 strays 1-10 km away in %s" %
                (FAR_N, side * 1e3, "A" if where == "one" else "each set (their own)"))
    if name.startswith("crowded-"):
        n = SIZES[name.split("-")[1]]
        a, b = crowded(n, 10), crowded(n, 11)
        return a.astype(np.float32), b.astype(np.float32), \
            "%d points per set on a noisy sphere of radius 0.05 in the unit box (its corners in both)" % n
    if name.startswith("cauchy-"):
        n = SIZES[name.split("-")[1]]
        a = np.random.default_rng(3).standard_cauchy((n, 3))
        b = np.random.default_rng(4).standard_cauchy((n, 3))
        return a.astype(np.float32), b.astype(np.float32), "%d points per set, standard Cauchy coordinates" % n
    if name == "lidar-fsite8-stray":
        a = read_ply(os.path.join(data, "lidar/FSite8_orig-utm.ply")).astype(np.float64)
        b = read_ply(os.path.join(data, "lidar/FSite8_red1-utm.ply")).astype(np.float64)
        centre = 0.5 * (a.min(0) + a.max(0))
        d = np.random.default_rng(5).normal(size=(10, 3))
        stray = centre + 5000.0 * d / np.linalg.norm(d, axis=1, keepdims=True)
        return (np.vstack([a, stray]).astype(np.float32), np.vstack([b, stray]).astype(np.float32),
                "FSite8_orig vs FSite8_red1 + the same 10 stray points 5 km away in both")
    if name == "dragon-far-vertex":
        a = read_ply(os.path.join(data, "stanford/dragon/dragon_vrip.ply.gz")).astype(np.float64)
        b = read_ply(os.path.join(data, "stanford/dragon/dragon_vrip_res2.ply.gz")).astype(np.float64)
        far = a.min(0) + np.array([[1000.0, 0.0, 0.0]])
        return (np.vstack([a, far]).astype(np.float32), np.vstack([b, far]).astype(np.float32),
                "Dragon vs Dragon res2 + the same vertex 1 km away in both")
    raise SystemExit("unknown row " + name)


def prepare(name, data, work):
    meta_path = os.path.join(work, name + ".json")
    if os.path.exists(meta_path):
        with open(meta_path) as f:
            return json.load(f)
    log("preparing " + name)
    a, b, what = make_row(name, data)
    meta = {"name": name, "what": what, "a_ply": os.path.join(work, name + "_a.ply"),
            "b_ply": os.path.join(work, name + "_b.ply"), "points": [len(a), len(b)]}
    write_ply(meta["a_ply"], a)
    write_ply(meta["b_ply"], b)
    with open(meta_path, "w") as f:
        json.dump(meta, f)
    return meta


def run_json(cmd, cap):
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=cap)
    except subprocess.TimeoutExpired:
        return None, "capped", time.perf_counter() - t0
    lines = [l for l in p.stdout.splitlines() if l.startswith("{")]
    if p.returncode != 0 or not lines:
        return {"error": (p.stderr or p.stdout)[-600:]}, "error", time.perf_counter() - t0
    return json.loads(lines[-1]), "ok", time.perf_counter() - t0


def rthdist_row(bench, meta, backend, runs, cap):
    cmd = [bench, meta["a_ply"], meta["b_ply"], "--backend", backend, "--name", meta["name"], "--runs", str(runs),
           "--warmup", "1"]
    if backend == "cpu":
        cmd.append("--no-verify")  # rthdist-bench's check is the CPU backend itself
    out, status, dt = run_json(cmd, cap)
    row = {"tool": "rthdist-" + backend, "status": status, "process_s": dt, "cap_s": cap}
    if status == "ok":
        m = out["median_ms"]
        row.update({"seconds": m["wall"] / 1e3, "median_ms": m, "wall_ms_all": out["wall_ms_all"],
                    "hausdorff": out["hausdorff"], "h_ab": out["h_ab"], "h_ba": out["h_ba"], "bits": out["bits"],
                    "counters": out["counters"], "runs": out["runs"], "agree_cpu": out.get("agree"),
                    "max_rss_kb": out.get("max_rss_kb")})
    elif status == "error":
        row["error"] = out["error"]
    return row


def ckdtree_row(meta, runs, cap):
    cmd = [PY, os.path.join(HERE, "peers.py"), "ckdtree", meta["a_ply"], meta["b_ply"], "--max-runs", str(runs),
           "--budget", "1e9"]
    out, status, dt = run_json(cmd, cap)
    row = {"tool": "ckdtree", "status": status, "process_s": dt, "cap_s": cap}
    if status == "ok":
        row.update({"seconds": out["seconds"], "seconds_all": out["seconds_all"], "hausdorff": out["hausdorff"],
                    "h_ab": out["h_ab"], "h_ba": out["h_ba"]})
    elif status == "error":
        row["error"] = out["error"]
    return row


def slope(points):
    """Least-squares exponent p of t ~ n^p over (n, t) pairs."""
    if len(points) < 2:
        return None
    x = np.log([p[0] for p in points])
    y = np.log([p[1] for p in points])
    return float(np.polyfit(x, y, 1)[0])


def fmt(s):
    if s is None:
        return "-"
    return "%.3g" % s


def cell(row):
    if row is None:
        return "not run"
    if row["status"] == "capped":
        return "> %g" % row["cap_s"]
    if row["status"] != "ok":
        return "error"
    return fmt(row["seconds"])


def report(results, out_dir):
    rows = results["rows"]
    lines = ["# Density benchmark (issue 17): clusters, strays and heavy tails", "",
             "Generated by `tools/bench/density.py` (see its docstring for the exact inputs and seeds); "
             "results.json holds every number. Machine: %s, %s cores, %s; rthdist %s%s; numpy %s, scipy %s; %s." % (
                 results["machine"]["cpu"], results["machine"]["cores"], results["machine"]["os"],
                 results["machine"]["rthdist_commit"], " (dirty tree)" if results["machine"]["rthdist_dirty"] else "",
                 results["machine"]["numpy"], results["machine"]["scipy"], results["machine"]["date_utc"]),
             "",
             "Times in seconds, both directions (symmetric H), median of %d timed calls (rthdist: after one "
             "warm-up call, same Engine; cKDTree: tree builds included). Loading is not timed." % results["runs"],
             "", "| row | points A / B | H | rthdist cpu | cKDTree | **cpu / cKDTree** | ray-query (lavapipe) | "
             "ray-query / cKDTree | values agree |", "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for name, r in rows.items():
        cpu, kd, rq = r["tools"].get("rthdist-cpu"), r["tools"].get("ckdtree"), r["tools"].get("rthdist-ray-query")
        ratio = rq_ratio = None
        if cpu and kd and cpu["status"] == "ok" and kd["status"] == "ok":
            ratio = cpu["seconds"] / kd["seconds"]
        if rq and kd and rq["status"] == "ok" and kd["status"] == "ok":
            rq_ratio = rq["seconds"] / kd["seconds"]
        h = cpu["hausdorff"] if cpu and cpu["status"] == "ok" else None
        lines.append("| %s | %s / %s | %s | %s | %s | **%s** | %s | %s | %s |" % (
            name, "{:,}".format(r["points"][0]), "{:,}".format(r["points"][1]), "%.9g" % h if h is not None else "-",
            cell(cpu), cell(kd), fmt(ratio), cell(rq), fmt(rq_ratio), r.get("agree", "-")))
    lines += ["", "Stage medians of rthdist cpu (ms, both directions; index = target index + query order, "
              "cull = lower bound, search = the pass over all queries):", "",
              "| row | wall | index | cull | search | refine | bits A->B / B->A | surviving queries A->B / B->A |",
              "|---|---:|---:|---:|---:|---:|---|---|"]
    for name, r in rows.items():
        cpu = r["tools"].get("rthdist-cpu")
        if not cpu or cpu["status"] != "ok":
            continue
        m, c = cpu["median_ms"], cpu.get("counters", [])
        surv = " / ".join("{:,}".format(d.get("surviving", 0)) for d in c) or "-"
        lines.append("| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %s | %s |" % (
            name, m["wall"], m["index"], m["cull"], m["search"], m["refine"],
            " / ".join(str(b) for b in cpu.get("bits", [])), surv))
    g = results.get("growth")
    if g:
        lines += ["", "Growth over the cluster rows (%s points per set): fitted exponent of t ~ n^p" % (
            ", ".join("{:,}".format(n) for n in g["n"])), "",
            "| tool | times (s) | exponent p | t(largest) / t(smallest) |", "|---|---|---:|---:|"]
        for tool, v in g["tools"].items():
            lines.append("| %s | %s | %s | %s |" % (tool, " / ".join(fmt(t) for t in v["seconds"]),
                                                    fmt(v["exponent"]), fmt(v["ratio"])))
        lines.append("| n log n (reference) | | %s | %s |" % (fmt(g["nlogn_exponent"]), fmt(g["nlogn_ratio"])))
    lines += ["", results.get("notes", "")]
    with open(os.path.join(out_dir, "README.md"), "w") as f:
        f.write("\n".join(lines).rstrip() + "\n")


def machine_info(bench):
    def sh(cmd):
        try:
            return subprocess.run(cmd, capture_output=True, text=True).stdout.strip()
        except OSError:
            return ""
    cpu = "unknown"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    import scipy
    return {"date_utc": datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%M:%SZ"), "cpu": cpu,
            "cores": os.cpu_count(), "os": platform.platform(), "numpy": np.__version__,
            "scipy": scipy.__version__, "rthdist_bench": bench,
            "rthdist_commit": sh(["git", "-C", REPO, "rev-parse", "--short", "HEAD"]),
            "rthdist_dirty": bool(sh(["git", "-C", REPO, "status", "--porcelain", "--", "src", "include"])),
            "load_avg_start": os.getloadavg()}


def agree(row):
    """rthdist cpu vs cKDTree (and ray-query) within design.md §1's tolerance (1e-6 of the diagonal)."""
    tools = row["tools"]
    cpu = tools.get("rthdist-cpu")
    if not cpu or cpu["status"] != "ok":
        return "-"
    tol = 1e-6 * row["diagonal"] + 8 * 2 ** -24 * cpu["hausdorff"]
    bad = [t for t, r in tools.items() if r["status"] == "ok" and abs(r["hausdorff"] - cpu["hausdorff"]) > tol]
    return "yes" if not bad else "NO (" + ", ".join(bad) + ")"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=os.path.join(REPO, "..", "shared", "data"))
    ap.add_argument("--bench", default=os.path.join(REPO, "build-density", "rthdist-bench"))
    ap.add_argument("--work", default="/tmp/rthdist-density-work")
    ap.add_argument("--out", default=os.path.join(REPO, "docs", "bench", "density"))
    ap.add_argument("--rows", default=",".join(ROWS))
    ap.add_argument("--backends", default="cpu", help="rthdist backends, e.g. cpu,ray-query")
    ap.add_argument("--tools", default="ckdtree", help="peers: ckdtree or none")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cap", type=float, default=600.0, help="seconds per process")
    ap.add_argument("--gpu-max-points", type=int, default=1_000_000, help="lavapipe rows up to this size per set")
    ap.add_argument("--gpu-cap", type=float, default=300.0)
    ap.add_argument("--merge", action="store_true", help="update the rows of an existing results.json")
    ap.add_argument("--report", help="re-render README.md from this results.json")
    args = ap.parse_args()
    if args.report:
        with open(args.report) as f:
            report(json.load(f), os.path.dirname(os.path.abspath(args.report)))
        return
    os.makedirs(args.work, exist_ok=True)
    os.makedirs(args.out, exist_ok=True)
    out_json = os.path.join(args.out, "results.json")
    results = {"rows": {}}
    if args.merge and os.path.exists(out_json):
        with open(out_json) as f:
            results = json.load(f)
    if not args.merge:
        results.update({"machine": machine_info(args.bench), "runs": args.runs})
    if args.merge:
        results.setdefault("merged_runs", []).append({"backends": args.backends, "tools": args.tools,
                                                      "runs": args.runs, "machine": machine_info(args.bench)})
    names = [r for x in args.rows.split(",") for r in (EXTRA_ROWS if x == "extra" else [x])]
    for name in names:
        meta = prepare(name, args.data, args.work)
        a, b = read_ply(meta["a_ply"]).astype(np.float64), read_ply(meta["b_ply"]).astype(np.float64)
        both = np.vstack([a, b])
        diagonal = float(np.linalg.norm(both.max(0) - both.min(0)))
        del a, b, both
        row = results["rows"].get(name, {"tools": {}})
        row.update({"what": meta["what"], "points": meta["points"], "diagonal": diagonal})
        for backend in args.backends.split(","):
            if backend != "cpu" and max(meta["points"]) > args.gpu_max_points:
                continue
            log("%s: rthdist %s" % (name, backend))
            cap = args.cap if backend == "cpu" else args.gpu_cap
            row["tools"]["rthdist-" + backend] = rthdist_row(args.bench, meta, backend, args.runs, cap)
            log("  -> %s" % cell(row["tools"]["rthdist-" + backend]))
        if "ckdtree" in args.tools.split(","):
            log("%s: cKDTree" % name)
            row["tools"]["ckdtree"] = ckdtree_row(meta, args.runs, args.cap)
            log("  -> %s" % cell(row["tools"]["ckdtree"]))
        row["agree"] = agree(row)
        results["rows"][name] = row
        with open(out_json, "w") as f:
            json.dump(results, f, indent=1)
    # Growth over the cluster rows.
    sizes = [n for n in ("200k", "1M", "5M") if "cluster-" + n in results["rows"]]
    if len(sizes) >= 2:
        ns = [SIZES[s] for s in sizes]
        growth = {"n": ns, "tools": {}, "nlogn_exponent": slope([(n, n * math.log(n)) for n in ns]),
                  "nlogn_ratio": ns[-1] * math.log(ns[-1]) / (ns[0] * math.log(ns[0]))}
        for tool in ("rthdist-cpu", "ckdtree", "rthdist-ray-query"):
            pts = [(SIZES[s], results["rows"]["cluster-" + s]["tools"].get(tool, {}).get("seconds")) for s in sizes]
            pts = [p for p in pts if p[1]]
            if len(pts) >= 2:
                growth["tools"][tool] = {"seconds": [p[1] for p in pts], "exponent": slope(pts),
                                         "ratio": pts[-1][1] / pts[0][1]}
        results["growth"] = growth
    if not args.merge:
        results["machine"]["load_avg_end"] = os.getloadavg()
    with open(out_json, "w") as f:
        json.dump(results, f, indent=1)
    report(results, args.out)
    log("wrote %s and README.md" % out_json)


if __name__ == "__main__":
    main()
