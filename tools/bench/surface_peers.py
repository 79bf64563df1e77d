#!/usr/bin/python3
"""rthdist's surface features against their peers, side by side in one run
(issue 34): every row runs every tool on the same prepared files
(surface_inputs.py), each tool `--runs` times, and checks the values agree.

  /usr/bin/python3 tools/bench/surface_peers.py --data ../shared/data \
      --rthdist build/rthdist --cgal build/surface-cgal --out docs/bench/surfaces

Rows
  points    h(A's vertices, B's triangles), directed and exact:
            rthdist A B --surface b (cpu backend; --gpu-backends adds ray-query
            or rt-pipeline) against Open3D 0.16 RaycastingScene.compute_distance
            (Embree, float32; max over A's vertices; open3d-kept: the scene
            built once, each run its query alone, beside rthdist's kept
            columns) and surface-cgal points
            (CGAL 5.5 AABB_tree closest_point_and_primitive, double).
            --oneshot-backends adds rthdist-<backend>-oneshot: the same
            bench's --one-shot calls (the free function, a BVH built each
            call, as Open3D builds its scene each run) in one process.
            --kept-backends adds rthdist-<backend>-kept: rthdist-surface-bench
            (--surface-bench), the same call on one Engine that keeps its
            device (Engine::hausdorffToSurface): one warm-up call, then
            --runs calls; compute = each call's total.
  surfaces  H(surface A, surface B): rthdist A B --surface both --tolerance T
            (certified [lower, upper], upper - lower <= T) against surface-cgal
            surfaces (CGAL's bounded_error_symmetric_Hausdorff_distance at the
            same T; it returns its lower bound, its upper at most T above;
            --gpu-backends adds rthdist on those backends, whose compute is
            timings_ms.total less the device's setup) and
            MeshLab 2020.09's sampled "Hausdorff Distance" filter, both ways
            (meshlabserver under xvfb-run, on copies without the vertices no
            triangle uses; vertex + edge + face samples, SampleNum
            = --meshlab-samples-per-face times the sampled mesh's triangles, at
            most --meshlab-max-samples).

Times (milliseconds, median of --runs): "compute" is what each tool reports
for the work without reading files: rthdist's timings_ms.total (the BVH build
and the search; for surfaces all rounds), Open3D's scene build + query,
CGAL's tree build + queries (points) or the whole bounded-error call
(surfaces). MeshLab reports no time: its compute is the process's wall less
the median wall of a process that only loads the two meshes (same xvfb-run).
"wall" is each tool's whole process (rthdist: timings_ms.wall; Open3D and
CGAL: one process for all runs, so wall/runs; MeshLab: process wall).
ratio = peer compute / rthdist compute (> 1: rthdist faster); rthdist is
rthdist-cpu unless --reference names another that ran the row. rthdist-cpu-1t
(in --tools) is the cpu backend on one thread, the thread count of CGAL's
bounded-error Hausdorff; it is shown beside, not used in the ratios.

Agreement: points: |peer - rthdist| <= 1e-12 * max|coordinate| for CGAL
(double), <= 1e-6 * max|coordinate| for Open3D (float32). surfaces: CGAL's
[value, value + T] meets rthdist's [lower, upper]; MeshLab's sampled maximum
is <= upper (a sample lies on the surface; + 5e-7, as meshlabserver prints
its distances with 6 decimals), and is reported when it falls below lower
(sampling missed the farthest region).
"""
import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import surface_inputs  # noqa: E402

