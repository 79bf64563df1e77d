#!/usr/bin/env python3
"""Area-weighted uniform samples on a triangle mesh's surface, fixed seed.

  sample_surface.py MESH.ply[.gz] N SEED OUT.ply

The paper's multi-million-point models are not available here; the benchmark
uses independent samplings of the Dragon's surface instead (say so wherever
the numbers appear).
"""
import sys
import numpy as np
from ply_points import read_ply, write_ply


def sample(verts, faces, n, seed):
    rng = np.random.default_rng(seed)
    v = verts.astype(np.float64)
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    tri = rng.choice(len(faces), size=n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    u, w = 1.0 - s, s * r2
    p = a[tri] * u[:, None] + b[tri] * (s * (1.0 - r2))[:, None] + c[tri] * w[:, None]
    return p.astype(np.float32)


if __name__ == "__main__":
    mesh, n, seed, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    verts, faces = read_ply(mesh, want_faces=True)
    write_ply(out, sample(verts, faces, n, seed))
