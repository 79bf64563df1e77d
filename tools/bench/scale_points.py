#!/usr/bin/env python3
"""Large fixed-seed samplings for the size tests of docs/bench/gpu.md, written
as binary little-endian PLY (float x y z) in chunks, so 400M points need
about 1 GB of memory, not 10.

  scale_points.py torus|sphere N SEED OUT.ply

torus: area-uniform samples of the torus R = 1, r = 0.3 with Gaussian noise
(sigma 1e-4) along the normal; sphere: uniform on the unit sphere. Two seeds
give two independent samplings of the same surface, whose Hausdorff distance
is of the order of the sample spacing.
"""
import sys
import numpy as np

CHUNK = 25_000_000


def torus(rng, n, big=1.0, small=0.3, sigma=1e-4):
    out = np.empty((0, 3))
    while len(out) < n:
        m = int((n - len(out)) * 1.4) + 16
        u = rng.random(m) * 2 * np.pi
        v = rng.random(m) * 2 * np.pi
        keep = rng.random(m) * (big + small) < big + small * np.cos(v)  # area density
        u, v = u[keep], v[keep]
        rr = small + rng.normal(0.0, sigma, len(u))
        ring = big + rr * np.cos(v)
        pts = np.stack([ring * np.cos(u), ring * np.sin(u), rr * np.sin(v)], axis=1)
        out = np.concatenate([out, pts])
    return out[:n]


def sphere(rng, n):
    p = rng.normal(size=(n, 3))
    return p / np.linalg.norm(p, axis=1)[:, None]


def main():
    shape, n, seed, path = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    make = {"torus": torus, "sphere": sphere}[shape]
    rng = np.random.default_rng(seed)
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\nend_header\n" % n).encode())
        done = 0
        while done < n:
            m = min(CHUNK, n - done)
            f.write(make(rng, m).astype("<f4").tobytes())
            done += m


if __name__ == "__main__":
    main()