# name, kind, A, B. Tolerance of surfaces rows: 1e-4 of the diagonal of both meshes' box.
ROWS = [
    ("bunny>res2", "points", "bunny", "bunny-res2"),
    ("bunny>res3", "points", "bunny", "bunny-res3"),
    ("bunny>res4", "points", "bunny", "bunny-res4"),
    ("bunny-res4>bunny", "points", "bunny-res4", "bunny"),
    ("dragon>res2", "points", "dragon", "dragon-res2"),
    ("dragon>res3", "points", "dragon", "dragon-res3"),
    ("dragon>res4", "points", "dragon", "dragon-res4"),
    ("dragon-res4>dragon", "points", "dragon-res4", "dragon"),
    ("armadillo>dec", "points", "armadillo", "armadillo-dec"),
    ("armadillo-dec>armadillo", "points", "armadillo-dec", "armadillo"),
    ("scans>bunny", "points", "bunny-scans", "bunny"),
    ("bunny>t0.1", "points", "bunny", "bunny-t0.1"),
    ("bunny>t0.01", "points", "bunny", "bunny-t0.01"),
    ("bunny>t0.001", "points", "bunny", "bunny-t0.001"),
    ("bunny|res2", "surfaces", "bunny", "bunny-res2"),
    ("bunny-res2|res3", "surfaces", "bunny-res2", "bunny-res3"),
    ("bunny-res3|res4", "surfaces", "bunny-res3", "bunny-res4"),
    ("dragon|res2", "surfaces", "dragon", "dragon-res2"),
    ("dragon-res2|res3", "surfaces", "dragon-res2", "dragon-res3"),
    ("dragon-res3|res4", "surfaces", "dragon-res3", "dragon-res4"),
    ("armadillo|dec", "surfaces", "armadillo", "armadillo-dec"),
    ("bunny-res2|t0.1", "surfaces", "bunny-res2", "bunny-res2-t0.1"),
    ("bunny-res2|t0.01", "surfaces", "bunny-res2", "bunny-res2-t0.01"),
    ("bunny-res2|t0.001", "surfaces", "bunny-res2", "bunny-res2-t0.001"),
]
PEERS = {"points": ["open3d", "open3d-kept", "cgal"], "surfaces": ["cgal", "meshlab"]}
RELATIVE_TOLERANCE = {"cgal": 1e-12, "open3d": 1e-6, "open3d-kept": 1e-6}

MESHLAB_SCRIPT = """<!DOCTYPE FilterScript>
<FilterScript>
%s</FilterScript>
"""
MESHLAB_FILTER = """ <filter name="Hausdorff Distance">
  <Param type="RichMesh" value="%d" name="SampledMesh"/>
  <Param type="RichMesh" value="%d" name="TargetMesh"/>
  <Param type="RichBool" value="false" name="SaveSample"/>
  <Param type="RichBool" value="true" name="SampleVert"/>
  <Param type="RichBool" value="true" name="SampleEdge"/>
  <Param type="RichBool" value="false" name="SampleFauxEdge"/>
  <Param type="RichBool" value="true" name="SampleFace"/>
  <Param type="RichInt" value="%d" name="SampleNum"/>
  <Param type="RichAbsPerc" value="%.17g" min="0" max="%.17g" name="MaxDist"/>
 </filter>
"""


def run_process(cmd, timeout, env=None):
    """(stdout, wall seconds) or raises RuntimeError with the reason."""
    start = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        raise RuntimeError("timeout > %d s" % timeout)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        raise RuntimeError("exit %d: %s" % (p.returncode, (p.stderr or p.stdout).strip()[-300:]))
    return p.stdout, wall


def rthdist_tool(args, backend, threads=0):
    def run(row, a, b, tolerance):
        cmd = [args.rthdist, a, b, "--json", "--quiet", "--backend", backend, "--threads", str(threads)]
        cmd += ["--surface", "b"] if row["kind"] == "points" else ["--surface", "both", "--tolerance",
                                                                   repr(tolerance)]
        compute, wall, value = [], [], None
        for _ in range(args.runs):
            out, _ = run_process(cmd, args.cap)
            j = json.loads(out)
            # A GPU backend's surface-to-surface call opens its device (setup,
            # beside the meshes' checks): its compute is the rest.
            compute.append(j["timings_ms"]["total"] - j["timings_ms"].get("setup", 0.0))
            wall.append(j["timings_ms"]["wall"])
            if row["kind"] == "points":
                value = {"h": j["hausdorff"], "query": j["a_to_b"]["a_index"], "triangle": j["a_to_b"]["triangle"]}
            else:
                value = {"lower": j["bounds"][0], "upper": j["bounds"][1], "tolerance": j["tolerance"],
                         "queries": j["counters"]["a_to_b"]["queries"] + j["counters"]["b_to_a"]["queries"]}
            value["build_ms"] = j["timings_ms"]["build"]
            value["search_ms"] = j["timings_ms"]["search"]
            value["setup_ms"] = j["timings_ms"].get("setup", 0.0)
            value["gpu_ms"] = j["timings_ms"].get("gpu", 0.0)
            value["device"] = j["device"]
        return compute, wall, value
    return run


