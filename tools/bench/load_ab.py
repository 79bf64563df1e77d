#!/usr/bin/python3
"""A/B loader throughput of two rthdist-load-bench binaries (issue 14).

    /usr/bin/python3 tools/bench/load_ab.py --before OLD/rthdist-load-bench \\
        --after build/rthdist-load-bench --dir /tmp/rthdist-load --rounds 5 \\
        --out docs/bench/loaders/ab.json [--threads N] [FILE...]

For every file, --rounds rounds; each round runs the before binary, then the
after binary (order swapped every other round), each with --runs timed loads
after --warmup, so that both see the same page cache and the same load from
other users of the machine; --threads N (both binaries need the option:
rthdist-load-bench from issue 33 on) parses on N threads, 0 (default) on
every hardware thread. The figure per binary is the median over all its
timed loads' medians; the CPU seconds (all threads) of a load are kept
beside the wall time. Writes every raw record and the summary as JSON and
prints a Markdown table (file, MB, before / after / best after MB/s,
speedup, before / after CPU s, 1-minute load average).
"""
import argparse
import json
import os
import statistics
import subprocess
import time

FILES = ["ply_float.ply", "ply_double.ply", "ply_float_extra.ply", "ply_double_be.ply",
         "las12_f1.las", "las14_f6.las", "pcd_binary.pcd",
         "text.xyz", "ascii.ply", "text.obj", "text.off", "ascii.pcd"]


def run(binary, path, runs, warmup, threads):
    args = [binary, "--runs", str(runs), "--warmup", str(warmup)]
    if threads is not None:
        args += ["--threads", str(threads)]
    out = subprocess.run(args + [path], check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def loadavg():
    return os.getloadavg()[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--dir", default="/tmp/rthdist-load")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--warmup", type=int, default=1)
    ap.add_argument("--out", required=True)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("files", nargs="*", default=FILES)
    a = ap.parse_args()
    records, summary = [], []
    for name in a.files:
        path = os.path.join(a.dir, name)
        seen = {"before": [], "after": []}
        for r in range(a.rounds):
            order = ["before", "after"] if r % 2 == 0 else ["after", "before"]
            for which in order:
                load = loadavg()
                rec = run(getattr(a, which), path, a.runs, a.warmup, a.threads)
                rec.update({"binary": which, "round": r, "loadavg_1min": load, "time": time.time()})
                records.append(rec)
                seen[which].append(rec)
        row = {"file": name, "bytes": seen["after"][0]["bytes"], "points": seen["after"][0]["points"],
               "precision": seen["after"][0]["precision"]}
        for which in ("before", "after"):
            s = statistics.median(x["median_s"] for x in seen[which])
            row[which + "_median_s"] = s
            row[which + "_mb_per_s"] = row["bytes"] / 1e6 / s
            row[which + "_best_mb_per_s"] = row["bytes"] / 1e6 / min(x["min_s"] for x in seen[which])
            row[which + "_cpu_s"] = statistics.median(x["cpu_median_s"] for x in seen[which])
        row["speedup"] = row["before_median_s"] / row["after_median_s"]
        row["read_mb_per_s"] = statistics.median(x["read_mb_per_s"] for x in records if x["file"] == path)
        summary.append(row)
        row["loadavg_1min"] = statistics.median(x["loadavg_1min"] for x in seen["after"])
        print(f"| {name} | {row['bytes'] / 1e6:.0f} | {row['before_mb_per_s']:.0f} | "
              f"{row['after_mb_per_s']:.0f} | {row['after_best_mb_per_s']:.0f} | {row['speedup']:.2f}x | "
              f"{row['before_cpu_s']:.2f} | {row['after_cpu_s']:.2f} | {row['loadavg_1min']:.1f} |",
              flush=True)
    with open(a.out, "w") as f:
        json.dump({"rounds": a.rounds, "runs": a.runs, "warmup": a.warmup, "threads": a.threads,
                   "cpus": os.cpu_count(),
                   "summary": summary, "records": records}, f, indent=1)


if __name__ == "__main__":
    main()
