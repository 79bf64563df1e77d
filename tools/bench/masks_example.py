#!/usr/bin/python3
"""The README's disagreement example: one pair of masks, every convention.

  masks_example.py --cli build/rthdist-masks [--out docs/bench/masks/example.md]

Reference: an ellipsoid (radii 12 x 10 x 15 mm) on a 64 x 64 x 24 grid of
0.8 x 0.8 x 2.5 mm voxels. Prediction: the same ellipsoid shifted by one
voxel in x, plus a spurious island (6 x 6 x 3 voxels) about 20 mm away — the kind of
false positive a segmentation network makes. Writes both masks as NIfTI next
to the table (example_ref.nii.gz, example_pred.nii.gz) and a Markdown table
of HD, HD95, ASSD, MSD and surface Dice at 1 mm per convention.
"""
import argparse
import json
import os
import subprocess

import nibabel as nib
import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--out", default="docs/bench/masks/example.md")
    args = ap.parse_args()
    shape, sp = (64, 64, 24), (0.8, 0.8, 2.5)
    g = np.indices(shape).astype(float)
    def ellipsoid(c):
        return sum(((g[i] - c[i]) * sp[i] / r) ** 2 for i, r in enumerate((12.0, 10.0, 15.0))) <= 1.0
    ref = ellipsoid((31.5, 31.5, 11.5))
    pred = ellipsoid((32.5, 31.5, 11.5))
    pred[54:60, 49:55, 10:13] = True
    out_dir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(out_dir, exist_ok=True)
    aff = np.diag(list(sp) + [1.0])
    pa, pb = os.path.join(out_dir, "example_pred.nii.gz"), os.path.join(out_dir, "example_ref.nii.gz")
    nib.save(nib.Nifti1Image(pred.astype(np.uint8), aff), pa)
    nib.save(nib.Nifti1Image(ref.astype(np.uint8), aff), pb)
    p = subprocess.run([args.cli, pa, pb, "--json", "--convention", "all", "--backend", "cpu", "--percentile", "95",
                        "--tolerance", "1"], capture_output=True, text=True, check=True)
    res = json.loads(p.stdout)["results"]
    def f(v):
        return "—" if v is None else f"{v:.3f}"
    lines = ["| convention | points pred / ref | HD (mm) | HD95 (mm) | ASSD (mm) | MSD (mm) | surface Dice @1 mm |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in res:
        hp = r["hd_percentile"][0]["value"] if r["hd_percentile"] else None
        lines.append(f"| {r['convention']} | {r['a_to_b']['points']} / {r['b_to_a']['points']} | {f(r['hd'])} | {f(hp)} | "
                     f"{f(r['assd'])} | {f(r['msd'])} | {f(r['surface_dice'])} |")
    text = "\n".join(lines) + "\n"
    with open(args.out, "w") as fh:
        fh.write(text)
    print(text)


if __name__ == "__main__":
    main()