def kept_tool(args, backend):
    """rthdist-surface-bench: --runs calls on one Engine after a warm-up call."""
    def run(row, a, b, tolerance):
        cmd = [args.surface_bench, a, b, "--backend", backend, "--runs", str(args.runs), "--warmup", "1",
               "--no-verify"]
        out, wall = run_process(cmd, args.cap * (args.runs + 2))
        j = json.loads(out)
        m = j["kept_median_ms"]
        value = {"h": j["hausdorff"], "query": j["query"], "triangle": j["triangle"], "device": j["device"],
                 "setup_ms": j["setup_ms"], "warmup_ms": j["warmup_ms"], "counters": j["counters"],
                 "stages_ms": {k: m[k] for k in ("frame", "upload", "device", "readback", "certify", "gpu",
                                                 "gpu_build", "tail_build", "gpu_tail", "tail_host") if k in m}}
        return j["kept_total_ms_all"], j["kept_wall_ms_all"], value
    return run


def oneshot_tool(args, backend):
    """rthdist-surface-bench --one-shot: --runs calls of the free function
    hausdorffToSurface in one process (each builds its BVH and, on a GPU
    backend, opens its device), as Open3D's runs build a scene each in one
    Python process; one Engine call before them warms the process."""
    def run(row, a, b, tolerance):
        cmd = [args.surface_bench, a, b, "--backend", backend, "--runs", "1", "--warmup", "0",
               "--one-shot", str(args.runs), "--no-verify"]
        out, wall = run_process(cmd, args.cap * (args.runs + 2))
        j = json.loads(out)
        m = j["one_shot_median_ms"]
        value = {"h": j["hausdorff"], "query": j["query"], "triangle": j["triangle"], "device": j["device"],
                 "build_ms": m["build"], "search_ms": m["search"]}
        return j["one_shot_total_ms_all"], j["one_shot_wall_ms_all"], value
    return run


def open3d_tool(args, kept=False):
    def run(row, a, b, tolerance):
        out, wall = run_process([args.open3d_python or sys.executable, os.path.abspath(__file__),
                                 "--open3d-worker", a, b, str(args.runs)] + (["--open3d-kept"] if kept else []),
                                args.cap * args.runs)
        j = json.loads(out)
        return j["ms"], [1000.0 * wall / args.runs] * args.runs, {"h": j["h"], "query": j["query"]}
    return run


def open3d_worker(a, b, runs, kept=False):
    """Each run builds the scene and queries; kept: the scene built once
    (untimed), each run its query alone (as an Engine that keeps its tree)."""
    import numpy as np
    import open3d as o3d
    points, _ = surface_inputs.read_prepared(a)
    verts, faces = surface_inputs.read_prepared(b)
    query = o3d.core.Tensor(np.ascontiguousarray(points, dtype=np.float32))
    v = o3d.core.Tensor(np.ascontiguousarray(verts, dtype=np.float32))
    f = o3d.core.Tensor(np.ascontiguousarray(faces, dtype=np.uint32))
    ms, h, q = [], None, None
    scene = None
    if kept:
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(v, f)
        scene.compute_distance(query)  # the first query commits the scene
    for _ in range(runs):
        start = time.perf_counter()
        if not kept:
            scene = o3d.t.geometry.RaycastingScene()
            scene.add_triangles(v, f)
        d = scene.compute_distance(query).numpy()
        q = int(np.argmax(d))
        h = float(d[q])
        ms.append(1000.0 * (time.perf_counter() - start))
    print(json.dumps({"ms": ms, "h": h, "query": q, "open3d": o3d.__version__}))


