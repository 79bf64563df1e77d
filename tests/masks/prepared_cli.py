#!/usr/bin/env python3
"""rthdist-masks REF PRED1 PRED2 ... (one reference, several predictions,
through the prepared reference) against the same comparisons one pair at a
time (rthdist-masks REF PREDi) and against --unprepared: every row's values
equal, rows named by their prediction, label-major per prediction; CSV has
one row per (prediction, label, convention); a prediction on another grid
exits 3 naming both files. Run by ctest (masks_prepared_cli_<backend>)."""
import argparse
import csv
import io
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

SPACING = "0.8,0.7,2.5"
TIMING_KEYS = {"timings_ms", "engine_ms", "repeat_total_ms", "extraction"}


def masks(directory, seed=11):
    """The reference and 11 predictions (shifted, noisy, a second and a third
    label, identical, one voxel, empty) as .npy files; their paths."""
    rng = np.random.default_rng(seed)
    i, j, k = np.mgrid[:32, :30, :12]

    def ellipsoid(c, r):
        return (i - c[0]) ** 2 / r[0] ** 2 + (j - c[1]) ** 2 / r[1] ** 2 + (k - c[2]) ** 2 / r[2] ** 2 <= 1

    ref = ellipsoid((15, 14, 6), (7, 6, 3.5)).astype(np.uint8)
    ref[20:24, 3:6, 2:4] = 2
    paths = [os.path.join(directory, "ref.npy")]
    np.save(paths[0], ref)
    preds = []
    for n in range(7):
        p = ellipsoid(np.array((15, 14, 6)) + rng.uniform(-2, 2, 3), rng.uniform(4, 8, 3) * (1, 1, 0.5))
        p = p.astype(np.int16)
        if n % 2:
            p[rng.integers(0, 32, 25), rng.integers(0, 30, 25), rng.integers(0, 12, 25)] = 2
        if n == 3:
            p[1:3, 1:3, 1:3] = 3  # a label the reference lacks
        preds.append(p)
    preds.append(ref.astype(np.int32))  # identical
    one = np.zeros_like(ref)
    one[3, 25, 9] = 1
    preds += [one, np.zeros_like(ref), (ref == 1).astype(np.bool_)]
    for n, p in enumerate(preds):
        paths.append(os.path.join(directory, f"pred{n:02d}.npy"))
        np.save(paths[-1], p)
    return paths


def run(cli, args, expect=0):
    r = subprocess.run([cli] + args, capture_output=True, text=True)
    if r.returncode != expect:
        sys.exit(f"FAIL: {' '.join(args)} exited {r.returncode}, expected {expect}\n{r.stderr}")
    return r


def values(row):
    """A JSON row without its timings, extraction and prediction name."""
    return {k: v for k, v in row.items() if k not in TIMING_KEYS and k != "b"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--backend", default="cpu")
    a = ap.parse_args()
    common = ["--spacing", SPACING, "--backend", a.backend, "--convention", "all", "--labels", "all",
              "--percentile", "95", "--percentile", "50", "--percentile", "100", "--tolerance", "1.5"]
    failures = 0
    with tempfile.TemporaryDirectory() as d:
        paths = masks(d)
        ref, preds = paths[0], paths[1:]
        many = json.loads(run(a.cli, [ref] + preds + common + ["--json"]).stdout)
        unprepared = json.loads(run(a.cli, [ref] + preds + common + ["--json", "--unprepared"]).stdout)
        assert many["prepared_reference"] is True and unprepared["prepared_reference"] is False
        assert [p["path"] for p in many["predictions"]] == preds, many["predictions"]
        conventions = {p["convention"] for p in many["prepared"]}  # every row of the conventions table
        assert len(many["prepared"]) == 3 * len(conventions), many["prepared"]  # 3 labels, prepared once each
        assert all(p["host_bytes"] > 0 for p in many["prepared"] if p["points"] > 0), many["prepared"]
        rows = many["results"]
        expected = []
        for p in preds:
            pair = json.loads(run(a.cli, [ref, p] + common + ["--json"]).stdout)
            assert "b" not in pair["results"][0] and pair["b"]["path"] == p
            expected += [(p, r) for r in pair["results"]]
        assert len(rows) == len(expected) == len(unprepared["results"]), (len(rows), len(expected))
        for got, (path, want), plain in zip(rows, expected, unprepared["results"]):
            tag = f"{path} label {want['label']} {want['convention']}"
            if got["b"] != path or plain["b"] != path:
                print(f"FAIL {tag}: row names {got['b']!r}")
                failures += 1
            if values(got) != values(want) or values(plain) != values(want):
                print(f"FAIL {tag}: prepared {values(got)}\n  pair {values(want)}")
                failures += 1
        statuses = {r["status"] for r in rows}
        assert {"ok", "b_empty", "a_empty"} <= statuses, statuses

        table = list(csv.DictReader(io.StringIO(run(a.cli, [ref] + preds + common + ["--csv"]).stdout)))
        assert len(table) == len(rows), (len(table), len(rows))
        for t, r in zip(table, rows):
            assert t["b"] == r["b"] and t["label"] == r["label"] and t["convention"] == r["convention"], t
            if r["hd"] is not None:
                assert float(t["hd"]) == r["hd"], (t, r["hd"])

        other = os.path.join(d, "other_grid.npy")
        np.save(other, np.zeros((32, 30, 13), np.uint8))
        bad = run(a.cli, [ref, preds[0], other, "--spacing", SPACING, "--backend", a.backend], expect=3)
        assert ref in bad.stderr and other in bad.stderr, bad.stderr
        run(a.cli, [ref, "--backend", a.backend], expect=2)
    print(f"{len(rows)} rows of {len(preds)} predictions: {failures} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
