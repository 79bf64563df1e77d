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


def _small_pair(tmp_path):
    """Two seeded float64 sets as .xyz files (decimal text loads as float64)."""
    rng = np.random.default_rng(20250612)
    paths = []
    for name, n in (("a", 300), ("b", 200)):
        path = tmp_path / f"{name}.xyz"
        np.savetxt(path, rng.random((n, 3)), fmt="%.17g")
        paths.append(str(path))
    return paths


def _cli_binary():
    cli = os.environ.get("RTHDIST_CLI", os.path.join(REPO, "build", "rthdist"))
    return cli if os.path.exists(cli) else None


def _no_constants(name):
    raise AssertionError(f"non-standard JSON token {name}")


@pytest.mark.parametrize(
    "option, percentiles, bins, hist_range",
    [
        (["--percentile", "12.5"], [12.5, 95.0], 20, None),
        (["--histogram-bins", "7"], [50.0, 90.0, 95.0, 99.0], 7, None),
        (["--range", "0", "0.25"], [50.0, 90.0, 95.0, 99.0], 20, (0.0, 0.25)),
    ],
)
def test_module_per_point_options_imply_per_point(tmp_path, option, percentiles, bins, hist_range):
    """--percentile, --histogram-bins and --range turn --per-point on, as in the CLI (README "Per-point
    distances"); python -m rthdist printed no per_point block and dropped the option."""
    a, b = _small_pair(tmp_path)
    p = run_module("--json", "--backend", "cpu", *option, a, b)
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout)["per_point"]
    r = rthdist.hausdorff(rthdist.load(a), rthdist.load(b), backend="cpu", per_point=True)
    want = r.stats(percentiles=percentiles, bins=bins, range=hist_range)
    assert got["percentiles"] == want["percentiles"]
    assert got["histogram"]["lo"] == want["histogram"]["lo"] and got["histogram"]["hi"] == want["histogram"]["hi"]
    assert got["histogram"]["a_to_b"] == want["histogram"]["a_to_b"].tolist()
    text = run_module("--backend", "cpu", *option, a, b)
    assert text.returncode == 0 and "HD95" in text.stdout
    cli = _cli_binary()
    if cli is not None:
        ref = json.loads(subprocess.run([cli, "--json", "--quiet", "--backend", "cpu", *option, a, b],
                                        capture_output=True, text=True, check=True).stdout)["per_point"]
        for block in ("a_to_b", "b_to_a", "pooled"):
            assert got[block]["percentiles"] == ref[block]["percentiles"], block
        assert got["histogram"]["a_to_b"] == ref["histogram"]["a_to_b"]
        assert got["histogram"]["pooled"] == ref["histogram"]["pooled"]


@pytest.mark.parametrize(
    "lo, hi", [("0", "inf"), ("-1", "1"), ("0.5", "0.5"), ("0.5", "0.1"), ("nan", "1"), ("0", "1e400")]
)
def test_module_range_is_checked_as_the_cli_does(tmp_path, lo, hi):
    """--range MIN MAX: finite, 0 <= MIN < MAX, else exit 2 (usage) before any file is read, as the CLI;
    python -m rthdist ran MIN < 0 or MAX = inf (exit 0, its JSON holding Infinity and NaN) and gave an
    empty or NaN range exit 3."""
    a, b = _small_pair(tmp_path)
    for extra in (["--per-point"], []):
        p = run_module("--json", "--backend", "cpu", *extra, "--range", lo, hi, a, b)
        assert p.returncode == 2, (p.returncode, p.stdout[:200], p.stderr)
        assert "option '--range' expects finite numbers 0 <= MIN < MAX" in p.stderr and p.stdout == ""
    assert run_module("--range", lo, hi, a, "/nonexistent.ply").returncode == 2
    cli = _cli_binary()
    if cli is not None:
        ref = subprocess.run([cli, "--json", "--quiet", "--per-point", "--range", lo, hi, a, b],
                             capture_output=True, text=True)
        assert ref.returncode == 2, ref.stderr


@pytest.mark.parametrize("option, value", [("--threads", "1_0"), ("--threads", "+1"), ("--threads", " 1"),
                                           ("--percentile", "+5"), ("--percentile", "5_0"),
                                           ("--las-classes", "2,+6"), ("--radius-growth", "2 ")])
def test_module_reads_numbers_as_the_cli_does(tmp_path, option, value):
    """Numbers as the CLI reads them (std::from_chars: no '+', no spaces, no '_'): exit 2; Python's
    int() and float() took '1_0', '+1' and ' 1'."""
    a, b = _small_pair(tmp_path)
    p = run_module("--json", "--backend", "cpu", option, value, a, b)
    assert p.returncode == 2, (p.returncode, p.stdout[:200], p.stderr)
    cli = _cli_binary()
    if cli is not None:
        ref = subprocess.run([cli, "--json", "--quiet", option, value, a, b], capture_output=True, text=True)
        assert ref.returncode == 2, ref.stderr


def test_module_json_is_strict(tmp_path):
    """python -m rthdist writes standard JSON: a non-finite number is null, as in the CLI's JSON
    (json.dumps wrote the tokens NaN and Infinity, which strict parsers refuse)."""
    from rthdist.__main__ import _json_text

    value = {"nan": float("nan"), "list": [np.float64("inf"), 1.5, np.float32(0.5)],
             "array": np.array([-np.inf, 2.0]), "count": np.uint64(3), "name": "x", "none": None}
    assert json.loads(_json_text(value), parse_constant=_no_constants) == {
        "nan": None, "list": [None, 1.5, 0.5], "array": [None, 2.0], "count": 3, "name": "x", "none": None}
    a, b = _small_pair(tmp_path)
    p = run_module("--json", "--backend", "cpu", "--per-point", a, b)
    assert p.returncode == 0, p.stderr
    json.loads(p.stdout, parse_constant=_no_constants)