def cgal_tool(args):
    def run(row, a, b, tolerance):
        cmd = [args.cgal, row["kind"], a, b, "--repeat", str(args.runs)]
        if row["kind"] == "surfaces":
            cmd += ["--tolerance", repr(tolerance)]
        out, wall = run_process(cmd, args.cap * args.runs)
        j = json.loads(out)
        value = {"h": j["h"]}
        if row["kind"] == "points":
            value.update(query=j["query_index"], triangle=j["triangle"])
        return j["total_ms"], [1000.0 * wall / args.runs] * args.runs, value
    return run


def meshlab_maxima(out, a, b):
    """[h(a, b), h(b, a)] from meshlabserver's stdout, which repeats earlier
    filters' logs: each 'Sampled N pts (rng: 0) on A searched closest on B'
    line and the absolute 'min : .. max X' line after it."""
    found = {}
    lines = out.splitlines()
    for i, line in enumerate(lines[:-1]):
        words = line.split()
        if words[:1] == ["Sampled"] and "closest" in words and lines[i + 1].split()[:2] == ["min", ":"]:
            found[(words[-5], words[-1])] = float(lines[i + 1].split("max")[1].split()[0])
    names = (os.path.basename(a), os.path.basename(b))
    return [found[k] for k in (names, names[::-1]) if k in found]


def referenced_copy(path, folder):
    """The mesh at path without the vertices no triangle uses, written to
    folder: the same surface. MeshLab samples every vertex (SampleVert), so a
    stray vertex would count as a point of the surface (bunny-res2 has 25,
    dragon-res2 43); rthdist and CGAL measure triangles only."""
    import numpy as np
    verts, faces = surface_inputs.read_prepared(path)
    used = np.unique(faces.ravel())
    new_index = np.full(len(verts), -1, dtype=np.int64)
    new_index[used] = np.arange(len(used))
    out = os.path.join(folder, os.path.basename(path))
    surface_inputs.write_mesh(out, verts[used], new_index[faces])
    return out


def meshlab_tool(args):
    def run(row, a, b, tolerance):
        env = dict(os.environ, QT_QPA_PLATFORM="xcb")  # the X server of xvfb-run (offscreen aborts: no GL)
        scratch = tempfile.mkdtemp(prefix="rthdist-meshlab-")
        a, b = referenced_copy(a, scratch), referenced_copy(b, scratch)
        base = ["xvfb-run", "-a", "meshlabserver", "-i", a, "-i", b]
        na, nb = row["triangles"]
        diag = row["diagonal"]
        samples = [min(args.meshlab_samples_per_face * n, args.meshlab_max_samples) for n in (na, nb)]
        script = MESHLAB_SCRIPT % (MESHLAB_FILTER % (0, 1, samples[0], diag, diag)
                                   + MESHLAB_FILTER % (1, 0, samples[1], diag, diag))
        with tempfile.NamedTemporaryFile("w", suffix=".mlx", delete=False) as f:
            f.write(script)
        try:
            load = [run_process(base, args.cap, env)[1] for _ in range(args.runs)]
            compute, wall, maxima = [], [], []
            for _ in range(args.runs):
                out, seconds = run_process(base + ["-s", f.name], args.cap, env)
                maxima = meshlab_maxima(out, a, b)
                wall.append(1000.0 * seconds)
            load_ms = 1000.0 * statistics.median(load)
            compute = [max(w - load_ms, 0.0) for w in wall]
        finally:
            os.unlink(f.name)
            for p in (a, b):
                os.unlink(p)
            os.rmdir(scratch)
        if len(maxima) != 2:
            raise RuntimeError("expected two Hausdorff logs from meshlabserver, got %d" % len(maxima))
        return compute, wall, {"h": max(maxima), "a_to_b": maxima[0], "b_to_a": maxima[1], "load_ms": load_ms,
                               "samples": samples}
    return run


