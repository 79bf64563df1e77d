#!/usr/bin/python3
"""The benchmark's scenarios (issue 4, after the RT-HDIST paper): how each is
built from ../shared/data, and writing them once as float32 point files that
every tool reads (binary PLY for rthdist and the Python peers, binary PCD for
PCL), so all tools see the SAME float32 coordinates.

  scenarios.py DATA WORK [NAME ...]     prepare (all when no NAME) and list

Every scenario is a pair of vertex sets (A, B); H is symmetric.
  decimation   a model vs Stanford's own decimation / a LiDAR subset, as stored
  translation  B = A moved along x by F * (A's x-extent), float32 arithmetic
  different    each model normalized to unit bbox diagonal and centred at the
               origin (double, then rounded to float32 once), B moved +0.5 in x
  scale        independent area-weighted samplings of the Dragon's surface,
               fixed seeds (the paper's 3.6M/5M models are not available here)
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ply_points import read_ply, write_ply  # noqa: E402

DRAGON = "stanford/dragon/dragon_vrip.ply.gz"
BUNNY = "stanford/bunny/bun_zipper.ply"
IGEA = "scans/igea.ply"
NEFERTITI = "scans/nefertiti.obj"

# name -> (group, recipe). Recipes: ("files", a, b), ("translate", a, F),
# ("different", a, b), ("sample", mesh, n, seed_a, seed_b).
SCENARIOS = {
    "dragon-res2": ("decimation", ("files", DRAGON, "stanford/dragon/dragon_vrip_res2.ply.gz")),
    "dragon-res3": ("decimation", ("files", DRAGON, "stanford/dragon/dragon_vrip_res3.ply.gz")),
    "dragon-res4": ("decimation", ("files", DRAGON, "stanford/dragon/dragon_vrip_res4.ply.gz")),
    "bunny-res2": ("decimation", ("files", BUNNY, "stanford/bunny/bun_zipper_res2.ply")),
    "lidar-fsite8-red1": ("decimation", ("files", "lidar/FSite8_orig-utm.ply", "lidar/FSite8_red1-utm.ply")),
    "dragon-t0.3": ("translation", ("translate", DRAGON, 0.3)),
    "dragon-t0.5": ("translation", ("translate", DRAGON, 0.5)),
    "dragon-t0.7": ("translation", ("translate", DRAGON, 0.7)),
    "igea-t0.5": ("translation", ("translate", IGEA, 0.5)),
    "dragon-igea": ("different", ("different", DRAGON, IGEA)),
    "dragon-bunny": ("different", ("different", DRAGON, BUNNY)),
    "igea-nefertiti": ("different", ("different", IGEA, NEFERTITI)),
    "surface-1M": ("scale", ("sample", DRAGON, 1_000_000, 1, 2)),
    "surface-5M": ("scale", ("sample", DRAGON, 5_000_000, 3, 4)),
}


def read_points(path):
    """float32 (N, 3) vertices of a PLY (ascii/binary, gz) or OBJ file."""
    if path.endswith(".obj"):
        rows = []
        with open(path, "rb") as f:
            for line in f:
                if line.startswith(b"v "):
                    rows.append(line.split()[1:4])
        return np.array(rows, dtype=np.float64).astype(np.float32)
    return read_ply(path)


def normalize(points):
    """Unit bbox diagonal, bbox centre at the origin (double, one rounding)."""
    p = points.astype(np.float64)
    lo, hi = p.min(axis=0), p.max(axis=0)
    return ((p - 0.5 * (lo + hi)) / np.linalg.norm(hi - lo)).astype(np.float32)


def write_pcd(path, points):
    points = np.ascontiguousarray(points, dtype="<f4")
    n = len(points)
    header = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
              "TYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\n"
              "DATA binary\n" % (n, n))
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(points.tobytes())


def bbox_diagonal(points):
    p = points.astype(np.float64)
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))


def build(name, data):
    """(A, B, description) as float32 arrays."""
    group, r = SCENARIOS[name]
    kind = r[0]
    if kind == "files":
        a, b = read_points(os.path.join(data, r[1])), read_points(os.path.join(data, r[2]))
        return a, b, "%s vs %s (as stored)" % (r[1], r[2])
    if kind == "translate":
        a = read_points(os.path.join(data, r[1]))
        dx = np.float32(r[2] * (float(a[:, 0].max()) - float(a[:, 0].min())))
        b = a.copy()
        b[:, 0] += dx  # float32 arithmetic
        return a, b, "%s vs itself moved +%g of its x-extent along x (dx = %.9g)" % (r[1], r[2], float(dx))
    if kind == "different":
        a = normalize(read_points(os.path.join(data, r[1])))
        b = normalize(read_points(os.path.join(data, r[2])))
        b[:, 0] += np.float32(0.5)
        return a, b, "%s vs %s, each unit bbox diagonal and centred, B moved +0.5 along x" % (r[1], r[2])
    if kind == "sample":
        from sample_surface import sample
        verts, faces = read_ply(os.path.join(data, r[1]), want_faces=True)
        a = sample(verts, faces, r[2], r[3])
        b = sample(verts, faces, r[2], r[4])
        return a, b, "%s surface, %d area-weighted samples per side, seeds %d / %d" % (r[1], r[2], r[3], r[4])
    raise ValueError(kind)


def prepare(name, data, work):
    """Writes WORK/NAME/{a,b}.{ply,pcd} + meta.json once; returns the meta dict."""
    d = os.path.join(work, name)
    meta_path = os.path.join(d, "meta.json")
    if os.path.exists(meta_path):
        with open(meta_path) as f:
            return json.load(f)
    os.makedirs(d, exist_ok=True)
    a, b, desc = build(name, data)
    for side, p in (("a", a), ("b", b)):
        write_ply(os.path.join(d, side + ".ply"), p)
        write_pcd(os.path.join(d, side + ".pcd"), p)
    meta = {"name": name, "group": SCENARIOS[name][0], "description": desc,
            "points_a": int(len(a)), "points_b": int(len(b)),
            "diag_a": bbox_diagonal(a), "diag_b": bbox_diagonal(b),
            "tolerance": 1e-6 * max(bbox_diagonal(a), bbox_diagonal(b)),
            "a_ply": os.path.join(d, "a.ply"), "b_ply": os.path.join(d, "b.ply"),
            "a_pcd": os.path.join(d, "a.pcd"), "b_pcd": os.path.join(d, "b.pcd")}
    with open(meta_path + ".tmp", "w") as f:
        json.dump(meta, f, indent=1)
    os.replace(meta_path + ".tmp", meta_path)
    return meta


if __name__ == "__main__":
    data, work = sys.argv[1], sys.argv[2]
    for n in sys.argv[3:] or list(SCENARIOS):
        m = prepare(n, data, work)
        print("%-18s %9d / %9d  %s" % (n, m["points_a"], m["points_b"], m["description"]))
