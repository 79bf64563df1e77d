#!/usr/bin/python3
"""Writes OUT/README.md and OUT/*.png from a results.json of run_all.py.

  /usr/bin/python3 tools/bench/report.py docs/bench/results.json docs/bench
"""
import json
import os
import sys

TOOLS = ["rthdist-cpu", "rthdist-ray-query", "rthdist-rt-pipeline", "scipy-dh", "ckdtree", "open3d", "pcl", "faiss"]
LABEL = {"rthdist-cpu": "rthdist cpu", "rthdist-ray-query": "rthdist ray-query (lavapipe)",
         "rthdist-rt-pipeline": "rthdist rt-pipeline (lavapipe)", "scipy-dh": "SciPy directed_hausdorff",
         "ckdtree": "SciPy cKDTree", "open3d": "Open3D", "pcl": "PCL", "faiss": "FAISS IndexFlatL2"}
SHORT = {"rthdist-cpu": "rthdist cpu", "rthdist-ray-query": "ray-query", "rthdist-rt-pipeline": "rt-pipeline",
         "scipy-dh": "directed_hausdorff", "ckdtree": "cKDTree", "open3d": "Open3D", "pcl": "PCL",
         "faiss": "FAISS flat"}
PEERS = ["scipy-dh", "ckdtree", "open3d", "pcl", "faiss"]
CPU_STAGES = ["index", "cull", "search", "refine"]
GPU_STAGES = ["upload", "gpu_index", "gpu_cull", "gpu_search", "gpu_refine"]


def fmt_s(x):
    if x >= 100:
        return "%.0f" % x
    if x >= 10:
        return "%.1f" % x
    if x >= 1:
        return "%.2f" % x
    return "%.3f" % x


def cell(r, with_agree=True):
    if r is None:
        return "–"
    st = r["status"]
    if st == "ok":
        s = fmt_s(r["seconds"])
        if with_agree and r.get("agree") is False:
            s += " **≠**"
        return s
    if st == "capped":
        if r.get("projected_seconds"):
            return "> %g (proj. %.0f)" % (r["cap_s"], r["projected_seconds"])
        return "> %g" % r["cap_s"]
    if st == "skipped":
        return "not run"
    return "error"


def row_of(entry, tool):
    return next((r for r in entry["rows"] if r["tool"] == tool), None)


def fastest_peer(entry):
    best = None
    for t in PEERS:
        r = row_of(entry, t)
        if r and r["status"] == "ok" and (best is None or r["seconds"] < best["seconds"]):
            best = r
    return best


def ratio(a, b):
    """a/b as text; a, b rows. Capped peers give an upper bound on the ratio."""
    if not a or a["status"] != "ok" or not b:
        return "–"
    if b["status"] == "ok":
        x = a["seconds"] / b["seconds"]
        return "%.2f" % x if 0.1 <= x < 100 else "%.2g" % x
    if b["status"] == "capped":
        return "< %.2g" % (a["seconds"] / b["cap_s"])
    return "–"


def dominant(r):
    m = r.get("median_ms", {})
    stages = CPU_STAGES if r["tool"] == "rthdist-cpu" else GPU_STAGES
    vals = {s: m.get(s, 0.0) for s in stages}
    s = max(vals, key=vals.get)
    tot = sum(vals.values()) or 1.0
    return s, vals[s] / tot, vals


