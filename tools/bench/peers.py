#!/usr/bin/python3
"""One CPU peer on one scenario: the tools a user would pick instead of
rthdist. Prints one JSON object. Run by run_all.py in a subprocess with a
time cap (a capped run is killed and reported as '> cap').

  peers.py TOOL A.ply B.ply [--max-runs N] [--budget S] [--cap S] [--pcd-a A.pcd --pcd-b B.pcd]
  peers.py faiss-precision A.ply B.ply    FAISS's neighbours for 2000 random points
                                          of B vs the exact ones (cKDTree), raw and
                                          with A's centroid subtracted first

TOOL: scipy-dh     scipy.spatial.distance.directed_hausdorff, both directions
                   (exact, double; early break + random shuffle, seed 0)
      ckdtree      scipy.spatial.cKDTree(T).query(Q, workers=-1), both
                   directions, tree builds included (exact, double)
      open3d       open3d PointCloud.compute_point_cloud_distance, both
                   directions (KD-tree, double; OpenMP over queries)
      faiss        faiss.IndexFlatL2 (exact brute force, float32 GEMM
                   expansion): search k=1 both directions; the found
                   neighbour's distance is recomputed in double. Brute force
                   costs the same per query, so with --cap it first times a
                   random subset of queries per direction and, when the
                   linear projection exceeds the cap, reports
                   {"capped": true, "projected_seconds": ...} instead of
                   running for longer than the cap
      pcl          pcl_compute_hausdorff A.pcd B.pcd (the CLI of pcl-tools):
                   time = its own printed compute time (after loading: builds
                   the KD-trees, both directions, single thread); the
                   process wall time (loading included) is reported too
Timing: distance computation only, inputs already in memory as the peer
wants them (float64 for scipy/Open3D, float32 for FAISS); one run, then more
runs (median) while the time spent stays under --budget seconds.
"""
import json
import os
import re
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ply_points import read_ply  # noqa: E402


def exact_pair(q, t, i, j):
    return float(np.linalg.norm(q[i].astype(np.float64) - t[j].astype(np.float64)))


def tool_scipy_dh(a, b):
    from scipy.spatial.distance import directed_hausdorff
    a64, b64 = a.astype(np.float64), b.astype(np.float64)

    def run():
        dab, ia, jb = directed_hausdorff(a64, b64, seed=0)
        dba, ib, ja = directed_hausdorff(b64, a64, seed=0)
        return {"h_ab": dab, "h_ba": dba, "pair_ab": [int(ia), int(jb)], "pair_ba": [int(ib), int(ja)]}
    return run


def tool_ckdtree(a, b):
    from scipy.spatial import cKDTree
    a64, b64 = a.astype(np.float64), b.astype(np.float64)

    def directed(q, t):
        d, idx = cKDTree(t).query(q, k=1, workers=-1)
        i = int(np.argmax(d))
        return float(d[i]), i, int(idx[i])

    def run():
        dab, ia, jb = directed(a64, b64)
        dba, ib, ja = directed(b64, a64)
        return {"h_ab": dab, "h_ba": dba, "pair_ab": [ia, jb], "pair_ba": [ib, ja]}
    return run


def tool_open3d(a, b):
    import open3d as o3d
    pa, pb = o3d.geometry.PointCloud(), o3d.geometry.PointCloud()
    pa.points = o3d.utility.Vector3dVector(a.astype(np.float64))
    pb.points = o3d.utility.Vector3dVector(b.astype(np.float64))

    def run():
        dab = np.asarray(pa.compute_point_cloud_distance(pb))
        dba = np.asarray(pb.compute_point_cloud_distance(pa))
        ia, ib = int(np.argmax(dab)), int(np.argmax(dba))
        return {"h_ab": float(dab[ia]), "h_ba": float(dba[ib]), "pair_ab": [ia, None], "pair_ba": [ib, None]}
    return run


def tool_faiss(a, b):
    import faiss
    a32, b32 = np.ascontiguousarray(a, np.float32), np.ascontiguousarray(b, np.float32)
    faiss.omp_set_num_threads(os.cpu_count() or 1)

    def directed(q, t):
        index = faiss.IndexFlatL2(3)
        index.add(t)
        _, idx = index.search(q, 1)
        idx = idx[:, 0]
        d = np.linalg.norm(q.astype(np.float64) - t[idx].astype(np.float64), axis=1)  # exact recompute
        i = int(np.argmax(d))
        return float(d[i]), i, int(idx[i])

    def run():
        dab, ia, jb = directed(a32, b32)
        dba, ib, ja = directed(b32, a32)
        return {"h_ab": dab, "h_ba": dba, "pair_ab": [ia, jb], "pair_ba": [ib, ja]}

    def project():
        """Seconds the full run would take, from timed random query subsets."""
        rng = np.random.default_rng(0)
        total, probes = 0.0, []
        for q, t in ((a32, b32), (b32, a32)):
            n = int(min(len(q), max(256, 3e8 / len(t))))  # about 1-2 s per direction
            sub = np.ascontiguousarray(q[rng.choice(len(q), n, replace=False)])
            index = faiss.IndexFlatL2(3)
            index.add(t)
            t0 = time.perf_counter()
            index.search(sub, 1)
            dt = time.perf_counter() - t0
            total += dt * len(q) / n
            probes.append({"queries": n, "of": int(len(q)), "seconds": dt})
        return total, probes
    run.project = project
    return run