def agreement(row, results):
    """Each peer's check against rthdist-cpu (or the first rthdist that ran)."""
    ref = next((results[t] for t in results if t.startswith("rthdist") and "value" in results[t]), None)
    if ref is None:
        return
    scale = row["max_abs_coordinate"]
    for tool, r in results.items():
        if "value" not in r:
            continue
        v = r["value"]
        if row["kind"] == "points":
            diff = abs(v["h"] - ref["value"]["h"])
            limit = RELATIVE_TOLERANCE.get(tool, 0.0) * scale
            r["check"] = {"diff": diff, "relative_to_max_coordinate": diff / scale, "limit": limit,
                          "agrees": diff <= limit}
        elif tool.startswith("rthdist"):
            r["check"] = {"agrees": v["lower"] <= v["upper"] and v["upper"] - v["lower"] <= v["tolerance"]}
        else:
            lower, upper = ref["value"]["lower"], ref["value"]["upper"]
            if tool == "cgal":
                ok = v["h"] <= upper and v["h"] + row["tolerance"] >= lower
                r["check"] = {"agrees": ok, "cgal_interval": [v["h"], v["h"] + row["tolerance"]],
                              "below_lower": max(lower - v["h"], 0.0)}
            else:
                ok = v["h"] <= upper + 5e-7  # meshlabserver prints 6 decimals
                r["check"] = {"agrees": ok, "below_lower": max(lower - v["h"], 0.0),
                              "above_upper": max(v["h"] - upper, 0.0),
                              "note": "sampled, below rthdist's lower" if v["h"] < lower else ""}


