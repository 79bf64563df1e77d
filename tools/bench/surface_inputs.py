#!/usr/bin/python3
"""The surface benchmark's inputs (issue 34; tools/bench/surface_peers.py),
written once from ../shared/data as binary little-endian PLY files that every
tool reads: float x y z vertices and, for meshes, triangles as a face list of
uchar count and int indices. So rthdist, Open3D, CGAL and MeshLab all see the
same float32 coordinates and the same triangles.

  surface_inputs.py DATA WORK [NAME ...]   prepare (all when no NAME) and list

Recipes
  mesh        a Stanford / CGAL mesh as stored (PLY, PLY.gz, OFF)
  decimate    Open3D 0.16's simplify_quadric_decimation of a mesh to a
              triangle count (deterministic; Open3D is needed only here)
  scans       the 10 bunny range scans (points, no faces), each moved into the
              zippered bunny's frame by its line of bun.conf: p -> R(q)^T p + t
              (q = qx qy qz qw), in double, rounded to float32 once. That is
              the reading that registers all 10 (median distance to the
              zippered bunny's vertices 0.5 mm per scan; R(q) p + t leaves
              8 of them 12-130 mm off)
  translate   a mesh moved by F times its box diagonal along (1, 2, 3)/|(1, 2, 3)|,
              in double, rounded to float32 once (the Tang scenario)
"""
import gzip
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ply_points import read_ply  # noqa: E402

BUNNY = "stanford/bunny/bun_zipper%s.ply"
DRAGON = "stanford/dragon/dragon_vrip%s.ply.gz"
ARMADILLO = "stanford/armadillo/armadillo.off"

INPUTS = {
    "bunny": ("mesh", BUNNY % ""),
    "bunny-res2": ("mesh", BUNNY % "_res2"),
    "bunny-res3": ("mesh", BUNNY % "_res3"),
    "bunny-res4": ("mesh", BUNNY % "_res4"),
    "dragon": ("mesh", DRAGON % ""),
    "dragon-res2": ("mesh", DRAGON % "_res2"),
    "dragon-res3": ("mesh", DRAGON % "_res3"),
    "dragon-res4": ("mesh", DRAGON % "_res4"),
    "armadillo": ("mesh", ARMADILLO),
    "armadillo-dec": ("decimate", "armadillo", 13000),
    "bunny-scans": ("scans", "stanford/bunny/range_scans"),
    "bunny-t0.1": ("translate", "bunny", 0.1),
    "bunny-t0.01": ("translate", "bunny", 0.01),
    "bunny-t0.001": ("translate", "bunny", 0.001),
    "bunny-res2-t0.1": ("translate", "bunny-res2", 0.1),
    "bunny-res2-t0.01": ("translate", "bunny-res2", 0.01),
    "bunny-res2-t0.001": ("translate", "bunny-res2", 0.001),
}


def read_off(path):
    with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as f:
        words = f.read().split()
    if words[0] != "OFF":
        raise ValueError(path + ": not OFF")
    nv, nf = int(words[1]), int(words[2])
    pos = 4
    verts = np.array(words[pos:pos + 3 * nv], dtype=np.float64).reshape(nv, 3).astype(np.float32)
    pos += 3 * nv
    tris = []
    for _ in range(nf):
        k = int(words[pos])
        poly = [int(w) for w in words[pos + 1:pos + 1 + k]]
        pos += 1 + k
        tris += [(poly[0], poly[j], poly[j + 1]) for j in range(1, k - 1)]
    return verts, np.array(tris, dtype=np.int64)


def read_mesh(path):
    if path.endswith(".off") or path.endswith(".off.gz"):
        return read_off(path)
    return read_ply(path, want_faces=True)


def write_mesh(path, verts, faces=None):
    verts = np.ascontiguousarray(verts, dtype="<f4")
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(verts)
    header += "property float x\nproperty float y\nproperty float z\n"
    if faces is not None:
        header += "element face %d\nproperty list uchar int vertex_indices\n" % len(faces)
    header += "end_header\n"
    with open(path + ".tmp", "wb") as f:
        f.write(header.encode())
        f.write(verts.tobytes())
        if faces is not None:
            rec = np.empty(len(faces), dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]))
            rec["n"] = 3
            rec["i"] = faces
            f.write(rec.tobytes())
    os.replace(path + ".tmp", path)


def read_prepared(path):
    return read_ply(path, want_faces=True)


def quaternion_matrix(qx, qy, qz, qw):
    n = np.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    x, y, z, w = qx / n, qy / n, qz / n, qw / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def registered_scans(folder):
    parts = []
    with open(os.path.join(folder, "bun.conf")) as conf:
        for line in conf:
            w = line.split()
            if not w or w[0] != "bmesh":
                continue
            t = np.array([float(v) for v in w[2:5]])
            r = quaternion_matrix(*[float(v) for v in w[5:9]])
            pts = read_ply(os.path.join(folder, w[1])).astype(np.float64)
            parts.append(pts @ r + t)  # row vectors: R^T p
    return np.concatenate(parts).astype(np.float32)


def diagonal(verts):
    v = verts.astype(np.float64)
    return float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))


def prepare(name, data, work):
    path = os.path.join(work, name + ".ply")
    if os.path.exists(path):
        return path
    recipe = INPUTS[name]
    if recipe[0] == "mesh":
        verts, faces = read_mesh(os.path.join(data, recipe[1]))
    elif recipe[0] == "decimate":
        import open3d as o3d
        base_v, base_f = read_prepared(prepare(recipe[1], data, work))
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(base_v.astype(np.float64)),
                                         o3d.utility.Vector3iVector(base_f.astype(np.int32)))
        dec = mesh.simplify_quadric_decimation(target_number_of_triangles=recipe[2])
        verts, faces = np.asarray(dec.vertices).astype(np.float32), np.asarray(dec.triangles).astype(np.int64)
    elif recipe[0] == "scans":
        verts, faces = registered_scans(os.path.join(data, recipe[1])), None
    elif recipe[0] == "translate":
        base_v, faces = read_prepared(prepare(recipe[1], data, work))
        u = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
        verts = (base_v.astype(np.float64) + recipe[2] * diagonal(base_v) * u).astype(np.float32)
    else:
        raise ValueError(recipe)
    write_mesh(path, verts, faces)
    return path


def describe(name, work):
    verts, faces = read_prepared(os.path.join(work, name + ".ply"))
    return {"name": name, "recipe": list(INPUTS[name]), "vertices": int(len(verts)),
            "triangles": 0 if faces is None else int(len(faces)), "diagonal": diagonal(verts),
            "max_abs_coordinate": float(np.abs(verts.astype(np.float64)).max())}


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    data, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    for name in sys.argv[3:] or list(INPUTS):
        prepare(name, data, work)
        print(json.dumps(describe(name, work)))


if __name__ == "__main__":
    main()
