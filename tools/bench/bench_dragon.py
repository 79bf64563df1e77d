#!/usr/bin/env python3
"""Benchmark: rthdist against SciPy's exact cKDTree on the Stanford Dragon.

Cases (the paper's decimation and translation scenarios, DESIGN.md section 7):
  dragon-res2       dragon_vrip.ply.gz vs Stanford's own decimation dragon_vrip_res2.ply.gz
  dragon-translate  dragon_vrip.ply.gz vs a copy moved by 0.5 of its x-extent along x
                    (float32 arithmetic, written as a binary PLY into a temp dir)

For each case and backend, rthdist runs --json --repeat times; the table
reports the median of timings_ms.total (the computation, without device setup) and of the wall
time of the whole process (load + device setup + compute). cKDTree (SciPy,
workers=-1) is timed on tree builds plus queries in both directions (exact H,
no file loading), median over --repeat runs. Values are checked to agree
within 1e-6 of the larger bounding-box diagonal (the library's contract).

Writes a Markdown table and JSON (default docs/bench/dragon_lavapipe.{md,json}).
This is a tool, not a test: it asserts nothing about speed.

Dependencies: RTHDIST_BENCH_DEPS=1 bash tools/install-deps.sh (python3-scipy, numpy).
Usage: python3 tools/bench/bench_dragon.py [--build build] [--data ../shared/data]
"""

import argparse
import gzip
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

try:
    import numpy as np
    import scipy
    from scipy.spatial import cKDTree
except ImportError:
    # A pyenv/venv python may shadow Debian's, which has python3-scipy.
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath(
            "/usr/bin/python3") and not os.environ.get("RTHDIST_BENCH_REEXEC"):
        os.environ["RTHDIST_BENCH_REEXEC"] = "1"
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("bench_dragon: needs numpy and scipy: RTHDIST_BENCH_DEPS=1 bash tools/install-deps.sh")


# ---- input -----------------------------------------------------------------

def read_ply_vertices(path):
    """x, y, z of an ASCII PLY (optionally gzipped) as float32 (N, 3)."""
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise ValueError(f"{path}: not a PLY file")
        count, props, in_vertex, fmt = None, [], False, None
        while True:
            line = f.readline()
            if not line:
                raise ValueError(f"{path}: header without end_header")
            words = line.split()
            if not words:
                continue
            if words[0] == b"format":
                fmt = words[1].decode()
            elif words[0] == b"element":
                in_vertex = words[1] == b"vertex"
                if in_vertex:
                    count = int(words[2])
            elif words[0] == b"property" and in_vertex:
                if words[1] == b"list":
                    raise ValueError(f"{path}: list property in vertex element")
                props.append(words[-1].decode())
            elif words[0] == b"end_header":
                break
        if fmt != "ascii":
            raise ValueError(f"{path}: only ascii PLY is parsed here (format {fmt})")
        cols = [props.index(c) for c in ("x", "y", "z")]
        # Vertices come first in the Stanford files; parse exactly `count` lines.
        data = np.loadtxt(f, dtype=np.float64, max_rows=count, usecols=cols, ndmin=2)
    if data.shape[0] != count:
        raise ValueError(f"{path}: {data.shape[0]} of {count} vertices")
    # The float32 values rthdist works on (the file's decimal text rounded once).
    return data.astype(np.float32)


def write_binary_ply(path, points):
    points = np.ascontiguousarray(points, dtype="<f4")
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(points)}\n"
              "property float x\nproperty float y\nproperty float z\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(points.tobytes())


def bbox_diagonal(points):
    p = points.astype(np.float64)
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))


# ---- the two contenders -----------------------------------------------------