PCL_DONE = re.compile(r"\[done, ([0-9.eE+-]+) ms : A->B: ([0-9.eE+-]+), B->A: ([0-9.eE+-]+), "
                      r"Hausdorff Distance: ([0-9.eE+-]+)")


def tool_pcl(pcd_a, pcd_b):
    exe = "pcl_compute_hausdorff"

    def run():
        t0 = time.perf_counter()
        p = subprocess.run([exe, pcd_a, pcd_b], capture_output=True, text=True)
        wall = time.perf_counter() - t0
        text = re.sub(r"\x1b\[[0-9;]*m", "", p.stdout + p.stderr)
        m = PCL_DONE.search(text)
        if p.returncode != 0 or not m:
            raise RuntimeError("pcl_compute_hausdorff exit %d: %s" % (p.returncode, text[-400:]))
        return {"h_ab": float(m.group(2)), "h_ba": float(m.group(3)), "pair_ab": None, "pair_ba": None,
                "_seconds": float(m.group(1)) / 1e3, "wall_s": wall, "printed_decimals": 6}
    return run


def faiss_precision(a_path, b_path, n=2000):
    """FAISS's float32 GEMM expansion on B's points that are ALSO points of A
    (true NN distance 0): how many get a wrong neighbour, raw and centred."""
    import faiss
    a, b = read_ply(a_path), read_ply(b_path)
    rng = np.random.default_rng(0)
    sub = np.ascontiguousarray(b[rng.choice(len(b), min(n, len(b)), replace=False)])
    out = {"queries": int(len(sub))}
    a64 = a.astype(np.float64)
    true = cKDTree_min(a64, sub.astype(np.float64))
    out["true_nn_max"] = float(true.max())
    for label, shift in (("raw", np.zeros(3, np.float32)), ("centred", a64.mean(axis=0).astype(np.float32))):
        index = faiss.IndexFlatL2(3)
        index.add(np.ascontiguousarray(a - shift))
        D, I = index.search(np.ascontiguousarray(sub - shift), 1)
        d = np.linalg.norm(sub.astype(np.float64) - a64[I[:, 0]], axis=1)
        out[label] = {"wrong_neighbour": int((d > true + 1e-9).sum()), "max_error": float((d - true).max()),
                      "faiss_reported_max": float(np.sqrt(max(0.0, float(D.max()))))}
    return out


def cKDTree_min(t, q):
    from scipy.spatial import cKDTree
    return cKDTree(t).query(q, k=1, workers=-1)[0]


def main():
    args = sys.argv[1:]
    if args[0] == "faiss-precision":
        print(json.dumps(faiss_precision(args[1], args[2])))
        return
    tool, a_path, b_path = args[0], args[1], args[2]
    opts = {"--max-runs": "3", "--budget": "3", "--cap": None, "--pcd-a": None, "--pcd-b": None}
    rest = args[3:]
    for i in range(0, len(rest), 2):
        opts[rest[i]] = rest[i + 1]
    if tool == "pcl":
        run = tool_pcl(opts["--pcd-a"], opts["--pcd-b"])
    else:
        a, b = read_ply(a_path), read_ply(b_path)
        run = {"scipy-dh": tool_scipy_dh, "ckdtree": tool_ckdtree, "open3d": tool_open3d,
               "faiss": tool_faiss}[tool](a, b)
    if opts.get("--cap") and hasattr(run, "project"):
        projected, probes = run.project()
        if projected > float(opts["--cap"]):
            print(json.dumps({"tool": tool, "capped": True, "projected_seconds": projected, "probes": probes}))
            return
    times, walls, out = [], [], None
    spent = 0.0
    while True:
        t0 = time.perf_counter()
        out = run()
        dt = time.perf_counter() - t0
        spent += dt
        times.append(out.pop("_seconds", dt))
        if "wall_s" in out:
            walls.append(out.pop("wall_s"))
        if len(times) >= int(opts["--max-runs"]) or spent + dt > float(opts["--budget"]):
            break
    out.update({"tool": tool, "seconds": statistics.median(times), "seconds_all": times,
                "hausdorff": max(out["h_ab"], out["h_ba"])})
    if walls:
        out["wall_seconds"] = statistics.median(walls)
    import resource
    out["max_rss_kb"] = max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                            resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
