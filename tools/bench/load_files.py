#!/usr/bin/python3
"""Writes the loader benchmark's input files (rthdist-load-bench, issue 14).

    /usr/bin/python3 tools/bench/load_files.py [--out /tmp/rthdist-load] [--points 30000000]
        [--text-points 5000000] [--only ply_float,las14_f6]

Synthetic points (fixed seed 14): a 1 km x 1 km LiDAR-like tile at UTM
coordinates for LAS (millimetre integers), a 200 m cube elsewhere. Binary
files hold --points points, text files --text-points. Large files: keep
them out of the repository (default /tmp/rthdist-load).
"""
import argparse
import os
import struct

import numpy as np

SEED = 14


def coords(n, rng, dtype):
    return (rng.random((n, 3)) * 200.0 - 100.0).astype(dtype)


def ply_header(fmt, n, props, extra=""):
    lines = ["ply", f"format {fmt} 1.0", "comment rthdist load bench", f"element vertex {n}"]
    lines += [f"property {t} {name}" for t, name in props]
    return ("\n".join(lines) + "\n" + extra + "end_header\n").encode()


def write_binary_ply(path, n, rng, fields, big_endian=False):
    """fields: (ply type, numpy type, name); x, y, z random, others patterned."""
    order = ">" if big_endian else "<"
    dtype = np.dtype([(name, order + np.dtype(t).str[1:]) for _, t, name in fields])
    with open(path, "wb") as f:
        fmt = "binary_big_endian" if big_endian else "binary_little_endian"
        f.write(ply_header(fmt, n, [(p, name) for p, _, name in fields]))
        step = 1_000_000
        for start in range(0, n, step):
            m = min(step, n - start)
            rec = np.zeros(m, dtype)
            xyz = coords(m, rng, np.float64)
            for axis, name in enumerate("xyz"):
                rec[name] = xyz[:, axis]
            for _, t, name in fields:
                if name not in "xyz":
                    rec[name] = (np.arange(start, start + m) % 251).astype(t)
            f.write(rec.tobytes())


def las_header(minor, fmt, record_length, n, scale, offset):
    size = {2: 227, 4: 375}[minor]
    h = bytearray()
    h += b"LASF" + struct.pack("<HH", 7, 0) + bytes(16) + bytes([1, minor])
    h += b"S" * 32 + b"rthdist load_files.py".ljust(32, b" ")
    h += struct.pack("<HHHIIBHI", 100, 2026, size, size, 0, fmt, record_length,
                     0 if minor >= 4 else n)
    h += struct.pack("<5I", *([0] * 5))
    h += struct.pack("<3d", *scale) + struct.pack("<3d", *offset) + struct.pack("<6d", *([0.0] * 6))
    if minor >= 3:
        h += struct.pack("<Q", 0)
    if minor >= 4:
        h += struct.pack("<QIQ", 0, 0, n) + struct.pack("<15Q", *([0] * 15))
    assert len(h) == size, len(h)
    return bytes(h)


def write_las(path, n, rng, minor, fmt):
    if fmt == 1:
        dtype = np.dtype([("xyz", "<i4", 3), ("intensity", "<u2"), ("returns", "u1"),
                          ("cls", "u1"), ("angle", "i1"), ("user", "u1"), ("source", "<u2"),
                          ("gps", "<f8")])
    else:  # 6
        dtype = np.dtype([("xyz", "<i4", 3), ("intensity", "<u2"), ("returns", "u1"), ("flags", "u1"),
                          ("cls", "u1"), ("user", "u1"), ("angle", "<i2"), ("source", "<u2"),
                          ("gps", "<f8")])
    scale, offset = (0.001, 0.001, 0.001), (500000.0, 5400000.0, 0.0)
    with open(path, "wb") as f:
        f.write(las_header(minor, fmt, dtype.itemsize, n, scale, offset))
        step = 1_000_000
        for start in range(0, n, step):
            m = min(step, n - start)
            rec = np.zeros(m, dtype)
            rec["xyz"] = (rng.random((m, 3)) * (1e6, 1e6, 1e5)).astype(np.int32)
            rec["cls"] = rng.choice(np.array([1, 2, 6], np.uint8), m)
            rec["gps"] = np.arange(start, start + m) * 1e-5
            f.write(rec.tobytes())