def run_rthdist(binary, a_path, b_path, backend, repeat, extra):
    runs = []
    for _ in range(repeat):
        cmd = [binary, "--json", "--backend", backend, *extra, a_path, b_path]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = (time.perf_counter() - t0) * 1e3
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)}: exit {proc.returncode}\n{proc.stderr}")
        out = json.loads(proc.stdout)
        out["_wall_ms"] = wall
        runs.append(out)
    last = runs[-1]
    med = lambda key: statistics.median(r["timings_ms"][key] for r in runs)
    return {
        "backend": last["backend"],
        "device": last["device"],
        "bits": last["bits"],
        "hausdorff": last["hausdorff"],
        "a_to_b": last["a_to_b"]["distance"],
        "b_to_a": last["b_to_a"]["distance"],
        "witness_a_to_b": [last["a_to_b"]["a_index"], last["a_to_b"]["b_index"]],
        "witness_b_to_a": [last["b_to_a"]["b_index"], last["b_to_a"]["a_index"]],
        "total_ms_median": med("total"),
        "setup_ms_median": med("setup"),
        "stages_ms_median": {k: med(k) for k in last["timings_ms"]},
        "wall_ms_median": statistics.median(r["_wall_ms"] for r in runs),
        "total_ms_runs": [r["timings_ms"]["total"] for r in runs],
        "counters": last["counters"],
        "points": last["points"],
    }


def directed_ckdtree(q, t):
    tree = cKDTree(t)
    d, idx = tree.query(q, k=1, workers=-1)
    i = int(np.argmax(d))
    return float(d[i]), i, int(idx[i])


def run_ckdtree(a, b, repeat):
    a64, b64 = a.astype(np.float64), b.astype(np.float64)
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        ab = directed_ckdtree(a64, b64)
        ba = directed_ckdtree(b64, a64)
        times.append((time.perf_counter() - t0) * 1e3)
        result = (ab, ba)
    ab, ba = result
    # Recompute the witnesses' distances in double from the pairs, as rthdist does.
    hab = float(np.linalg.norm(a64[ab[1]] - b64[ab[2]]))
    hba = float(np.linalg.norm(b64[ba[1]] - a64[ba[2]]))
    return {
        "hausdorff": max(hab, hba),
        "a_to_b": hab,
        "b_to_a": hba,
        "witness_a_to_b": [ab[1], ab[2]],
        "witness_b_to_a": [ba[1], ba[2]],
        "ms_median": statistics.median(times),
        "ms_runs": times,
    }


# ---- report -----------------------------------------------------------------