def plots(res, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    made = []
    # 1. time per scenario per tool, log scale.
    ents = res["scenarios"]
    tools = [t for t in TOOLS if any(row_of(e, t) for e in ents)]
    fig, ax = plt.subplots(figsize=(12, 0.55 * len(ents) * 1.0 + 2.5))
    h = 0.8 / len(tools)
    colors = plt.cm.tab10(np.arange(len(tools)))
    for j, t in enumerate(tools):
        for i, e in enumerate(ents):
            r = row_of(e, t)
            if not r:
                continue
            y = i + (j - (len(tools) - 1) / 2) * h
            if r["status"] == "ok":
                ax.barh(y, r["seconds"], height=h, color=colors[j], label=SHORT[t] if i == 0 else None)
            elif r["status"] == "capped":
                ax.barh(y, r["cap_s"], height=h, color="none", edgecolor=colors[j], hatch="///", linewidth=0.6,
                        label=None)
                ax.text(r["cap_s"] * 1.05, y, ">cap", va="center", fontsize=6, color=colors[j])
    for j, t in enumerate(tools):  # legend entries even when the first scenario has no bar
        ax.barh(np.nan, 0, color=colors[j], label=SHORT[t] if not ax.get_legend_handles_labels()[1].count(SHORT[t])
                else None)
    ax.set_yticks(range(len(ents)))
    ax.set_yticklabels(["%s\n%s / %s" % (e["name"], f"{e['points_a']:,}", f"{e['points_b']:,}") for e in ents],
                       fontsize=7)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("seconds (log scale; hatched = hit the time cap)")
    ax.set_title("Exact symmetric Hausdorff distance, %s cores, %s" % (res["machine"]["cores"], res["machine"]["date_utc"]))
    ax.grid(axis="x", which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(os.path.join(out, "times.png"), dpi=110)
    plt.close(fig)
    made.append("times.png")

    # 2. stage breakdown vs k.
    sweeps = res.get("sweeps", [])
    scen = sorted(set(r["scenario"] for r in sweeps if r["tool"] == "rthdist-ray-query"))
    if scen:
        fig, axes = plt.subplots(2, len(scen), figsize=(5.5 * len(scen), 7.5), squeeze=False)
        for c, n in enumerate(scen):
            for rr, (tool, stages) in enumerate((("rthdist-cpu", CPU_STAGES), ("rthdist-ray-query", GPU_STAGES))):
                ax = axes[rr][c]
                rows = sorted([r for r in sweeps if r["scenario"] == n and r["tool"] == tool], key=lambda r: r["k"])
                ok = [r for r in rows if r["status"] == "ok" and r["k"] > 0]
                ks = [r["k"] for r in ok]
                for s in stages:
                    v = [r["median_ms"][s] / 1e3 for r in ok]
                    if max(v + [0.0]) < 1e-3:
                        continue  # a stage that never reaches 1 ms (e.g. refine when the cull resolves all)
                    ax.plot(ks, [x if x >= 1e-4 else float("nan") for x in v], "o-",
                            label=s.replace("gpu_", "device "))
                ax.plot(ks, [r["median_ms"]["wall"] / 1e3 for r in ok], "k--", label="wall (whole call)")
                for r in rows:
                    if r["status"] != "ok" and r["k"] > 0:
                        ax.annotate("> %gs" % r["cap_s"], (r["k"], 1e-3), ha="center", fontsize=7)
                ax.set_yscale("log")
                ax.set_xticks(range(1, 9))
                ax.grid(which="both", alpha=0.3)
                ax.set_xlabel("bit count k (cells of edge L / 2^k)")
                ax.set_ylabel("seconds per stage (median, log)")
                ax.set_title("%s, %s" % (n, SHORT[tool]))
                ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "stages_vs_k.png"), dpi=110)
        plt.close(fig)
        made.append("stages_vs_k.png")

    # 3. scaling with point count.
    sc = res.get("scaling", [])
    if sc:
        fig, ax = plt.subplots(figsize=(7, 5))
        for t in sorted(set(r["tool"] for r in sc), key=TOOLS.index):
            rows = sorted([r for r in sc if r["tool"] == t], key=lambda r: r["points"])
            ok = [r for r in rows if r["status"] == "ok"]
            ax.plot([r["points"] for r in ok], [r["seconds"] for r in ok], "o-", label=SHORT[t])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("points per side (Dragon surface samples, both sides)")
        ax.set_ylabel("seconds")
        ax.set_title("Scaling with point count (overlapping sets)")
        ax.grid(which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, "scaling.png"), dpi=110)
        plt.close(fig)
        made.append("scaling.png")
    return made