def machine():
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "system": platform.platform(), "python": platform.python_version()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--open3d-worker", nargs=3, metavar=("A", "B", "RUNS"), help=argparse.SUPPRESS)
    ap.add_argument("--open3d-kept", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--data", default=os.path.join(HERE, "..", "..", "..", "shared", "data"))
    ap.add_argument("--work", default="/tmp/rthdist-surface-work", help="prepared inputs (reused)")
    ap.add_argument("--inputs", default="", help="read prepared inputs from here, prepare nothing")
    ap.add_argument("--out", default="", help="folder for results.json and table.md (default: print only)")
    ap.add_argument("--rthdist", default="build/rthdist")
    ap.add_argument("--cgal", default="build/surface-cgal")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cap", type=int, default=300, help="seconds per process")
    ap.add_argument("--rows", default="", help="comma-separated row names (default: all)")
    ap.add_argument("--tools", default="rthdist-cpu,open3d,cgal,meshlab")
    ap.add_argument("--gpu-backends", default="", help="rthdist backends for points and surfaces rows, e.g. ray-query")
    ap.add_argument("--gpu-rows", default="", help="points rows the GPU backends run (default: all points rows)")
    ap.add_argument("--kept-backends", default="",
                    help="rthdist backends timed on a kept Engine (rthdist-surface-bench) for points rows")
    ap.add_argument("--oneshot-backends", default="",
                    help="rthdist backends timed as one-shot calls in one process (rthdist-surface-bench "
                         "--one-shot) for points rows: rthdist-<backend>-oneshot")
    ap.add_argument("--open3d-python", default="",
                    help="the Python that runs Open3D's worker (default: this one), e.g. a carried "
                         "interpreter's wrapper on a machine without Open3D")
    ap.add_argument("--surface-bench", default="build/rthdist-surface-bench")
    ap.add_argument("--reference", default="rthdist-cpu",
                    help="ratios against this rthdist (e.g. rthdist-rt-pipeline); rows it did not run: rthdist-cpu")
    ap.add_argument("--meshlab-samples-per-face", type=int, default=10)
    ap.add_argument("--meshlab-max-samples", type=int, default=2_000_000,
                    help="SampleNum cap: 8.7M samples on the Dragon abort meshlabserver 2020.09 "
                         "(vcg GridStaticPtr assertion)")
    ap.add_argument("--update", action="store_true",
                    help="keep --out's results.json and replace only the rows run now")
    ap.add_argument("--tolerance-fraction", type=float, default=1e-4, help="surfaces: T = this x the diagonal")
    ap.add_argument("--render", action="store_true", help="only write --out's table.md from its results.json")
    args = ap.parse_args()
    if args.render:
        with open(os.path.join(args.out, "results.json")) as f:
            write_outputs(json.load(f), args.out)
        return
    if args.open3d_worker:
        open3d_worker(args.open3d_worker[0], args.open3d_worker[1], int(args.open3d_worker[2]),
                      args.open3d_kept)
        return

    tools = {}
    for name in args.tools.split(","):
        if name == "rthdist-cpu":
            tools[name] = rthdist_tool(args, "cpu")
        elif name == "rthdist-cpu-1t":  # one thread, as CGAL's bounded-error Hausdorff
            tools[name] = rthdist_tool(args, "cpu", threads=1)
        elif name == "open3d":
            tools[name] = open3d_tool(args)
        elif name == "open3d-kept":  # the scene built once, each run its query alone
            tools[name] = open3d_tool(args, kept=True)
        elif name == "cgal":
            tools[name] = cgal_tool(args)
        elif name == "meshlab":
            # Checked before any row runs: each row would otherwise stop the
            # script at MeshLab's first call.
            missing = [c for c in ("meshlabserver", "xvfb-run") if shutil.which(c) is None]
            if missing:
                sys.exit("meshlab: " + " and ".join(missing) + " not found (bash tools/bench/setup.sh installs "
                         "them; or leave meshlab out of --tools)")
            tools[name] = meshlab_tool(args)
        elif name:
            sys.exit("unknown tool " + name)
    gpu = [b for b in args.gpu_backends.split(",") if b]
    kept = [b for b in args.kept_backends.split(",") if b]
    oneshot = [b for b in args.oneshot_backends.split(",") if b]
    gpu_rows = set(r for r in args.gpu_rows.split(",") if r)
    wanted = set(r for r in args.rows.split(",") if r)
    rows = [r for r in ROWS if not wanted or r[0] in wanted]
    folder = args.inputs or args.work
    described = {}
    results = {"machine": machine(), "runs": args.runs, "tolerance_fraction": args.tolerance_fraction,
               "meshlab_samples_per_face": args.meshlab_samples_per_face,
               "meshlab_max_samples": args.meshlab_max_samples, "rows": []}
    earlier = []
    if args.update and args.out and os.path.exists(os.path.join(args.out, "results.json")):
        with open(os.path.join(args.out, "results.json")) as f:
            earlier = json.load(f)["rows"]
    for name, kind, a, b in rows:
        for n in (a, b):
            if n not in described:
                if not args.inputs:
                    surface_inputs.prepare(n, args.data, args.work)
                described[n] = surface_inputs.describe(n, folder)
        da, db = described[a], described[b]
        row = {"name": name, "kind": kind, "a": a, "b": b, "points_a": da["vertices"],
               "triangles": [da["triangles"], db["triangles"]],
               "max_abs_coordinate": max(da["max_abs_coordinate"], db["max_abs_coordinate"]),
               "diagonal": max(da["diagonal"], db["diagonal"])}
        box = None
        if kind == "surfaces":
            # T: the fraction of the diagonal of the box of both meshes (rthdist's default rule).
            import numpy as np
            va, _ = surface_inputs.read_prepared(os.path.join(folder, a + ".ply"))
            vb, _ = surface_inputs.read_prepared(os.path.join(folder, b + ".ply"))
            box = np.concatenate([va, vb]).astype(np.float64)
            row["tolerance"] = args.tolerance_fraction * float(np.linalg.norm(box.max(0) - box.min(0)))
        row_tools = [t for t in tools if t.startswith("rthdist") or t in PEERS[kind]]
        row_tools += ["rthdist-" + g for g in gpu if not gpu_rows or name in gpu_rows]
        if kind == "points":
            row_tools += ["rthdist-" + k + "-kept" for k in kept if not gpu_rows or name in gpu_rows]
            row_tools += ["rthdist-" + k + "-oneshot" for k in oneshot]
        per_tool = {}
        pa, pb = os.path.join(folder, a + ".ply"), os.path.join(folder, b + ".ply")
        for tool in row_tools:
            if tool in tools:
                run = tools[tool]
            elif tool.endswith("-kept"):
                run = kept_tool(args, tool[len("rthdist-"):-len("-kept")])
            elif tool.endswith("-oneshot"):
                run = oneshot_tool(args, tool[len("rthdist-"):-len("-oneshot")])
            else:
                run = rthdist_tool(args, tool[len("rthdist-"):])
            try:
                compute, wall, value = run(row, pa, pb, row.get("tolerance"))
                per_tool[tool] = {"compute_ms": statistics.median(compute), "wall_ms": statistics.median(wall),
                                  "compute_runs_ms": compute, "value": value}
            except RuntimeError as e:
                per_tool[tool] = {"error": str(e)}
            print(name, tool, json.dumps(per_tool[tool])[:300], flush=True)
        agreement(row, per_tool)
        reference = args.reference if "compute_ms" in per_tool.get(args.reference, {}) else "rthdist-cpu"
        ref = per_tool.get(reference, {}).get("compute_ms")
        row["reference"] = reference
        for tool, r in per_tool.items():
            if ref and "compute_ms" in r and not tool.startswith("rthdist"):
                r["ratio"] = r["compute_ms"] / ref
        row["tools"] = per_tool
        results["rows"].append(row)
        if args.out:
            write_outputs(merged(earlier, results), args.out)
    if args.out:
        write_outputs(merged(earlier, results), args.out)


def merged(earlier, results):
    """results with the rows of `earlier` that it did not run, in ROWS order."""
    rows = {r["name"]: r for r in earlier}
    rows.update({r["name"]: r for r in results["rows"]})
    order = [name for name, _, _, _ in ROWS]
    return dict(results, rows=sorted(rows.values(), key=lambda r: order.index(r["name"])))


def fmt_ms(r):
    if "error" in r:
        return "— (%s)" % r["error"].split(":")[0]
    return "%.0f" % r["compute_ms"] if r["compute_ms"] >= 10 else "%.1f" % r["compute_ms"]


def write_outputs(results, out):
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    tools = []
    for row in results["rows"]:
        for t in row["tools"]:
            if t not in tools:
                tools.append(t)
    lines = ["| row | kind | A pts / tris | B tris | rthdist value | " + " | ".join(tools) +
             " | ratios (peer / reference) | agree |",
             "|---|---|---:|---:|---|" + "---:|" * len(tools) + "---|---|"]
    for row in results["rows"]:
        rt = row["tools"].get("rthdist-cpu", {})
        v = rt.get("value", {})
        if row["kind"] == "points":
            value = "%.9g" % v["h"] if v else "—"
            a_size = "%d pts" % row["points_a"]
        else:
            value = "[%.9g, %.9g]" % (v["lower"], v["upper"]) if v else "—"
            a_size = "%d tris" % row["triangles"][0]
        cells = [fmt_ms(row["tools"][t]) if t in row["tools"] else "" for t in tools]
        ratios = ", ".join("%s %.2f" % (t, r["ratio"]) for t, r in row["tools"].items() if "ratio" in r)
        if ratios and row.get("reference", "rthdist-cpu") != "rthdist-cpu":
            ratios += " (vs %s)" % row["reference"]
        one = row["tools"].get("rthdist-cpu-1t", {})
        if "compute_ms" in one and "compute_ms" in row["tools"].get("cgal", {}):
            ratios += "; cgal / rthdist-cpu-1t %.2f" % (row["tools"]["cgal"]["compute_ms"] / one["compute_ms"])
        checks = [(t, r["check"]) for t, r in row["tools"].items() if "check" in r]
        agree = "yes" if checks and all(c["agrees"] for _, c in checks) else \
            "NO: " + ", ".join(t for t, c in checks if not c["agrees"])
        notes = [t + " below lower by %.3g" % c["below_lower"] for t, c in checks
                 if c.get("below_lower", 0) > 0 and t == "meshlab"]
        notes += [t + " above upper by %.3g" % c["above_upper"] for t, c in checks if c.get("above_upper", 0) > 0]
        if notes:
            agree += " (" + "; ".join(notes) + ")"
        lines.append("| %s | %s | %s | %d | %s | %s | %s | %s |" % (
            row["name"].replace("|", "\\|"), row["kind"], a_size, row["triangles"][1], value, " | ".join(cells), ratios, agree))
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write("Compute milliseconds, median of %d runs (the tools' own timings, file reading excluded; "
                "MeshLab: process wall less a load-only process).\n\n" % results["runs"])
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
