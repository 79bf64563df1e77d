#!/usr/bin/env python3
"""One line of the scale suite (gpu_scale_suite.sh) from one process's JSON.

  scale_line.py CASE PROCESS EXIT JSON ERR
"""
import json
import sys


def main():
    case, proc, rc, path, err = sys.argv[1:6]
    try:
        with open(path) as f:
            j = json.load(f)
    except (OSError, ValueError):
        with open(err) as f:
            tail = f.read()[-300:].replace("\n", " | ")
        print(f"{case} p{proc} exit {rc}: no JSON ({tail})")
        return
    def fmt(x):
        return "null" if x is None else f"{x:.10g}"
    cert = j.get("certificate") or {}
    cs = []
    for d in ("a_to_b", "b_to_a"):
        c = cert.get(d)
        if c:
            state = "ok" if c.get("confirmed") else "FAILED"
            if c.get("recomputed"):
                state += "+recomputed"
            cs.append(f"{d}:{state} band {c.get('band', '?')}")
    g = j.get("gpu_ms") or {}
    gpu = " ".join(f"{k} {v:.1f}" for k, v in g.items())
    counters = j.get("counters", {})
    settled = []
    for d in ("a_to_b", "b_to_a"):
        c = counters.get(d)
        if c:
            settled.append(f"{100.0 * c['culled_by_neighbourhood'] / max(1, c['queries']):.1f}%")
    pieces = []
    for d in ("a_to_b", "b_to_a"):
        c = counters.get(d)
        if c and (c.get("query_chunks", 1) > 1 or c.get("target_tiles", 1) > 1):
            pieces.append(f"{c['query_chunks']}x{c['target_tiles']}"
                          f" (+{c.get('cross_piece_queries', 0)} past their piece)")
    v = j.get("verify")
    checked = "off" if v is None else ("ok" if v.get("ok") else "MISMATCH")
    v = v or {}
    t = j["timings_ms"]
    host = " ".join(f"{k} {t.get(k, 0):.0f}" for k in ("load", "setup", "upload", "index", "cull", "total"))
    print(f"{case} p{proc} exit {rc}: H {fmt(j.get('hausdorff'))} h(A,B) {fmt(j['a_to_b']['distance'])} "
          f"h(B,A) {fmt((j.get('b_to_a') or {}).get('distance'))} verify {checked} "
          f"cpu H {fmt((v.get('cpu') or {}).get('hausdorff'))} in {(v.get('cpu') or {}).get('total_ms', 0) / 1000:.1f} s | certificate {', '.join(cs) or 'none'} | "
          f"gpu ms {gpu} | host ms {host} | wall {j['timings_ms']['wall']:.0f} ms | neighbourhood-settled {'/'.join(settled)} | "
          f"points {j['points']['a']}x{j['points']['b']}"
          + (f" | pieces {' / '.join(pieces)} host total {j['timings_ms'].get('total', 0):.0f} ms" if pieces else ""))


if __name__ == "__main__":
    main()
