#!/usr/bin/python3
"""Before/after runs of the CPU backend on the same machine, alternated so
that both builds see the same load (docs/bench/cpu_index/).

  cpu_index_ab.py --report results.json    (the Markdown tables of a finished run)
  cpu_index_ab.py --before BENCH --after BENCH --work DIR --out results.json
                  [--rounds R] [--runs N] [--scenarios a,b] [--peers "TOOL:a,b;TOOL:c"]
                  [--index-before IDX --index-after IDX]

BENCH is an rthdist-bench binary (tools/bench/rthdist_bench.cpp) of each
build; IDX optionally a cpu-index-bench binary (tools/bench/cpu_index_bench.cpp)
of each build, for the index build per set and the hash that shows both
builds produce the same order and index. Scenario directories under --work
hold a.ply and b.ply (tools/bench/scenarios.py writes them). Every round
runs each scenario once with each build (order swapped every other round);
each run is `rthdist-bench --backend cpu --runs N --warmup 1`. Peers
(tools/bench/peers.py, default options) run on the scenarios listed with
them, in the same session, after the rthdist rounds. Prints progress to stderr; writes every raw result.
"""
import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run_json(cmd, timeout):
    """The last stdout line of cmd as JSON, with the child's CPU seconds (user + sys, all threads)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    r["process_cpu_s"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return r


def load_avg():
    return list(os.getloadavg())


def bench(binary, scenario_dir, runs):
    cmd = [binary, os.path.join(scenario_dir, "a.ply"), os.path.join(scenario_dir, "b.ply"),
           "--backend", "cpu", "--runs", str(runs), "--warmup", "1"]
    r = run_json(cmd, 900)
    r["load_avg_start"] = load_avg()
    return r


def index_bench(binary, scenario_dir, runs):
    cmd = [binary, os.path.join(scenario_dir, "a.ply"), os.path.join(scenario_dir, "b.ply"), "--runs", str(runs)]
    return run_json(cmd, 900)


def summary(results):
    med = lambda key: statistics.median(r["median_ms"][key] for r in results)
    return {"wall_ms": med("wall"), "index_ms": med("index"), "search_ms": med("search"),
            "cull_ms": med("cull"), "process_cpu_s": statistics.median(r["process_cpu_s"] for r in results),
            "hausdorff": results[0]["hausdorff"],
            "h_ab": results[0]["h_ab"], "h_ba": results[0]["h_ba"],
            "same_value_every_run": len({(r["hausdorff"], r["h_ab"], r["h_ba"]) for r in results}) == 1,
            "runs": len(results)}


def index_summary(results):
    """Per set: median wall of its order and of its index build, and CPU time of both (ms)."""
    if not results:
        return None
    med = lambda side, key: statistics.median(r[side][key] for r in results)
    return {side: {"order_ms": med(side, "order_ms"), "index_ms": med(side, "index_ms"),
                   "cpu_ms": med(side, "cpu_ms")} for side in ("set_a", "set_b")}


def report(path):
    d = json.load(open(path))
    print("| scenario | wall before (ms) | wall after | wall x | index before | index after | index x |"
          " search before | search after | process CPU s before / after | same H, witnesses' h | same order + index |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---|")
    for s, e in d["scenarios"].items():
        b, a = e["before"], e["after"]
        print("| %s | %.0f | %.0f | %.2f | %.0f | %.0f | %.2f | %.0f | %.0f | %.2f / %.2f | %s | %s |" % (
            s, b["wall_ms"], a["wall_ms"], e["speedup_wall"], b["index_ms"], a["index_ms"], e["speedup_index"],
            b["search_ms"], a["search_ms"], b["process_cpu_s"], a["process_cpu_s"],
            "yes" if e["same_values"] else "NO", {True: "yes", False: "NO", None: "-"}[e.get("same_order_and_index_hash")]))
    print()
    print("| scenario | set | order before (ms) | order after | index before | index after | CPU ms before | CPU ms after |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for s, e in d["scenarios"].items():
        for side in ("set_a", "set_b"):
            b, a = e["index_build_before"][side], e["index_build_after"][side]
            print("| %s | %s | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f |" % (
                s, side[-1].upper(), b["order_ms"], a["order_ms"], b["index_ms"], a["index_ms"], b["cpu_ms"],
                a["cpu_ms"]))
    print()
    print("| scenario | peer | seconds | H agrees with rthdist | rthdist cpu after (s) | rthdist / peer |")
    print("|---|---|---:|---|---:|---:|")
    for s, peers in d["peers"].items():
        after = d["scenarios"][s]["after"]
        for tool, r in peers.items():
            if "seconds" not in r:
                print("| %s | %s | %s | | | |" % (s, tool, r.get("error", "capped")))
                continue
            agree = abs(r["hausdorff"] - after["hausdorff"]) <= 1e-6 * max(1.0, after["hausdorff"])
            print("| %s | %s | %.3f | %s | %.3f | %.3f |" % (s, tool, r["seconds"], "yes" if agree else "NO",
                                                          after["wall_ms"] / 1e3, after["wall_ms"] / 1e3 / r["seconds"]))


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--report":
        report(sys.argv[2])
        return
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--index-before")
    ap.add_argument("--index-after")
    ap.add_argument("--work", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--scenarios", default="surface-5M,sphere-5M,surface-1M,dragon-t0.5,dragon-res2")
    ap.add_argument("--peers", default="ckdtree:surface-5M,sphere-5M,surface-1M,dragon-t0.5,dragon-res2;"
                    "scipy-dh:dragon-t0.5,dragon-res2")
    a = ap.parse_args()
    scenarios = a.scenarios.split(",")
    builds = {"before": a.before, "after": a.after}
    index_builds = {"before": a.index_before, "after": a.index_after}
    raw = {s: {"before": [], "after": [], "index_before": [], "index_after": []} for s in scenarios}
    started = time.time()
    out = {"date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "machine": platform.node(),
           "cpus": os.cpu_count(), "load_avg_start": load_avg(), "rounds": a.rounds,
           "runs_per_process": a.runs, "scenarios": {}}
    for rnd in range(a.rounds):
        order = ["before", "after"] if rnd % 2 == 0 else ["after", "before"]
        for s in scenarios:
            d = os.path.join(a.work, s)
            for b in order:
                r = bench(builds[b], d, a.runs)
                raw[s][b].append(r)
                print("round %d %-12s %-6s wall %7.0f index %7.0f search %6.0f  load %.2f" %
                      (rnd, s, b, r["median_ms"]["wall"], r["median_ms"]["index"], r["median_ms"]["search"],
                       r["load_avg_start"][0]), file=sys.stderr)
                if index_builds[b]:
                    raw[s]["index_" + b].append(index_bench(index_builds[b], d, a.runs))
    for s in scenarios:
        entry = {"before": summary(raw[s]["before"]), "after": summary(raw[s]["after"]), "raw": raw[s]}
        entry["index_build_before"] = index_summary(raw[s]["index_before"])
        entry["index_build_after"] = index_summary(raw[s]["index_after"])
        entry["speedup_wall"] = entry["before"]["wall_ms"] / entry["after"]["wall_ms"]
        entry["speedup_index"] = entry["before"]["index_ms"] / entry["after"]["index_ms"]
        entry["same_values"] = all(entry["before"][k] == entry["after"][k] for k in ("hausdorff", "h_ab", "h_ba"))
        hashes = {b: {(r["set_a"]["hash"], r["set_b"]["hash"]) for r in raw[s]["index_" + b]}
                  for b in ("before", "after")}
        if hashes["before"] and hashes["after"]:
            entry["same_order_and_index_hash"] = hashes["before"] == hashes["after"] and len(hashes["after"]) == 1
        out["scenarios"][s] = entry
    out["peers"] = {}
    for spec in [x for x in a.peers.split(";") if x]:
        tool, names = spec.split(":")
        for s in names.split(","):
            d = os.path.join(a.work, s)
            cmd = ["/usr/bin/python3", os.path.join(HERE, "peers.py"), tool, os.path.join(d, "a.ply"),
                   os.path.join(d, "b.ply")]
            try:
                r = run_json(cmd, 600)
            except (subprocess.CalledProcessError, subprocess.TimeoutExpired, ValueError) as e:
                r = {"error": str(e)[:500]}
            r["load_avg_start"] = load_avg()
            out["peers"].setdefault(s, {})[tool] = r
            print("peer %-12s %-10s %s" % (s, tool, r.get("seconds", r.get("error"))), file=sys.stderr)
    out["load_avg_end"] = load_avg()
    out["minutes"] = (time.time() - started) / 60
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