def write_binary_pcd(path, n, rng):
    dtype = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
    with open(path, "wb") as f:
        f.write((f"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\n"
                 f"COUNT 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\n"
                 f"DATA binary\n").encode())
        step = 1_000_000
        for start in range(0, n, step):
            m = min(step, n - start)
            rec = np.zeros(m, dtype)
            xyz = coords(m, rng, np.float32)
            rec["x"], rec["y"], rec["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
            rec["rgb"] = np.arange(start, start + m, dtype=np.uint32)
            f.write(rec.tobytes())


def text_lines(n, rng, prefix="", suffix=""):
    """Yields blocks of lines 'prefix x y z suffix' with 6 decimals."""
    step = 500_000
    for start in range(0, n, step):
        m = min(step, n - start)
        xyz = coords(m, rng, np.float64)
        yield "".join(f"{prefix}{x:.6f} {y:.6f} {z:.6f}{suffix}\n" for x, y, z in xyz.tolist())


def write_text(path, n, rng, head="", prefix="", suffix="", tail=""):
    with open(path, "w") as f:
        f.write(head)
        for block in text_lines(n, rng, prefix, suffix):
            f.write(block)
        f.write(tail)


FLOAT_XYZ = [("float", "f4", "x"), ("float", "f4", "y"), ("float", "f4", "z")]
DOUBLE_XYZ = [("double", "f8", "x"), ("double", "f8", "y"), ("double", "f8", "z")]
EXTRA = FLOAT_XYZ + [("float", "f4", "nx"), ("float", "f4", "ny"), ("float", "f4", "nz"),
                     ("uchar", "u1", "red"), ("uchar", "u1", "green"), ("uchar", "u1", "blue"),
                     ("uchar", "u1", "alpha")]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="/tmp/rthdist-load")
    ap.add_argument("--points", type=int, default=30_000_000)
    ap.add_argument("--text-points", type=int, default=5_000_000)
    ap.add_argument("--only", default="", help="comma-separated names (default: all)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    n, t = a.points, a.text_points
    jobs = {
        "ply_float.ply": lambda p, r: write_binary_ply(p, n, r, FLOAT_XYZ),
        "ply_double.ply": lambda p, r: write_binary_ply(p, n, r, DOUBLE_XYZ),
        "ply_float_extra.ply": lambda p, r: write_binary_ply(p, n, r, EXTRA),
        "ply_double_be.ply": lambda p, r: write_binary_ply(p, n, r, DOUBLE_XYZ, big_endian=True),
        "las12_f1.las": lambda p, r: write_las(p, n, r, 2, 1),
        "las14_f6.las": lambda p, r: write_las(p, n, r, 4, 6),
        "pcd_binary.pcd": lambda p, r: write_binary_pcd(p, n, r),
        "text.xyz": lambda p, r: write_text(p, t, r),
        "ascii.ply": lambda p, r: write_text(p, t, r, ply_header("ascii", t, [("double", c) for c in "xyz"]).decode()),
        "text.obj": lambda p, r: write_text(p, t, r, "# rthdist\n", "v "),
        "text.off": lambda p, r: write_text(p, t, r, f"OFF\n{t} 0 0\n"),
        "ascii.pcd": lambda p, r: write_text(
            p, t, r, f"VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {t}\nHEIGHT 1\n"
            f"POINTS {t}\nDATA ascii\n"),
    }
    only = [s for s in a.only.split(",") if s]
    for name, write in jobs.items():
        if only and name.split(".")[0] not in only:
            continue
        path = os.path.join(a.out, name)
        write(path, np.random.default_rng(SEED))
        print(f"{path}: {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    main()