def markdown(res, pngs):
    m = res["machine"]
    L = []
    L.append("# rthdist benchmark: the RT-HDIST paper's scenarios beside the CPU tools users pick instead")
    L.append("")
    L.append("Generated by `%s` (tools/bench/run_all.py, then report.py); do not edit by hand." % res["command"])
    L.append("")
    L.append("- Date: %s (UTC), whole suite %.0f min." % (m["date_utc"], res.get("elapsed_s", 0) / 60))
    L.append("- Machine: %s, %s cores, %s GiB, %s, Linux %s." % (m["cpu"], m["cores"], m["mem_gib"], m["os"],
                                                              m["kernel"]))
    dev = next((r.get("device") for e in res["scenarios"] for r in e["rows"]
                if r["tool"] != "rthdist-cpu" and r.get("device")), "n/a")
    L.append("- Vulkan device for the ray-query / rt-pipeline rows: %s, Mesa %s (lavapipe, software "
             "ray tracing on the same 2 cores). rthdist cpu = the native multithreaded CPU backend." %
             (dev, m["mesa_vulkan_drivers"]))
    L.append("- rthdist commit %s%s (Release build, %s); peers from Debian 12: SciPy %s, Open3D %s, "
             "PCL (pcl-tools) %s, FAISS %s, NumPy %s." % (
                 m["rthdist_commit"], " + uncommitted changes" if m.get("rthdist_dirty") else "", m["rthdist_bench"],
                 m.get("scipy"), m["open3d"], m["pcl_tools"], m["faiss"], m.get("numpy")))
    la0, la1 = m["load_avg_start"], m.get("load_avg_end", [0, 0, 0])
    L.append("- Load average (1/5/15 min) at start %.2f / %.2f / %.2f, at end %.2f / %.2f / %.2f; each row's "
             "1-min load at its start is in results.json (`load_avg_1m`). The 2 cores are shared with other "
             "work in this environment; timings carry that noise." % (tuple(la0) + tuple(la1)))
    L.append("- Time cap: %g s per peer run (FAISS: projected from timed query subsets, see below), %g s per "
             "rthdist lavapipe process; '> cap' rows are kept." % (res["cap_s"], res["gpu_cap_s"]))
    L.append("")
    L += summary(res)
    L.append("## What is timed")
    L.append("")
    L.append("Seconds for the exact symmetric H = max(h(A,B), h(B,A)), both directions, inputs already in memory:")
    L.append("")
    L.append("- **rthdist** (`rthdist-bench`): median wall time of `Engine::compute` after a warm-up call "
             "(index build, culling, search, refinement, host->device upload; device/pipeline creation excluded, "
             "it is once per Engine). Up to 5 timed calls (cpu) or 3 (lavapipe), fewer when slow (`--budget`).")
    L.append("- **SciPy directed_hausdorff**: both directions (early break, random shuffle, seed 0), float64.")
    L.append("- **SciPy cKDTree**: tree build + `query(workers=-1)` per direction, float64.")
    L.append("- **Open3D** `compute_point_cloud_distance` per direction (KD-tree, OpenMP), float64; the "
             "PointCloud objects are built before timing.")
    L.append("- **PCL** `pcl_compute_hausdorff A.pcd B.pcd`: the tool's own printed compute time (cloud "
             "copies, two KD-tree builds, nearest-neighbour search in both directions, one thread). PCD loading is "
             "NOT in that figure; the whole process's wall time (loading included) is `wall_seconds` in "
             "results.json and in the PCL wall column below.")
    L.append("- **FAISS** `IndexFlatL2` (exact brute force, float32 GEMM expansion, OpenMP), `search(k=1)` per "
             "direction; each found neighbour's distance is recomputed in double. Its cost is fixed per query, "
             "so a random query subset is timed first and the run is skipped, reported '> cap (proj. X)', when "
             "the linear projection exceeds the cap.")
    L.append("- Peers: median of up to 3 runs while that stays under 3 s, else one run.")
    L.append("")
    L.append("All tools read the same float32 coordinates (each scenario is written once as binary PLY and PCD by "
             "tools/bench/scenarios.py).")
    L.append("")

    # ---- times table
    L.append("## Times (seconds)")
    L.append("")
    L.append("| scenario | points A / B | H | " + " | ".join(SHORT[t] for t in TOOLS) + " | PCL wall (incl. load) |")
    L.append("|---|---:|---:|" + "---:|" * (len(TOOLS) + 1))
    for e in res["scenarios"]:
        ref = row_of(e, "rthdist-cpu")
        H = "%.9g" % ref["hausdorff"] if ref and ref["status"] == "ok" else "–"
        pcl = row_of(e, "pcl")
        pw = fmt_s(pcl["wall_seconds"]) if pcl and pcl.get("wall_seconds") else cell(pcl)
        L.append("| %s | %s / %s | %s | %s | %s |" % (
            e["name"], f"{e['points_a']:,}", f"{e['points_b']:,}", H,
            " | ".join(cell(row_of(e, t)) for t in TOOLS), pw))
    L.append("")
    L.append("**≠** marks a value outside the agreement tolerance (see Agreement).")
    L.append("")

    # ---- ratio table
    L.append("## rthdist / peer time ratios (same run; < 1 means rthdist is faster)")
    L.append("")
    L.append("| scenario | fastest peer | fastest peer (s) | rthdist cpu (s) | **cpu / fastest** | " +
             " | ".join("cpu / " + SHORT[p] for p in PEERS) + " | ray-query / fastest | rt-pipeline / fastest |")
    L.append("|---|---|---:|---:|---:|" + "---:|" * (len(PEERS) + 2))
    slower = []
    for e in res["scenarios"]:
        cpu = row_of(e, "rthdist-cpu")
        fp = fastest_peer(e)
        L.append("| %s | %s | %s | %s | **%s** | %s | %s | %s |" % (
            e["name"], SHORT[fp["tool"]] if fp else "–", fmt_s(fp["seconds"]) if fp else "–", cell(cpu),
            ratio(cpu, fp), " | ".join(ratio(cpu, row_of(e, p)) for p in PEERS),
            ratio(row_of(e, "rthdist-ray-query"), fp), ratio(row_of(e, "rthdist-rt-pipeline"), fp)))
        for t in ("rthdist-cpu", "rthdist-ray-query", "rthdist-rt-pipeline"):
            r = row_of(e, t)
            if r and r["status"] == "ok" and fp and r["seconds"] > fp["seconds"]:
                slower.append((e, r, fp))
    L.append("")

    # ---- where rthdist is not the fastest
    L.append("## Where rthdist is not the fastest, and which stage dominates there")
    L.append("")
    cpu_slow = [x for x in slower if x[1]["tool"] == "rthdist-cpu"]
    if not cpu_slow:
        L.append("- rthdist cpu: fastest on every scenario of this run.")
    for e, r, fp in cpu_slow:
        s, frac, vals = dominant(r)
        L.append("- **%s**, rthdist cpu %.3f s vs %s %.3f s (x%.2f): dominant stage `%s` (%.0f%% of the stage sum; "
                 "%s ms)." % (e["name"], r["seconds"], SHORT[fp["tool"]], fp["seconds"], r["seconds"] / fp["seconds"],
                              s, 100 * frac, ", ".join("%s %.0f" % (k, v) for k, v in vals.items())))
    gpu_slow = [x for x in slower if x[1]["tool"] != "rthdist-cpu"]
    if gpu_slow:
        by = {}
        for e, r, fp in gpu_slow:
            s, frac, vals = dominant(r)
            by.setdefault(r["tool"], []).append("%s x%.1f (`%s` %.0f%%)" % (e["name"], r["seconds"] / fp["seconds"],
                                                                          s.replace("gpu_", "device "), 100 * frac))
        for t, items in by.items():
            L.append("- %s, slower than the fastest peer on %d scenarios (ratio to the fastest peer, dominant "
                     "device stage): %s." % (LABEL[t], len(items), "; ".join(items)))
        L.append("  On lavapipe every 'device' stage is a compute or ray-tracing shader run by llvmpipe on the "
                 "same 2 CPU cores, so these rows measure the Vulkan path's cost on a software device, not a GPU.")
    L.append("")

    # ---- agreement
    L.append("## Agreement (design.md §1: within 1e-6 of the larger bbox diagonal)")
    L.append("")
    L.append("Every tool's h(A,B), h(B,A) and H are compared with rthdist cpu's. PCL prints its values with 6 "
             "decimals (`%f` of a float32), so its allowance adds 5e-7 + float32 rounding.")
    L.append("")
    L.append("| scenario | tolerance | " + " | ".join(SHORT[t] for t in TOOLS[1:]) + " |")
    L.append("|---|---:|" + "---|" * (len(TOOLS) - 1))
    bad = []
    for e in res["scenarios"]:
        cells = []
        for t in TOOLS[1:]:
            r = row_of(e, t)
            if not r or r["status"] != "ok" or "abs_diff" not in r:
                cells.append("–")
            else:
                cells.append(("ok (%.1g)" % r["abs_diff"]) if r["agree"] else "**NO (%.3g)**" % r["abs_diff"])
                if not r["agree"]:
                    bad.append((e, r))
        L.append("| %s | %.2g | %s |" % (e["name"], e["tolerance"], " | ".join(cells)))
    L.append("")
    L.append("Cells: max |difference| over h(A,B), h(B,A), H; '–' = not run or capped.")
    L.append("")
    if not bad:
        L.append("Every peer that finished agrees with rthdist on every scenario.")
    for e, r in bad:
        ref = row_of(e, "rthdist-cpu")
        L.append("- **%s, %s**: h(A,B) %.9g vs rthdist %.9g; h(B,A) %.9g vs %.9g (allowed %.3g)." % (
            e["name"], SHORT[r["tool"]], r["h_ab"], ref["h_ab"], r["h_ba"], ref["h_ba"], r["allowed"]))
    fp = res.get("faiss_precision", {})
    if fp:
        L.append("")
        L.append("FAISS IndexFlatL2 is exact only in name: it ranks neighbours by the float32 expansion "
                 "|q|^2 + |t|^2 - 2 q.t, which cancels catastrophically when coordinates are large relative to "
                 "the distances. Measured in this run on 2000 random points of B (nearest neighbours in A checked "
                 "with cKDTree; the neighbour FAISS returns is re-measured in double):")
        L.append("")
        L.append("| scenario | queries | true NN max | wrong neighbours (raw) | max error (raw) | FAISS's own max "
                 "distance (raw) | wrong neighbours (A's centroid subtracted) | max error (centred) |")
        L.append("|---|---:|---:|---:|---:|---:|---:|---:|")
        for n, v in fp.items():
            if v.get("status") != "ok":
                continue
            L.append("| %s | %d | %.3g | %d | %.3g | %.3g | %d | %.3g |" % (
                n, v["queries"], v["true_nn_max"], v["raw"]["wrong_neighbour"], v["raw"]["max_error"],
                v["raw"]["faiss_reported_max"], v["centred"]["wrong_neighbour"], v["centred"]["max_error"]))
        L.append("")
        L.append("On the LiDAR data (UTM, y ≈ 5.4e6 m; FSite8_red1 is a subset of FSite8_orig, so every true NN "
                 "distance is 0) FAISS reports distance 0 for every query while the neighbour it returns is up to "
                 "the 'max error' away, so its H there can be wrong by that much.")
        fin = [(e, row_of(e, "faiss")) for e in res["scenarios"]
               if row_of(e, "faiss") and row_of(e, "faiss")["status"] == "ok" and "agree" in row_of(e, "faiss")]
        if fin and all(r["agree"] for _, r in fin):
            L.append("Where FAISS finished in this run (%s) its H matched: there the wrong neighbours did not "
                     "touch the query that realizes the maximum. With wrong neighbours on other queries, that "
                     "agreement is luck, not a guarantee." % ", ".join(e["name"] for e, _ in fin))
    L.append("")

    # ---- k sweep
    sweeps = res.get("sweeps", [])
    if sweeps:
        L.append("## Stage breakdown vs bit count k (the paper's analysis figure)")
        L.append("")
        L.append("One k for both directions (`rthdist-bench --bits K`); median ms per stage. cpu: index / cull "
                 "(exact NN in the 3x3x3 block) / search (grid rings) / refine; ray-query: device timestamps per "
                 "stage on lavapipe (index = compute shaders incl. sort; search = BLAS builds + ray traversal).")
        L.append("")
        for n in sorted(set(r["scenario"] for r in sweeps if r["tool"] == "rthdist-ray-query")):
            for tool, stages in (("rthdist-cpu", CPU_STAGES), ("rthdist-ray-query", GPU_STAGES)):
                rows = sorted([r for r in sweeps if r["scenario"] == n and r["tool"] == tool], key=lambda r: r["k"])
                L.append("**%s, %s**" % (n, SHORT[tool]))
                L.append("")
                L.append("| k | occupied cells (A→B / B→A) | surviving queries | iterations | " +
                         " | ".join(s.replace("gpu_", "dev ") for s in stages) + " | wall |")
                L.append("|---:|---:|---:|---:|" + "---:|" * (len(stages) + 1))
                for r in rows:
                    if r["status"] != "ok":
                        L.append("| %d | | | | %s |" % (r["k"], " | ".join(["–"] * len(stages)) + " | " + cell(r)))
                        continue
                    c = r["counters"]
                    L.append("| %d | %s / %s | %s / %s | %s / %s | %s | %.1f |" % (
                        r["k"], f"{c[0]['cells']:,}", f"{c[1]['cells']:,}", f"{c[0]['surviving']:,}",
                        f"{c[1]['surviving']:,}", c[0]["iterations"], c[1]["iterations"],
                        " | ".join("%.1f" % r["median_ms"][s] for s in stages), r["median_ms"]["wall"]))
                L.append("")
        if "stages_vs_k.png" in pngs:
            L.append("![stage breakdown vs k](stages_vs_k.png)")
            L.append("")

        L.append("## Index-space ablation (the paper's \"Ours-NoIS\")")
        L.append("")
        L.append("Not applicable as such: rthdist has no code path without the index space (the paper's NoIS puts "
                 "one AABB per target point in the BVH; our cull, search and refinement are defined over cells). "
                 "The closest analogue is the coarsest grid: k = 1 (8 cells) and k = 2 (64 cells) make the index "
                 "space nearly useless, so the cpu rows at k = 1, 2 above show what the index space buys; on "
                 "lavapipe k < 3 is not run (in a trial, ray-query at k = 1 took 94 s on dragon-res2, against "
                 "0.15-2.4 s at k = 3..8).")
        L.append("")
        for n in sorted(set(r["scenario"] for r in sweeps if r["tool"] == "rthdist-ray-query")):
            rows = {r["k"]: r for r in sweeps if r["scenario"] == n and r["tool"] == "rthdist-cpu"}
            auto = row_of(next(e for e in res["scenarios"] if e["name"] == n), "rthdist-cpu")
            if 1 in rows and rows[1]["status"] == "ok" and auto and auto["status"] == "ok":
                L.append("- %s: k = 1 %.3f s, k = 2 %.3f s, automatic k %s: %.3f s (x%.0f faster than k = 1)." % (
                    n, rows[1]["seconds"], rows[2]["seconds"] if rows.get(2, {}).get("status") == "ok" else float("nan"),
                    "/".join(map(str, auto["bits"])), auto["seconds"], rows[1]["seconds"] / auto["seconds"]))
        L.append("")

        L.append("## Automatic bit count vs the best fixed k (rthdist cpu)")
        L.append("")
        L.append("Automatic k is chosen per direction from the target set (about 6 points per occupied cell); "
                 "the fixed-k runs use one k for both directions, k = 2..8 (8 is the largest the index allows; "
                 "k >= 5 only at 1M+ points per side, where k = 2..4 take minutes). The automatic choice is "
                 "timed again in the same series (median of up to 5 calls), so the columns are comparable; at "
                 "tens of milliseconds, differences of 10-30% are within this shared machine's noise.")
        L.append("")
        rat = []
        for e in res["scenarios"]:
            rows = {r["k"]: r for r in sweeps if r["scenario"] == e["name"] and r["tool"] == "rthdist-cpu"}
            ok = [r for k, r in rows.items() if k >= 2 and r["status"] == "ok"]
            if ok and rows.get(0, {}).get("status") == "ok":
                rat.append((rows[0]["seconds"] / min(r["seconds"] for r in ok), e["name"]))
        if rat:
            rat.sort()
            L.append("Automatic k / best fixed k: median %.2f, from %.2f (%s) to %.2f (%s) over %d scenarios." % (
                rat[len(rat) // 2][0], rat[0][0], rat[0][1], rat[-1][0], rat[-1][1], len(rat)))
            L.append("")
        L.append("| scenario | auto k (A→B / B→A) | auto (s) | best fixed k | best (s) | auto / best | "
                 + " | ".join("k=%d" % k for k in range(2, 9)) + " |")
        L.append("|---|---|---:|---:|---:|---:|" + "---:|" * 7)
        for e in res["scenarios"]:
            rows = {r["k"]: r for r in sweeps if r["scenario"] == e["name"] and r["tool"] == "rthdist-cpu"}
            auto = rows.get(0) if rows.get(0, {}).get("status") == "ok" else row_of(e, "rthdist-cpu")
            ok = {k: r for k, r in rows.items() if r["status"] == "ok" and k >= 2}
            if not ok or not auto or auto["status"] != "ok":
                continue
            bk = min(ok, key=lambda k: ok[k]["seconds"])
            L.append("| %s | %s | %s | %d | %s | %.2f | %s |" % (
                e["name"], " / ".join(map(str, auto["bits"])), fmt_s(auto["seconds"]), bk, fmt_s(ok[bk]["seconds"]),
                auto["seconds"] / ok[bk]["seconds"], " | ".join(cell(rows.get(k)) for k in range(2, 9))))
        L.append("")

    sc = res.get("scaling", [])
    if sc:
        L.append("## Scaling with point count")
        L.append("")
        L.append("Independent area-weighted samplings of the Dragon's surface, N points per side (1M and 5M are "
                 "the scale scenarios above, fixed seeds 1/2 and 3/4; the others seeds 101/102). The paper's "
                 "3.6M/5M-vertex models are not available here.")
        L.append("")
        tools = sorted(set(r["tool"] for r in sc), key=TOOLS.index)
        L.append("| N per side | " + " | ".join(SHORT[t] for t in tools) + " |")
        L.append("|---:|" + "---:|" * len(tools))
        for n in sorted(set(r["points"] for r in sc)):
            L.append("| %s | %s |" % (f"{n:,}", " | ".join(cell(next((r for r in sc if r["points"] == n and
                                                                          r["tool"] == t), None)) for t in tools)))
        L.append("")
        if "scaling.png" in pngs:
            L.append("![scaling](scaling.png)")
            L.append("")

    L.append("## Plots")
    L.append("")
    if "times.png" in pngs:
        L.append("![time per scenario per tool](times.png)")
        L.append("")
    L.append("## Scenarios")
    L.append("")
    L.append("| scenario | group | what |")
    L.append("|---|---|---|")
    for e in res["scenarios"]:
        L.append("| %s | %s | %s |" % (e["name"], e["group"], e["description"]))
    L.append("")
    L += notes_section(res)
    return "\n".join(L)


def summary(res):
    ents = res["scenarios"]
    L = ["## Summary", ""]
    won, lost, ratios = [], [], []
    for e in ents:
        cpu, fp = row_of(e, "rthdist-cpu"), fastest_peer(e)
        if not cpu or cpu["status"] != "ok" or not fp:
            continue
        x = cpu["seconds"] / fp["seconds"]
        ratios.append((x, e["name"], SHORT[fp["tool"]]))
        (won if x < 1 else lost).append(e["name"])
    if ratios:
        lo, hi = min(ratios), max(ratios)
        L.append("- rthdist cpu is faster than the fastest peer on %d of %d scenarios; rthdist cpu / fastest peer "
                 "ranges from %.2g (%s, vs %s) to %.2g (%s, vs %s)%s." % (
                     len(won), len(ratios), lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
                     "" if not lost else "; slower on " + ", ".join(lost)))
    for t in ("rthdist-ray-query", "rthdist-rt-pipeline"):
        rows = [(e, row_of(e, t), fastest_peer(e)) for e in ents]
        ok = [(e, r, fp) for e, r, fp in rows if r and r["status"] == "ok" and fp]
        if ok:
            faster = [e["name"] for e, r, fp in ok if r["seconds"] < fp["seconds"]]
            L.append("- %s is faster than the fastest peer on %d of %d scenarios run (%s)." % (
                LABEL[t], len(faster), len(ok), ", ".join(faster) or "none"))
    nbad = sum(1 for e in ents for r in e["rows"] if r.get("agree") is False)
    nchk = sum(1 for e in ents for r in e["rows"] if "agree" in r)
    L.append("- Values: %d of %d finished (tool, scenario) results agree with rthdist cpu within design.md §1's "
             "tolerance%s." % (nchk - nbad, nchk, "" if not nbad else " (see Agreement for the others)"))
    L.append("")
    return L


def notes_section(res):
    L = ["## Notes, and what is missing", ""]
    ents = res["scenarios"]
    big = next((e for e in ents if e["name"] == "surface-5M"), None)
    cpu5 = row_of(big, "rthdist-cpu") if big else None
    if cpu5 and cpu5["status"] == "ok" and cpu5.get("max_rss_kb"):
        inputs = 2 * big["points_a"] * 12 / 2**20
        L.append("- Memory (issue 6): peak RSS of the whole rthdist-bench process (loading, inputs, index, "
                 "every call) on surface-5M, cpu backend: %.0f MiB; the two float32 input arrays are %.0f MiB. "
                 "Issue 6 asks for at most 2x the inputs plus the index; this whole-process peak is an upper "
                 "bound on what the library call itself holds." % (cpu5["max_rss_kb"] / 1024, inputs))
    # peers' pattern
    L.append("- The peers' two failure modes from issue 6 show here too: the KD-tree tools (cKDTree, PCL, and to "
             "a lesser degree Open3D) slow down by 10-100x when the sets are apart (translation, different "
             "objects: every query's nearest neighbour is far, so each query visits many tree nodes and nothing "
             "stops early), while directed_hausdorff's early break makes it the fastest peer there but "
             "quadratic on overlapping sets (decimation, scale: up to the cap). FAISS's brute force is "
             "quadratic everywhere.")
    # lavapipe summary from counters
    rq = [(e, row_of(e, "rthdist-ray-query")) for e in ents]
    surv = [(e["name"], sum(c["surviving"] for c in r["counters"]), max(c["iterations"] for c in r["counters"]),
             sum(c["rays"] for c in r["counters"])) for e, r in rq if r and r["status"] == "ok"]
    if surv:
        none = [n for n, sv, it, ry in surv if sv == 0]
        some = ["%s %s queries / %d iterations / %s rays" % (n, f"{sv:,}", it, f"{ry:,}") for n, sv, it, ry in surv
                if sv > 0]
        L.append("- lavapipe (ray-query, rt-pipeline): on %s the neighbourhood cull resolves every query and "
                 "no ray is cast; elsewhere the surviving queries go through radius iterations of BLAS builds "
                 "and rays on llvmpipe (%s); the stage shares of the slow rows are in 'Where rthdist is not the "
                 "fastest'. The native cpu backend does the same search on a grid without Vulkan." % (", ".join(none) or "no scenario",
                                                                           "; ".join(some)))
    sw = res.get("sweeps", [])
    for n in sorted(set(r["scenario"] for r in sw if r["tool"] == "rthdist-ray-query")):
        rows = [r for r in sw if r["scenario"] == n and r["tool"] == "rthdist-ray-query" and r["status"] == "ok"]
        auto = row_of(next(e for e in ents if e["name"] == n), "rthdist-ray-query")
        if rows and auto and auto["status"] == "ok":
            b = min(rows, key=lambda r: r["seconds"])
            L.append("- Automatic k on lavapipe (ray-query), %s: auto k %s took %.3f s, the best fixed k = %d "
                     "%.3f s (x%.1f). The automatic rule aims at ~6 points per cell, which suits the cpu backend; "
                     "on lavapipe the dense 2^(3k) cell table (index stage) and the per-iteration BLAS work grow "
                     "with k (see the sweep tables)." % (n, "/".join(map(str, auto["bits"])), auto["seconds"],
                                                          b["k"], b["seconds"], auto["seconds"] / b["seconds"]))
    L.append("- Timings come from one run on a shared 2-core machine (see the load averages above): rows of a "
             "few milliseconds vary by tens of percent between runs, rows of seconds by ~10-30%; lavapipe "
             "rows of several seconds are the median of 1-3 calls after one warm-up call (in a trial the "
             "first call on an Engine took 8.2 s against 4.4 s for the next ones on dragon-t0.3, ray-query).")
    L.append("- Not here: real RT hardware (this suite runs the Vulkan backends on lavapipe only; the H100 "
             "figures are in [gpu.md](gpu.md), from tools/bench/gpu_device_run.sh); the paper's Happy Buddha, "
             "Thai Statue and Asian Dragon (not in ../shared/data; the Dragon surface samplings stand in at "
             "1M/5M); the lavapipe backends on surface-5M (%s); exact values for capped peer runs; PCL values "
             "beyond 6 decimals; a NoIS variant (see the ablation section); Python peers' import and "
             "array-conversion time (excluded by design)." % (
                 "skipped for time" if "surface-5M" in res.get("gpu_skip", []) else "run"))
    L.append("")
    return L


def main():
    src, out = sys.argv[1], sys.argv[2]
    with open(src) as f:
        res = json.load(f)
    pngs = plots(res, out)
    with open(os.path.join(out, "README.md"), "w") as f:
        f.write(markdown(res, pngs))
    print("wrote %s/README.md and %s" % (out, ", ".join(pngs)))


if __name__ == "__main__":
    main()
