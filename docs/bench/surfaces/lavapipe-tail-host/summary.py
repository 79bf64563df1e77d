#!/usr/bin/env python3
"""The table of an ab.sh run: per row, backend and build, the medians over
the processes of each process's medians (ms) of the stages the session
changed, and the counters of the last call.
  summary.py ROUND.jsonl > ROUND.md"""
import json
import statistics
import sys

rows = {}
for line in open(sys.argv[1]):
    j = json.loads(line)
    r = j["r"]
    k = r["kept_median_ms"]
    d = rows.setdefault((r["case"], j["be"], j["label"]), {"n": 0})
    d["n"] += 1
    for name, v in [("total", k["total"]), ("host_search", k["device"] - k["gpu"]), ("certify", k["certify"]),
                    ("tail_build", k["tail_build"]), ("gpu_tail", k["gpu_tail"]),
                    ("tail_host", k.get("tail_host", 0.0)), ("host", k["total"] - k["gpu"] + k["gpu_tail"])]:
        d.setdefault(name, []).append(v)
    d["counters"] = r["counters"]
print("| row | backend | build | processes | total | search - gpu | certify | tail_build | gpu_tail | tail_host "
      "| total - gpu + gpu_tail | counters |")
print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
for key in sorted(rows):
    d = rows[key]

    def m(name):
        return statistics.median(d[name])
    c = d["counters"]
    counters = "tail %s, host %s, kept %s, submissions %s, band %s" % (
        c.get("tail_queries"), c.get("tail_host_queries", "-"), c.get("tail_tree_reused", "-"), c["submissions"],
        c["band"])
    print("| %s | %s | %s | %d | %.0f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %s |" % (
        key[0], key[1], key[2], d["n"], m("total"), m("host_search"), m("certify"), m("tail_build"),
        m("gpu_tail"), m("tail_host"), m("host"), counters))
