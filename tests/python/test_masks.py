"""rthdist.compare_masks / MaskEngine / MaskVolume against the rthdist-masks CLI.

The CLI (tools/cli/masks, built by tools/test.sh before this suite) reads the
same volumes from .npy and .nii files written here; every row of the Python
result must equal its `--json` row key for key (timings aside). Anisotropic
spacing and single voxels are checked against the definition directly.
"""

import json
import math
import os
import subprocess

import numpy as np
import pytest

import rthdist
from conftest import SEED

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TIMING_KEYS = ("timings_ms", "engine_ms")


def masks_cli():
    """The rthdist-masks binary beside RTHDIST_CLI (tools/test.sh), else build/."""
    cli = os.environ.get("RTHDIST_MASKS_CLI")
    if cli is None:
        point_cli = os.environ.get("RTHDIST_CLI", os.path.join(REPO, "build", "rthdist"))
        cli = os.path.join(os.path.dirname(point_cli), "rthdist-masks")
    if not os.path.exists(cli):
        pytest.skip(f"no rthdist-masks binary at {cli} (tools/test.sh builds it first)")
    return cli


def cli_rows(*args):
    p = subprocess.run([masks_cli(), "--json", *args], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def without_timings(row):
    return {k: v for k, v in row.items() if k not in TIMING_KEYS}


def as_list(r):
    return r if isinstance(r, list) else [r]


def assert_rows_equal(results, want_rows):
    got = [without_timings(r.to_dict()) for r in as_list(results)]
    want = [without_timings(r) for r in want_rows]
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert g == w, (g["label"], g["convention"])


def no_nan(x):
    """No NaN anywhere in a result dict (empty masks are a status, numbers None)."""
    if isinstance(x, dict):
        return all(no_nan(v) for v in x.values())
    if isinstance(x, list):
        return all(no_nan(v) for v in x)
    return not (isinstance(x, float) and math.isnan(x))


def blobs(shape, rng, labels=(1, 2)):
    """A label volume: an ellipsoid per label, randomly placed and sized, plus noise voxels."""
    v = np.zeros(shape, dtype=np.int32)
    idx = np.indices(shape).astype(np.float64)
    for label in labels:
        centre = [rng.uniform(0.3, 0.7) * n for n in shape]
        radii = [rng.uniform(0.15, 0.3) * n for n in shape]
        inside = sum(((idx[d] - centre[d]) / radii[d]) ** 2 for d in range(3)) <= 1.0
        v[inside] = label
    noise = rng.random(shape) < 0.01
    v[noise] = rng.choice(labels, size=int(noise.sum()))
    return v


@pytest.fixture
def pair(rng):
    a = blobs((22, 18, 10), rng)
    b = blobs((22, 18, 10), rng)
    return a, b


SPACING = (0.8, 0.7, 2.5)


def test_arrays_match_the_cli_in_every_convention(backend, tmp_path, pair):
    a, b = pair
    a16 = a.astype(np.uint16)  # C order, uint16
    b64 = np.asfortranarray(b.astype(np.float64))  # Fortran order, integral floats
    np.save(tmp_path / "a.npy", a16)
    np.save(tmp_path / "b.npy", b64)
    want = cli_rows(str(tmp_path / "a.npy"), str(tmp_path / "b.npy"), "--spacing", ",".join(map(str, SPACING)),
                    "--convention", "all", "--labels", "all", "--percentile", "50", "--percentile", "95",
                    "--percentile", "100", "--tolerance", "1.5", "--backend", backend)
    got = rthdist.compare_masks(a16, b64, spacing=SPACING, convention="all", labels="all",
                                percentiles=(50, 95, 100), tolerance=1.5, backend=backend)
    assert len(got) == 2 * len(rthdist.CONVENTIONS)
    assert [(r.label, r.convention) for r in got] == [(l, c) for l in (1, 2) for c in rthdist.CONVENTIONS]
    assert_rows_equal(got, want["results"])
    for r in got:
        assert r.backend == want["backend"] and r.device == want["device"]
        assert r.ok and r.hd is not None and r.a_to_b.points > 0
    # The whole foreground (default) and connectivity 26.
    want = cli_rows(str(tmp_path / "a.npy"), str(tmp_path / "b.npy"), "--spacing", ",".join(map(str, SPACING)),
                    "--connectivity", "26", "--convention", "rthdist", "--convention", "medpy",
                    "--backend", backend)
    got = rthdist.compare_masks(a16, b64, spacing=SPACING, connectivity=26, convention=["rthdist", "medpy"],
                                backend=backend)
    assert [r.label for r in got] == [None, None]
    assert_rows_equal(got, want["results"])


def oblique_affine():
    """A rotation about an oblique axis, anisotropic voxels and an offset (sform)."""
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    angle = 0.4
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rot = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    m = np.eye(4)
    m[:3, :3] = rot @ np.diag([0.9, 1.1, 2.0])
    m[:3, 3] = [-40.0, 12.5, 7.25]
    return m.astype(np.float32).astype(np.float64)  # what the file's float32 sform holds, exactly


def test_nibabel_images_match_the_cli(backend, tmp_path, pair):
    nib = pytest.importorskip("nibabel")
    a, b = pair
    affine = oblique_affine()
    img_a = nib.Nifti1Image(a.astype(np.uint8), affine)
    img_b = nib.Nifti1Image(b.astype(np.int16), affine)
    nib.save(img_a, tmp_path / "a.nii.gz")
    nib.save(img_b, tmp_path / "b.nii")
    want = cli_rows(str(tmp_path / "a.nii.gz"), str(tmp_path / "b.nii"), "--convention", "all", "--labels",
                    "all", "--backend", backend)
    assert want["a"]["transform"] == "sform"
    in_memory = rthdist.compare_masks(img_a, img_b, convention="all", labels="all", backend=backend)
    assert_rows_equal(in_memory, want["results"])
    loaded_a, loaded_b = nib.load(tmp_path / "a.nii.gz"), nib.load(tmp_path / "b.nii")
    assert_rows_equal(rthdist.compare_masks(loaded_a, loaded_b, convention="all", labels="all", backend=backend),
                      want["results"])
    va = rthdist.MaskVolume(loaded_a)
    assert va.transform == "sform" and va.name.endswith("a.nii.gz")
    np.testing.assert_allclose(va.affine[:3], np.array(want["a"]["affine"]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(va.spacing, want["a"]["spacing"], rtol=1e-15)
    # An array beside an image takes the image's affine.
    assert_rows_equal(rthdist.compare_masks(a, loaded_b, convention="all", labels="all", backend=backend),
                      want["results"])
    # rthdist's world geometry: witness points are the affine applied to the witness voxels.
    r = rthdist.compare_masks(img_a, img_b, label=1, backend=backend)
    for d in (r.a_to_b, r.b_to_a):
        np.testing.assert_allclose(d.point, (affine @ np.array([*d.voxel, 1.0]))[:3], atol=1e-9)
        np.testing.assert_allclose(d.nearest_point, (affine @ np.array([*d.nearest_voxel, 1.0]))[:3], atol=1e-9)
        assert abs(np.linalg.norm(d.point - d.nearest_point) - d.hd) <= 1e-9


def test_a_4d_image_with_one_volume(tmp_path, pair):
    nib = pytest.importorskip("nibabel")
    a, b = pair
    img4 = nib.Nifti1Image(a[..., None].astype(np.uint8), np.diag([*SPACING, 1.0]))
    img3 = nib.Nifti1Image(b.astype(np.uint8), np.diag([*SPACING, 1.0]))
    r = rthdist.compare_masks(img4, img3, backend="cpu")
    want = rthdist.compare_masks(a, b, spacing=SPACING, backend="cpu")
    assert without_timings(r.to_dict()) == without_timings(want.to_dict())
    two = nib.Nifti1Image(np.stack([a, a], axis=-1).astype(np.uint8), np.eye(4))
    with pytest.raises(ValueError, match="more than one volume"):
        rthdist.compare_masks(two, img3, backend="cpu")


def test_anisotropic_spacing_single_voxels(backend):
    """One voxel each: every convention's HD is the spaced distance of the two voxels."""
    rng = np.random.default_rng(SEED)
    shape = (9, 7, 5)
    for _ in range(3):
        a = np.zeros(shape, dtype=bool)
        b = np.zeros(shape, dtype=bool)
        va = tuple(int(rng.integers(0, n)) for n in shape)
        vb = tuple(int(rng.integers(0, n)) for n in shape)
        a[va] = True
        b[vb] = True
        spacing = tuple(float(s) for s in rng.uniform(0.3, 3.0, size=3))
        truth = math.sqrt(sum(((i - j) * s) ** 2 for i, j, s in zip(va, vb, spacing)))
        for r in rthdist.compare_masks(a, b, spacing=spacing, convention=["rthdist", "monai", "itk", "medpy"],
                                       backend=backend):
            assert r.status == "ok"
            assert r.hd == pytest.approx(truth, rel=1e-12, abs=1e-12), r.convention
            assert r.a_to_b.voxel == va and r.a_to_b.nearest_voxel == vb
            assert r.b_to_a.voxel == vb and r.b_to_a.nearest_voxel == va
            np.testing.assert_allclose(r.a_to_b.point, np.array(va) * spacing, rtol=1e-15)
        # The same grid given as an affine (4 x 4 or 3 x 4) is the same comparison.
        m = np.diag([*spacing, 1.0])
        by_spacing = rthdist.compare_masks(a, b, spacing=spacing, backend=backend).to_dict()
        for affine in (m, m[:3]):
            by_affine = rthdist.compare_masks(a, b, affine=affine, backend=backend).to_dict()
            assert without_timings(by_affine) == without_timings(by_spacing)


def test_spacing_scales_the_distances(pair):
    a, b = pair
    unit = rthdist.compare_masks(a, b, convention="monai", backend="cpu")
    scaled = rthdist.compare_masks(a, b, convention="monai", spacing=(2.0, 2.0, 2.0), backend="cpu")
    assert scaled.hd == pytest.approx(2 * unit.hd, rel=1e-12)
    assert scaled.hd95 == pytest.approx(2 * unit.hd95, rel=1e-12)
    assert scaled.assd == pytest.approx(2 * unit.assd, rel=1e-12)
    stretched = rthdist.compare_masks(a, b, convention="monai", spacing=(1.0, 1.0, 3.0), backend="cpu")
    assert stretched.hd != unit.hd


@pytest.mark.parametrize("which", ["a_empty", "b_empty", "both_empty"])
def test_empty_masks_are_a_status(which, tmp_path, pair):
    a, b = pair
    if which in ("a_empty", "both_empty"):
        a = np.zeros_like(a)
    if which in ("b_empty", "both_empty"):
        b = np.zeros_like(b)
    np.save(tmp_path / "a.npy", a)
    np.save(tmp_path / "b.npy", b)
    want = cli_rows(str(tmp_path / "a.npy"), str(tmp_path / "b.npy"), "--convention", "all", "--backend", "cpu")
    got = rthdist.compare_masks(a, b, convention="all", backend="cpu")
    assert_rows_equal(got, want["results"])
    for r in got:
        d = r.to_dict()
        assert r.status == which and not r.ok
        assert no_nan(d), r.convention
        json.dumps(d, allow_nan=False)
        assert r.hd is None and r.assd is None
        if r.convention != "itk":  # itk has no percentile
            assert r.hd95 is None
        assert r.a_to_b.hd is None and r.a_to_b.voxel is None
        v = r.convention_value
        assert v["hd"] and v["assd"] and v["surface_dice"] and v["a_to_b"]["mean"] and v["b_to_a"]["mean"]
        assert len(v["hd_percentile"]) == (0 if r.convention == "itk" else 1)
        # Both sides' points, also the non-empty one.
        assert (r.a_to_b.points > 0) == (which == "b_empty") and (r.b_to_a.points > 0) == (which == "a_empty")
        assert which in repr(r)
    monai = got[rthdist.CONVENTIONS.index("monai")]
    assert monai.convention_value["hd"] == ("nan" if which == "both_empty" else "inf")
    one = which != "both_empty"
    assert monai.convention_value["hd_percentile"] == [{"p": 95.0, "value": "nan"}]
    assert monai.convention_value["surface_dice"] == ("0" if one else "nan")
    assert monai.convention_value["a_to_b"]["hd"] == ("inf" if one else "nan")
    deepmind = got[rthdist.CONVENTIONS.index("deepmind")]
    assert deepmind.convention_value["a_to_b"]["surface_overlap"] == ("0" if which == "b_empty" else "nan")


def test_spacing_below_the_limit_is_a_value_error(backend):
    """Issue 36: a spacing below what the engine computes exactly gave wrong
    values silently (1e-40 mm along x: H 3e-40 for 2e-40); below 1e-30 mm it
    is a ValueError naming the axis and the limit, just above it exact."""
    a = np.zeros((8, 8, 8), np.uint8)
    a[2:4, 2:4, 2:4] = 1
    b = np.zeros_like(a)
    b[3:6, 2:4, 2:4] = 1
    limit = r"below the smallest spacing rthdist computes exactly, 1e-30 mm"
    for spacing in [(1e-40, 1.0, 1.0), (1.0, 1e-40, 1.0)]:
        with pytest.raises(ValueError, match=limit):
            rthdist.compare_masks(a, b, spacing=spacing, backend=backend)
    with pytest.raises(ValueError, match=limit):
        rthdist.compare_masks(a, b, affine=np.diag([1e-40, 1.0, 1.0, 1.0]), backend=backend)
    exact = rthdist.compare_masks(a, b, spacing=(1e-29, 1.0, 1.0), backend=backend)
    assert exact.hd == pytest.approx(2e-29, rel=1e-12)


def test_bad_inputs_raise_value_errors(pair):
    a, b = pair
    with pytest.raises(ValueError, match="different grids.*22x18x10"):
        rthdist.compare_masks(a, b[:, :, :9], backend="cpu")
    with pytest.raises(ValueError, match="different grids: affine entry"):
        rthdist.compare_masks(rthdist.MaskVolume(a, spacing=(1, 1, 1)), rthdist.MaskVolume(b, spacing=(1, 1, 2)),
                              backend="cpu")
    with pytest.raises(ValueError, match="3-D label array"):
        rthdist.compare_masks(a[:, :, 0], b[:, :, 0], backend="cpu")
    f = a.astype(np.float32)
    f[3, 4, 5] = 0.5
    with pytest.raises(ValueError, match=r"^a: label value 0.5 .* not an int32 integer"):
        rthdist.compare_masks(f, b, backend="cpu")
    big = a.astype(np.uint64)
    big[0, 0, 0] = 2**40
    with pytest.raises(ValueError, match=r"^b: label 1099511627776 .* does not fit int32"):
        rthdist.compare_masks(a, big, backend="cpu")
    with pytest.raises(ValueError, match="not a label type"):
        rthdist.compare_masks(a.astype(np.complex64), b, backend="cpu")
    with pytest.raises(ValueError, match="unknown convention 'nnunet'"):
        rthdist.compare_masks(a, b, convention="nnunet", backend="cpu")
    with pytest.raises(ValueError, match="unknown backend"):
        rthdist.compare_masks(a, b, backend="nope")
    with pytest.raises(ValueError, match="percentile"):
        rthdist.compare_masks(a, b, percentiles=(101,), backend="cpu")
    with pytest.raises(ValueError, match="connectivity"):
        rthdist.compare_masks(a, b, connectivity=8, backend="cpu")
    with pytest.raises(ValueError, match="tolerance"):
        rthdist.compare_masks(a, b, tolerance=-1, backend="cpu")
    with pytest.raises(ValueError, match="spacing"):
        rthdist.compare_masks(a, b, spacing=(1, 0, 1), backend="cpu")
    with pytest.raises(ValueError, match="singular|below the smallest spacing"):
        rthdist.compare_masks(a, b, affine=np.diag([1.0, 1.0, 0.0, 1.0]), backend="cpu")
    with pytest.raises(ValueError, match="last row"):
        rthdist.compare_masks(a, b, affine=np.ones((4, 4)), backend="cpu")
    with pytest.raises(ValueError, match="exclude each other"):
        rthdist.compare_masks(a, b, label=1, labels="all", backend="cpu")
    with pytest.raises(ValueError, match="labels must be 'all'"):
        rthdist.compare_masks(a, b, labels="some", backend="cpu")
    with pytest.raises(ValueError, match="int32"):
        rthdist.compare_masks(a, b, label=2**31, backend="cpu")
    with pytest.raises(ValueError, match="was not asked for"):
        rthdist.compare_masks(a, b, percentiles=(90,), backend="cpu").hd95


def test_images_carry_their_affine(pair):
    nib = pytest.importorskip("nibabel")
    a, b = pair
    img_a, img_b = nib.Nifti1Image(a.astype(np.uint8), np.eye(4)), nib.Nifti1Image(b.astype(np.uint8), np.eye(4))
    with pytest.raises(ValueError, match="spacing/affine"):
        rthdist.compare_masks(img_a, img_b, spacing=(1, 1, 2), backend="cpu")
    with pytest.raises(ValueError, match="different grids"):  # an explicit spacing for the array differs
        rthdist.compare_masks(img_a, b, spacing=(1, 1, 2), backend="cpu")


def test_memory_orders_and_dtypes_read_the_same(pair):
    a, b = pair
    want = without_timings(rthdist.compare_masks(a, b, convention="monai", backend="cpu").to_dict())
    swapped = np.ascontiguousarray(a.transpose(2, 1, 0)).transpose(2, 1, 0)  # Fortran order
    strided = np.zeros((44, 18, 10), dtype=np.int32)[::2]  # not contiguous
    strided[...] = a
    for variant in (np.asfortranarray(a), swapped, strided, a.astype(">i4"), a.astype(np.int8),
                    a.astype(np.float16), a.astype(np.uint32), a.astype(np.int64)):
        got = rthdist.compare_masks(variant, b, convention="monai", backend="cpu")
        assert without_timings(got.to_dict()) == want, variant.dtype
    as_bool = rthdist.compare_masks(a != 0, b != 0, convention="monai", backend="cpu")
    assert without_timings(as_bool.to_dict()) == want  # default: every non-zero voxel


def test_label_selection(pair):
    a, b = pair
    rows = rthdist.compare_masks(a, b, labels="all", convention="rthdist", backend="cpu")
    present = sorted((set(np.unique(a).tolist()) | set(np.unique(b).tolist())) - {0})
    assert [r.label for r in rows] == present
    for r in rows:
        one = rthdist.compare_masks(a == r.label, b == r.label, backend="cpu")
        got, want = without_timings(r.to_dict()), without_timings(one.to_dict())
        assert got.pop("label") == str(r.label) and want.pop("label") == "nonzero"
        assert got == want
        single = rthdist.compare_masks(a, b, label=r.label, backend="cpu")
        assert without_timings(single.to_dict()) == without_timings(r.to_dict())
    listed = rthdist.compare_masks(a, b, labels=[2], backend="cpu")
    assert isinstance(listed, list) and [r.label for r in listed] == [2]
    absent = rthdist.compare_masks(a, b, label=7, backend="cpu")
    assert absent.status == "both_empty"
    empty = rthdist.compare_masks(np.zeros_like(a), np.zeros_like(b), labels="all", backend="cpu")
    assert [r.label for r in empty] == [None] and empty[0].status == "both_empty"


def test_mask_engine_reuse(backend, rng):
    ref = blobs((20, 16, 12), rng, labels=(1,))
    preds = [blobs((20, 16, 12), rng, labels=(1,)) for _ in range(3)]
    with rthdist.MaskEngine(backend, device_extraction=True) as engine:
        assert engine.backend == backend and engine.device and not engine.closed
        assert backend in repr(engine)
        assert engine.device_extraction == (backend != "cpu")
        ref_volume = rthdist.MaskVolume(ref, spacing=SPACING)
        first = [engine.compare(p, ref_volume, spacing=SPACING, convention="all", percentiles=(90, 95))
                 for p in preds]
        again = [engine.compare(p, ref, spacing=SPACING, convention="all", percentiles=(90, 95))
                 for p in reversed(preds)]
        again.reverse()
    assert engine.closed
    with pytest.raises(ValueError, match="closed"):
        engine.compare(preds[0], ref)
    engine.close()  # idempotent
    for x, y, p in zip(first, again, preds):
        one_shot = rthdist.compare_masks(p, ref, spacing=SPACING, convention="all", percentiles=(90, 95),
                                         backend=backend)
        assert {r.extraction for r in one_shot} == {"host"}
        for rx, ry, rz in zip(x, y, one_shot):
            assert without_timings(rx.to_dict()) == without_timings(ry.to_dict())
            assert values_only(rx) == values_only(rz)  # the one-shot call extracts on the host
    if backend != "cpu":
        assert {r.extraction for r in first[0] if r.convention in ("rthdist", "monai")} == {"device"}


def test_device_extraction_equals_the_host(rng):
    a = blobs((20, 16, 12), rng)
    b = blobs((20, 16, 12), rng)
    with rthdist.MaskEngine("ray-query", device_extraction=True) as engine:
        device = engine.compare(a, b, convention="all", labels="all")
        host = engine.compare(a, b, convention="all", labels="all", host_extraction=True)
    assert {r.extraction for r in host} == {"host"}
    assert "device" in {r.extraction for r in device}
    for d, h in zip(device, host):
        dd, hd = without_timings(d.to_dict()), without_timings(h.to_dict())
        dd.pop("extraction"), hd.pop("extraction")
        assert dd == hd


def test_result_accessors(pair):
    a, b = pair
    r = rthdist.compare_masks(a, b, convention="deepmind", percentiles=(95, 99), backend="cpu")
    d = r.to_dict()
    json.dumps(d, allow_nan=False)
    assert r.hd95 == r.percentile(95) == d["hd_percentile"][0]["value"]
    assert r.percentile(99) == d["hd_percentile"][1]["value"]
    assert r.a_to_b.corner == r.a_to_b.voxel == tuple(d["a_to_b"]["corner"])
    assert r.a_to_b.area_mm2 == d["a_to_b"]["area_mm2"] > 0
    assert r.points_are == "surfels" and r.geometry == "spacing"
    assert set(r.timings_ms) == {"extract", "distance", "total"}
    itk = rthdist.compare_masks(a, b, convention="itk", backend="cpu")
    assert itk.hd_percentile == [] and itk.assd is None and itk.surface_dice is None and itk.msd is not None
    assert "MaskResult(" in repr(itk)


def test_threads_share_or_own_engines(rng):
    """The GIL is released while comparing: threads with their own engines, or one shared
    engine (calls wait for each other; its properties stay readable meanwhile), give the
    serial results."""
    import threading

    pairs = [(blobs((18, 16, 10), rng), blobs((18, 16, 10), rng)) for _ in range(4)]
    want = [without_timings(rthdist.compare_masks(a, b, convention="all", backend="cpu")[i].to_dict())
            for a, b in pairs for i in range(len(rthdist.CONVENTIONS))]
    got = {}

    def work(engine, k):
        a, b = pairs[k]
        rows = engine.compare(a, b, convention="all")
        got[k] = [without_timings(r.to_dict()) for r in rows]

    own = [rthdist.MaskEngine("cpu") for _ in pairs]
    threads = [threading.Thread(target=work, args=(own[k], k)) for k in range(len(pairs))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [row for k in range(len(pairs)) for row in got[k]] == want
    got.clear()
    with rthdist.MaskEngine("cpu") as shared:
        threads = [threading.Thread(target=work, args=(shared, k)) for k in range(len(pairs))]
        for t in threads:
            t.start()
        while any(t.is_alive() for t in threads):
            assert not shared.closed and shared.backend == "cpu"
        for t in threads:
            t.join()
    assert [row for k in range(len(pairs)) for row in got[k]] == want
    for e in own:
        e.close()


def test_an_image_without_sform_or_qform(tmp_path, pair):
    """nibabel's fallback affine (x flipped, centred) instead of the CLI's diag(pixdim): the
    same spacing, hence the same numbers; the witness points differ."""
    nib = pytest.importorskip("nibabel")
    a, b = pair
    images = []
    for name, x in (("a.nii", a), ("b.nii", b)):
        img = nib.Nifti1Image(x.astype(np.int16), None)
        img.header.set_zooms(SPACING)
        img.header.set_sform(None, code=0)
        img.header.set_qform(None, code=0)
        nib.save(img, tmp_path / name)
        images.append(nib.load(tmp_path / name))
    want = cli_rows(str(tmp_path / "a.nii"), str(tmp_path / "b.nii"), "--convention", "all", "--backend", "cpu")
    assert want["a"]["transform"] == "pixdim"
    volume = rthdist.MaskVolume(images[0])
    assert volume.transform == "image" and volume.affine[0, 0] < 0
    np.testing.assert_allclose(volume.spacing, SPACING, rtol=1e-7)
    got = rthdist.compare_masks(images[0], images[1], convention="all", backend="cpu")
    for r, w in zip(got, want["results"]):
        assert r.convention == w["convention"] and r.status == w["status"] == "ok"
        for key in ("hd", "assd", "msd", "surface_dice"):
            assert r.to_dict()[key] == pytest.approx(w[key], rel=1e-12, abs=1e-12), (r.convention, key)
        assert [e["value"] for e in r.hd_percentile] == pytest.approx([e["value"] for e in w["hd_percentile"]],
                                                                     rel=1e-12)
        assert r.a_to_b.points == w["a_to_b"]["points"] and r.b_to_a.points == w["b_to_a"]["points"]


def values_only(r):
    """A row without timings and extraction (where the boundary was found)."""
    d = without_timings(r.to_dict())
    d.pop("extraction")
    return d


def test_prepared_reference_equals_compare(backend, rng):
    """One reference prepared once, 12 predictions (noisy, empty, one voxel,
    identical): as a, every row equals compare(reference, prediction); as b,
    compare(prediction, reference); every convention and label."""
    shape = (22, 18, 10)
    ref = blobs(shape, rng)
    preds = [blobs(shape, rng) for _ in range(8)]
    one = np.zeros(shape, np.uint8)
    one[3, 4, 5] = 1
    preds += [np.zeros(shape, np.int16), one, ref.copy(), (ref == 2).astype(np.bool_)]
    kw = dict(convention="all", labels="all", percentiles=(50, 95, 100), tolerance=1.5)
    with rthdist.MaskEngine(backend) as engine:
        prepared = engine.prepare_reference(ref, spacing=SPACING, convention="all", labels="all")
        assert isinstance(prepared, rthdist.PreparedReference) and prepared.engine is engine
        assert len(prepared.prepared) == 2 * len(rthdist.CONVENTIONS)
        assert prepared.host_bytes > 0 and (prepared.device_bytes > 0) == (backend != "cpu")
        assert prepared.volume.shape == shape and np.allclose(prepared.volume.spacing, SPACING)
        statuses = set()
        for p in preds:
            want_ab = engine.compare(ref, p, spacing=SPACING, **kw)
            want_ba = engine.compare(p, ref, spacing=SPACING, **kw)
            got_ab = engine.compare(prepared, p, **kw)
            got_ba = engine.compare(p, prepared, **kw)
            assert [values_only(r) for r in got_ab] == [values_only(r) for r in want_ab]
            assert [values_only(r) for r in got_ba] == [values_only(r) for r in want_ba]
            statuses |= {r.status for r in got_ba}
        assert {"ok", "a_empty"} <= statuses
        # A convention or connectivity asked later is prepared on first use.
        before = len(prepared.prepared)
        got = engine.compare(preds[0], prepared, convention="medpy", connectivity=26)
        want = engine.compare(preds[0], ref, spacing=SPACING, convention="medpy", connectivity=26)
        assert values_only(got) == values_only(want)
        assert len(prepared.prepared) == before + 1
        # compare_masks runs on the reference's engine.
        assert values_only(rthdist.compare_masks(preds[1], prepared, convention="itk")) == \
            values_only(engine.compare(preds[1], ref, spacing=SPACING, convention="itk"))


def test_prepared_reference_refusals(rng):
    shape = (12, 10, 8)
    ref = blobs(shape, rng, labels=(1,))
    with rthdist.MaskEngine("cpu") as engine, rthdist.MaskEngine("cpu") as other:
        prepared = engine.prepare_reference(ref, spacing=SPACING, convention="monai")
        with pytest.raises(ValueError, match="another MaskEngine"):
            other.compare(ref, prepared)
        with pytest.raises(ValueError, match="different grids"):
            engine.compare(np.zeros((12, 10, 9), np.uint8), prepared)
        with pytest.raises(ValueError, match="different grids"):
            engine.compare(ref, prepared, spacing=(1.0, 1.0, 1.0))
        with pytest.raises(ValueError, match="another PreparedReference"):
            engine.compare(prepared, prepared)
        with pytest.raises(ValueError, match="percentile"):
            engine.compare(ref, prepared, percentiles=(101,))
    with pytest.raises(ValueError, match="closed"):
        engine.compare(ref, prepared)


def test_a_volumes_nonzero_voxels_are_numpys_count():
    rng = np.random.default_rng(SEED)
    for dtype in (np.uint8, np.int32, np.float64):
        labels = (rng.integers(0, 4, size=(7, 5, 3)) * (rng.random((7, 5, 3)) < 0.4)).astype(dtype)
        v = rthdist.MaskVolume(labels)
        assert v._v.nonzero_voxels() == np.count_nonzero(labels)


def test_one_shot_backend_takes_the_cpu_only_for_a_small_auto_call():
    # compare_masks is one-shot: under "auto" a run of few points goes to the
    # CPU backend (rthdist::oneShotBackendFor); a device, validation or a
    # named backend keep the Vulkan path; past 2^18 points a thread, as asked.
    one = rthdist._rthdist._one_shot_backend
    per_thread = 1 << 18
    assert one(per_thread, "auto", None, 1, False) == "cpu"
    assert one(per_thread + 1, "auto", None, 1, False) == "auto"
    assert one(2 * per_thread, "auto", None, 2, False) == "cpu"
    assert one(10, "auto", 0, 2, False) == "auto"
    assert one(10, "auto", None, 2, True) == "auto"
    for named in ("ray-query", "rt-pipeline", "cpu"):
        assert one(10, named, None, 2, False) == named


def test_compare_masks_under_auto_gives_the_cpus_row(pair):
    a, b = pair
    auto = rthdist.compare_masks(a, b, convention="all")
    cpu = rthdist.compare_masks(a, b, convention="all", backend="cpu")
    assert [r.to_dict()["hd"] for r in auto] == [r.to_dict()["hd"] for r in cpu]
    assert all(r.backend == "cpu" for r in auto)
