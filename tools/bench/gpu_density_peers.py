#!/usr/bin/env python3
"""CuPy's exact KDTree (cupyx.scipy.spatial.KDTree, float64, both directions,
tree builds included, inputs already on the GPU) on the density rows of
docs/bench/density, on the device machine. Prints one JSON object per row.

  gpu_density_peers.py WORK ROW [ROW ...] [--runs N]
WORK holds ROW_a.ply / ROW_b.ply (tools/bench/density.py --work layout).
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gpu_peers import cupy_kdtree, time_it  # noqa: E402
from ply_points import read_ply  # noqa: E402


def main():
    args = sys.argv[1:]
    runs = 5
    if "--runs" in args:
        i = args.index("--runs")
        runs = int(args[i + 1])
        del args[i:i + 2]
    work, rows = args[0], args[1:]
    for row in rows:
        a = read_ply(os.path.join(work, row + "_a.ply"))
        b = read_ply(os.path.join(work, row + "_b.ply"))
        tools = [("cupy_kdtree", a, b)]
        # CuPy's KDTree gave wrong maxima on sets with duplicate points
        # (docs/bench/h100): the deduplicated sets (same H) are timed too.
        ua, ub = np.unique(a, axis=0), np.unique(b, axis=0)
        if len(ua) < len(a) or len(ub) < len(b):
            tools.append(("cupy_kdtree_dedup", ua, ub))
        for name, x, y in tools:
            try:
                sec, h = time_it(cupy_kdtree(x, y), runs)
                out = {"case": row, "tool": name, "median_s": sec, "hausdorff": h}
            except Exception as e:  # report, do not drop the row
                out = {"case": row, "tool": name, "error": str(e)[:200]}
            print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
