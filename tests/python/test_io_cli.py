"""rthdist.load and python3 -m rthdist against the CLI's contract."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import rthdist
from conftest import check_result

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUNNY = os.path.join(REPO, "data", "bunny.ply")
BUNNY2 = os.path.join(REPO, "data", "bunny_res2.ply")


def test_load(tmp_path):
    a = rthdist.load(BUNNY)
    assert a.shape == (35947, 3) and a.dtype == np.float32 and a.flags.c_contiguous
    xyz = tmp_path / "p.xyz"
    xyz.write_text("0 0 0\n1 2 3.5\n")
    p = rthdist.load(xyz)  # os.PathLike; decimal text is read as float64
    assert p.dtype == np.float64
    np.testing.assert_array_equal(p, [[0, 0, 0], [1, 2, 3.5]])
    with pytest.raises(FileNotFoundError):
        rthdist.load(tmp_path / "missing.ply")
    with pytest.raises(IsADirectoryError):
        rthdist.load(tmp_path)
    bad = tmp_path / "bad.ply"
    bad.write_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n")
    with pytest.raises(ValueError, match="bad.ply"):
        rthdist.load(bad)


def test_loaded_bunny_exact(backend):
    a, b = rthdist.load(BUNNY), rthdist.load(BUNNY2)
    check_result(rthdist.hausdorff(a, b, backend=backend), a, b)


def run_module(*args):
    return subprocess.run([sys.executable, "-m", "rthdist", *args], capture_output=True, text=True)


def test_module_cli():
    p = run_module("--json", "--backend", "cpu", "--per-point", BUNNY, BUNNY2)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    a, b = rthdist.load(BUNNY), rthdist.load(BUNNY2)
    r = rthdist.hausdorff(a, b, backend="cpu", per_point=True)
    assert out["hausdorff"] == r.distance and out["backend"] == "cpu"
    assert out["a_to_b"]["a_index"] == r.a_to_b.query_index
    assert out["per_point"]["hd95"] if "hd95" in out["per_point"] else True
    assert out["points"] == {"a": 35947, "b": 8171}
    text = run_module(BUNNY, BUNNY2)
    assert text.returncode == 0 and "H(A,B) = " in text.stdout
    assert run_module("--bits", "9", BUNNY, BUNNY2).returncode == 2
    assert run_module(BUNNY).returncode == 2
    assert run_module(BUNNY, "/nonexistent.ply").returncode == 3
    assert run_module("--backend", "ray-query", "--device", "1000", BUNNY, BUNNY2).returncode == 4
    assert run_module("--list-devices").returncode == 0


def test_module_matches_the_cli_binary():
    cli = os.environ.get("RTHDIST_CLI", os.path.join(REPO, "build", "rthdist"))
    if not os.path.exists(cli):
        pytest.skip(f"no CLI binary at {cli} (tools/test.sh builds it first)")
    args = ["--json", "--backend", "cpu", "--per-point", BUNNY, BUNNY2]
    want = json.loads(subprocess.run([cli, *args], capture_output=True, text=True, check=True).stdout)
    got = json.loads(run_module(*args).stdout)
    for key in ("hausdorff", "a_to_b", "b_to_a", "points", "precision", "origin", "counters"):
        assert got[key] == want[key], key
    ws, gs = want["per_point"], got["per_point"]
    assert gs["diagonal"] == ws["diagonal"]
    for block in ("a_to_b", "b_to_a", "pooled"):
        for key in ("count", "min", "max", "mean", "rms", "percentiles"):
            assert gs[block][key] == ws[block][key], (block, key)
    assert gs["histogram"]["a_to_b"] == ws["histogram"]["a_to_b"]
    r = rthdist.hausdorff(rthdist.load(BUNNY), rthdist.load(BUNNY2), backend="cpu", per_point=True)
    assert r.hd95 == ws["hd95"]["max"]
    assert r.percentile(95, "pooled") == ws["hd95"]["pooled"]
    assert r.mean == ws["pooled"]["mean"] and r.rms == ws["pooled"]["rms"]
