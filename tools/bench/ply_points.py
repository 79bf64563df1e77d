"""Minimal PLY reading/writing for the benchmark scripts (numpy only).

Reads ascii or binary PLY, optionally gzipped, returning float32 vertices and,
when asked, the faces of a triangle mesh. Only what the benchmark data needs;
the library's own loaders are in src/io.
"""
import gzip
import numpy as np

_TYPES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4",
          "float": "f4", "double": "f8", "int8": "i1", "uint8": "u1", "int16": "i2", "uint16": "u2",
          "int32": "i4", "uint32": "u4", "float32": "f4", "float64": "f8"}


def _open(path):
    return gzip.open(path, "rb") if str(path).endswith(".gz") else open(path, "rb")


def read_ply(path, want_faces=False):
    with _open(path) as f:
        data = f.read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii", "replace").splitlines()
    fmt = None
    elements = []
    for line in header:
        t = line.split()
        if not t:
            continue
        if t[0] == "format":
            fmt = t[1]
        elif t[0] == "element":
            elements.append([t[1], int(t[2]), []])
        elif t[0] == "property":
            elements[-1][2].append(t[1:])
    body = data[end:]
    verts = faces = None
    if fmt == "ascii":
        lines = body.split(b"\n")
        pos = 0
        for name, count, props in elements:
            chunk = lines[pos:pos + count]
            pos += count
            if name == "vertex":
                names = [p[-1] for p in props]
                cols = [names.index(c) for c in "xyz"]
                arr = np.array(b" ".join(chunk).split(), dtype=np.float64).reshape(count, len(props))
                verts = arr[:, cols].astype(np.float32)
            elif name == "face" and want_faces:
                arr = np.array(b" ".join(chunk).split(), dtype=np.int64)
                if arr.size == count * 4:
                    faces = arr.reshape(count, 4)[:, 1:]
                else:  # mixed polygon sizes: triangulate fans
                    tris, i = [], 0
                    while i < arr.size:
                        k = arr[i]
                        poly = arr[i + 1:i + 1 + k]
                        tris += [(poly[0], poly[j], poly[j + 1]) for j in range(1, k - 1)]
                        i += 1 + k
                    faces = np.array(tris, dtype=np.int64)
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        off = 0
        for name, count, props in elements:
            if any(p[0] == "list" for p in props):
                if name == "face" and want_faces and len(props) == 1:
                    ct, it = props[0][1], props[0][2]
                    dt = np.dtype([("n", order + _TYPES[ct]), ("i", order + _TYPES[it], 3)])
                    arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
                    faces = arr["i"].astype(np.int64)
                    off += dt.itemsize * count
                    continue
                break  # cannot skip variable-size lists without parsing; vertices come first in our data
            dt = np.dtype([(p[1], order + _TYPES[p[0]]) for p in props])
            arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
            off += dt.itemsize * count
            if name == "vertex":
                verts = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(np.float32)
    if want_faces:
        return verts, faces
    return verts


def write_ply(path, points):
    points = np.ascontiguousarray(points, dtype="<f4")
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\nend_header\n" % len(points)).encode())
        f.write(points.tobytes())
