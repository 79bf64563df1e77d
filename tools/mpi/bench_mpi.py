#!/usr/bin/env python3
"""Benchmark (a tool, not a test): rthdist-mpi under mpirun -np 1/2 against
rthdist in one process, CPU backend, --threads 1 per rank.

  bench_mpi.py --build BUILD --out DIR [--repeat 3] [--ranks 1,2] CASE=A,B ...

Configurations: rthdist with 1 thread and with max(ranks) threads; rthdist-mpi
replicated at each rank count; spatial at 2 and max(ranks) ranks.

For each case, every configuration runs --repeat times with --json; the
table gives medians of timings_ms.load, timings_ms.total (the computation:
for rthdist-mpi the whole collective call, exchanges included) and of the
command's wall time measured here (process start to exit, mpirun's start-up
included). H must agree to the last bit across configurations (the CPU
backend's MPI results are identical to one process). Writes results.json
and a Markdown table into --out.
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import time


def run(cmd):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr))
    j = json.loads(p.stdout)
    return {"wall_s": wall, "load_ms": j["timings_ms"]["load"], "total_ms": j["timings_ms"]["total"],
            "hausdorff": j["hausdorff"], "points": [j["points"]["a"], j["points"]["b"]]}


def configs(build, ranks):
    rth = os.path.join(build, "rthdist")
    mpi = os.path.join(build, "rthdist-mpi")
    mpirun = ["mpirun", "--allow-run-as-root", "--oversubscribe", "--bind-to", "none", "-np"]
    common = ["--json", "--backend", "cpu", "--threads", "1"]
    out = [("rthdist, 1 process, --threads 1", [rth] + common)]
    most = max(ranks)
    if most > 1:
        out.append(("rthdist, 1 process, --threads %d" % most,
                    [rth, "--json", "--backend", "cpu", "--threads", str(most)]))
    for n in ranks:
        out.append(("rthdist-mpi -np %d replicated" % n,
                    mpirun + [str(n), mpi] + common + ["--mpi-mode", "replicated"]))
    for n in sorted({min(2, most), most}):
        if n > 1:
            out.append(("rthdist-mpi -np %d spatial" % n, mpirun + [str(n), mpi] + common + ["--mpi-mode", "spatial"]))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="docs/bench/mpi")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ranks", default="1,2", help="comma-separated rank counts")
    ap.add_argument("cases", nargs="+", help="NAME=A,B")
    args = ap.parse_args()
    rows = []
    for case in args.cases:
        name, files = case.split("=", 1)
        a, b = files.split(",")
        reference = None
        for label, cmd in configs(args.build, [int(n) for n in args.ranks.split(",")]):
            runs = [run(cmd + [a, b]) for _ in range(args.repeat)]
            h = runs[0]["hausdorff"]
            if any(r["hausdorff"] != h for r in runs) or (reference is not None and h != reference):
                raise SystemExit("H differs in %s / %s" % (name, label))
            reference = h
            row = {"case": name, "config": label, "points": runs[0]["points"], "hausdorff": h,
                   "runs": runs}
            for k in ("wall_s", "load_ms", "total_ms"):
                row[k] = statistics.median(r[k] for r in runs)
            rows.append(row)
            print("%-12s %-34s load %8.1f ms  total %8.1f ms  wall %6.2f s  H %.17g" %
                  (name, label, row["load_ms"], row["total_ms"], row["wall_s"], h), flush=True)
    os.makedirs(args.out, exist_ok=True)
    machine = {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count(),
               "load_average": os.getloadavg()}
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump({"machine": machine, "repeat": args.repeat, "rows": rows}, f, indent=1)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write("| case | points A / B | configuration | load (ms) | compute (ms) | wall (s) | H |\n")
        f.write("|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %d / %d | %s | %.0f | %.0f | %.2f | %.9g |\n" %
                    (r["case"], r["points"][0], r["points"][1], r["config"], r["load_ms"], r["total_ms"],
                     r["wall_s"], r["hausdorff"]))


if __name__ == "__main__":
    main()