def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def markdown(report):
    lines = [
        "# rthdist vs SciPy cKDTree: Stanford Dragon",
        "",
        f"Machine: {report['machine']['cpu']}, {report['machine']['cores']} cores; "
        f"device: {report['machine']['device']}; SciPy {report['machine']['scipy']}, "
        f"NumPy {report['machine']['numpy']}; rthdist {report['machine']['rthdist']}.",
        f"Median of {report['repeat']} runs. rthdist total = timings_ms.total (library call); "
        "wall = whole process (load, device setup, compute). cKDTree = tree builds + queries, "
        "both directions, workers=-1, no file loading.",
        "",
        "| case | points A / B | H | backend | bits | rthdist total (ms) | rthdist wall (ms) "
        "| cKDTree (ms) | ratio total/cKDTree | agree |",
        "|---|---:|---:|---|---:|---:|---:|---:|---:|---|",
    ]
    for case in report["cases"]:
        for r in case["rthdist"]:
            lines.append(
                f"| {case['name']} | {case['points_a']:,} / {case['points_b']:,} | {r['hausdorff']:.9g} "
                f"| {r['backend']} | {r['bits']} | {r['total_ms_median']:.1f} | {r['wall_ms_median']:.1f} "
                f"| {case['ckdtree']['ms_median']:.1f} | {r['ratio_total_to_ckdtree']:.2f} "
                f"| {'yes' if r['agrees'] else 'NO'} |")
    lines += ["", "Generated by tools/bench/bench_dragon.py.", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(REPO, "build"), help="rthdist build dir (has ./rthdist)")
    ap.add_argument("--data", default=os.path.join(REPO, "..", "shared", "data"), help="data dir")
    ap.add_argument("--backends", default="ray-query,rt-pipeline,cpu", help="comma-separated rthdist backends")
    ap.add_argument("--cases", default="dragon-res2,dragon-translate", help="comma-separated cases")
    ap.add_argument("--repeat", type=int, default=5, help="runs per measurement (median)")
    ap.add_argument("--bits", type=int, default=0, help="rthdist --bits (0 = auto)")
    ap.add_argument("--out", default=os.path.join(REPO, "docs", "bench", "dragon_lavapipe"),
                    help="output path without extension (.md and .json are written)")
    args = ap.parse_args()

    binary = os.path.join(args.build, "rthdist")
    if not os.access(binary, os.X_OK):
        sys.exit(f"bench_dragon: no rthdist binary at {binary} (build first, or pass --build)")
    dragon = os.path.join(args.data, "stanford", "dragon", "dragon_vrip.ply.gz")
    res2 = os.path.join(args.data, "stanford", "dragon", "dragon_vrip_res2.ply.gz")
    for p in (dragon, res2):
        if not os.path.exists(p):
            sys.exit(f"bench_dragon: missing {p} (pass --data)")
    extra = ["--bits", str(args.bits)] if args.bits else []
    backends = [b for b in args.backends.split(",") if b]

    version = subprocess.run([binary, "--version"], capture_output=True, text=True).stdout.strip()
    version = version.removeprefix("rthdist ")
    print(f"loading {dragon}", flush=True)
    a = read_ply_vertices(dragon)
    report = {"repeat": args.repeat, "cases": [], "machine": {
        "cpu": cpu_model(), "cores": os.cpu_count(), "device": None,
        "scipy": scipy.__version__, "numpy": np.__version__, "rthdist": version}}
    all_agree = True
    with tempfile.TemporaryDirectory(prefix="rthdist-bench-") as tmp:
        for name in [c for c in args.cases.split(",") if c]:
            if name == "dragon-res2":
                b_path, b_label = res2, res2
                b = read_ply_vertices(res2)
            elif name == "dragon-translate":
                extent = float(a[:, 0].max()) - float(a[:, 0].min())
                b = a + np.array([0.5 * extent, 0.0, 0.0], dtype=np.float32)  # float32 arithmetic
                b_path = os.path.join(tmp, "dragon_translated_0.5x.ply")
                write_binary_ply(b_path, b)
                b_label = "dragon_vrip.ply.gz moved by 0.5 of its x-extent along x"
            else:
                sys.exit(f"bench_dragon: unknown case {name}")
            tol = 1e-6 * max(bbox_diagonal(a), bbox_diagonal(b))
            print(f"[{name}] cKDTree x{args.repeat}", flush=True)
            ref = run_ckdtree(a, b, args.repeat)
            case = {"name": name, "a": dragon, "b": b_label, "points_a": int(len(a)),
                    "points_b": int(len(b)), "tolerance": tol, "ckdtree": ref, "rthdist": []}
            for backend in backends:
                print(f"[{name}] rthdist --backend {backend} x{args.repeat}", flush=True)
                r = run_rthdist(binary, dragon, b_path, backend, args.repeat, extra)
                diffs = [abs(r[k] - ref[k]) for k in ("hausdorff", "a_to_b", "b_to_a")]
                r["max_abs_diff_vs_ckdtree"] = max(diffs)
                r["agrees"] = max(diffs) <= tol
                r["ratio_total_to_ckdtree"] = r["total_ms_median"] / ref["ms_median"]
                r["ratio_wall_to_ckdtree"] = r["wall_ms_median"] / ref["ms_median"]
                if r["backend"] != "cpu":
                    report["machine"]["device"] = r["device"]
                all_agree = all_agree and r["agrees"]
                if not r["agrees"]:
                    print(f"  MISMATCH: rthdist H={r['hausdorff']!r} vs cKDTree H={ref['hausdorff']!r} "
                          f"(max diff {max(diffs):.3g} > {tol:.3g})", file=sys.stderr)
                case["rthdist"].append(r)
            report["cases"].append(case)

    md = markdown(report)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out + ".md", "w") as f:
        f.write(md)
    with open(args.out + ".json", "w") as f:
        json.dump(report, f, indent=2)
        f.write("\n")
    print(md)
    print(f"wrote {args.out}.md and {args.out}.json")
    return 0 if all_agree else 1


if __name__ == "__main__":
    sys.exit(main())
