#!/usr/bin/python3
"""One reference against many predictions: rthdist-masks REF PRED1 ... PREDn
through the prepared reference against the same rows with --unprepared (the
reference extracted and indexed again for each prediction), same process
shape, same machine.

  masks_prepared_bench.py --cli build/rthdist-masks [--backend cpu]
                          [--predictions 20] [--size 256,256,128]
                          [--convention monai] [--runs 3]

Data (written once as .npy into --work, spacing 0.8 x 0.8 x 2.5 mm): the
reference is an organ-like ellipsoid with low-frequency bumps; prediction i
is a copy shifted by up to 2 voxels, scaled by up to 6 %, with a ragged
boundary (voxels flipped in a 2-voxel band) -- fixed seed.
Time reported per run: the library's time for all predictions, from the JSON
-- the prepared references' prepare_ms plus every row's total (extraction,
engine calls, percentiles; file loading excluded) -- the median of --runs
processes; and, over every row of those runs, the median of the rows'
extraction (extract_ms: the prediction's, and unprepared also the
reference's), of the engine's index stage and of its search. Prints one JSON
object.
"""
import argparse
import json
import os
import statistics
import subprocess

import numpy as np


def volumes(work, n, size, seed=13):
    """The reference and n predictions as .npy files; their paths."""
    os.makedirs(work, exist_ok=True)
    rng = np.random.default_rng(seed)
    nx, ny, nz = size
    i, j, k = np.ogrid[:nx, :ny, :nz]
    centre = np.array([nx / 2, ny / 2, nz / 2])
    radii = np.array([nx * 0.3, ny * 0.25, nz * 0.3])

    def organ(shift, scale, phase):
        x, y, z = (i - centre[0] - shift[0]) / radii[0], (j - centre[1] - shift[1]) / radii[1], \
            (k - centre[2] - shift[2]) / radii[2]
        bump = 0.08 * np.sin(3 * x + phase) * np.cos(2 * y - phase) + 0.05 * np.sin(4 * z + phase)
        return x * x + y * y + z * z <= (scale + bump) ** 2

    paths = [os.path.join(work, "ref.npy")]
    ref = organ((0, 0, 0), 1.0, 0.0)
    np.save(paths[0], ref.astype(np.uint8))
    for n_ in range(n):
        m = organ(rng.uniform(-2, 2, 3), rng.uniform(0.94, 1.06), rng.uniform(-0.3, 0.3))
        band = m ^ organ((0, 0, 0), 1.0 + 4 / radii.min(), 0.0)
        flip = band & (rng.random(m.shape) < 0.02)
        p = (m ^ flip).astype(np.uint8)
        paths.append(os.path.join(work, f"pred{n_:02d}.npy"))
        np.save(paths[-1], p)
    return paths


def library_ms(doc):
    return sum(p["prepare_ms"] for p in doc["prepared"]) + sum(r["timings_ms"]["total"] for r in doc["results"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--predictions", type=int, default=20)
    ap.add_argument("--size", default="256,256,128")
    ap.add_argument("--convention", default="monai")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--work", default="/tmp/rthdist-masks-prepared-bench")
    a = ap.parse_args()
    size = tuple(int(v) for v in a.size.split(","))
    paths = volumes(os.path.join(a.work, "x".join(map(str, size))), a.predictions, size)
    base = [a.cli] + paths + ["--spacing", "0.8,0.8,2.5", "--backend", a.backend, "--json",
                              "--convention", a.convention]
    out = {"backend": a.backend, "convention": a.convention, "size": size, "predictions": a.predictions}
    rows = {}
    for mode, extra in (("prepared", []), ("unprepared", ["--unprepared"])):
        times, stages = [], {"extract": [], "index": [], "search": []}
        for _ in range(a.runs):
            doc = json.loads(subprocess.run(base + extra, check=True, capture_output=True, text=True).stdout)
            times.append(library_ms(doc))
            for r in doc["results"]:
                stages["extract"].append(r["timings_ms"]["extract"])
                stages["index"].append(r["engine_ms"]["index"])
                stages["search"].append(r["engine_ms"]["search"])
        for k, v in stages.items():
            out[f"{mode}_row_{k}_ms"] = statistics.median(v)
            rows[mode] = [{k: v for k, v in r.items() if k not in ("timings_ms", "engine_ms", "extraction")}
                          for r in doc["results"]]
        out[mode + "_ms"] = statistics.median(times)
        out[mode + "_ms_all"] = times
        if mode == "prepared":
            out["reference_points"] = doc["prepared"][0]["points"]
            out["reference_host_bytes"] = doc["prepared"][0]["host_bytes"]
            out["reference_device_bytes"] = doc["prepared"][0]["device_bytes"]
            out["device"] = doc["device"]
    out["same_rows"] = rows["prepared"] == rows["unprepared"]
    out["speedup"] = out["unprepared_ms"] / out["prepared_ms"]
    print(json.dumps(out))


if __name__ == "__main__":
    main()
