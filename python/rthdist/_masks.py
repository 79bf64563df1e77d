"""Segmentation masks from Python: rthdist.compare_masks, MaskEngine, MaskVolume,
PreparedReference.

The C++ masks library (include/rthdist/masks.hpp, README "Segmentation masks") on
NumPy label arrays and nibabel images: HD, HD-p, ASSD/MSD and surface Dice in
the convention of a named tool, exactly, with the rows of `rthdist-masks
--json` as results (MaskResult.to_dict() is such a row).
"""

import math as _math
import os as _os

import numpy as _np

from . import _rthdist
from ._device_owner import DeviceOwner

CONVENTIONS = tuple(_rthdist._conventions())

# The dtypes a label array may have (src/masks label_types.hpp); float16 is
# widened to float32 (exact).
_LABEL_KINDS = {"b", "u", "i", "f"}


def _is_image(x):
    """A nibabel spatial image (or anything with .dataobj and .affine)."""
    return hasattr(x, "dataobj") and hasattr(x, "affine") and not isinstance(x, _np.ndarray)


def _image_data(img, name):
    """(3-D array, 4x4 affine, name, transform) of a nibabel spatial image."""
    affine = img.affine
    if affine is None:
        raise ValueError(f"{name}: the image has no affine")
    data = _np.asanyarray(img.dataobj)
    if data.ndim > 3:  # a 4-D (or more) image with one volume, as libnifti2 reads it for the CLI
        extra = data.shape[3:]
        if any(n != 1 for n in extra):
            raise ValueError(f"{name}: a {data.ndim}-D image with more than one volume (shape {data.shape}); "
                             "masks are 3-D")
        data = data.reshape(data.shape[:3])
    elif data.ndim < 3:
        data = data.reshape(data.shape + (1,) * (3 - data.ndim))
    filename = img.get_filename() if hasattr(img, "get_filename") else None
    transform = "image"
    header = getattr(img, "header", None)
    if header is not None and hasattr(header, "get_sform") and hasattr(header, "get_qform"):
        if int(header.get_sform(coded=True)[1] or 0) > 0:
            transform = "sform"
        elif int(header.get_qform(coded=True)[1] or 0) > 0:
            transform = "qform"
    return data, _np.asarray(affine, dtype=_np.float64), filename or name, transform


def _label_array(x, name):
    """x as a 3-D label array the module reads in place: a label dtype in
    native byte order, C or Fortran contiguous (copied only when not)."""
    a = _np.asarray(x)
    if a.ndim != 3:
        raise ValueError(f"{name}: expected a 3-D label array (axes i, j, k), got shape {a.shape}")
    if a.dtype == _np.float16:
        a = a.astype(_np.float32)
    if a.dtype.kind not in _LABEL_KINDS:
        raise ValueError(f"{name}: dtype {a.dtype} is not a label type (bool, integers, float32/float64 "
                         "holding integers)")
    if not a.dtype.isnative:
        a = a.astype(a.dtype.newbyteorder("="))
    if not (a.flags.c_contiguous or a.flags.f_contiguous):
        a = _np.ascontiguousarray(a)
    return a


def _affine_of(spacing, affine, name):
    """The 4x4 voxel-to-world matrix of an array: affine (4x4 or 3x4), else
    diag(spacing); (matrix, transform)."""
    if affine is not None:
        m = _np.asarray(affine, dtype=_np.float64)
        if m.shape == (3, 4):
            m = _np.vstack([m, [0.0, 0.0, 0.0, 1.0]])
        if m.shape != (4, 4):
            raise ValueError(f"{name}: affine must be 4 x 4 (or 3 x 4), got shape {m.shape}")
        return m, "affine"
    s = (1.0, 1.0, 1.0) if spacing is None else tuple(float(v) for v in spacing)
    if len(s) != 3 or not all(_math.isfinite(v) and v > 0 for v in s):
        raise ValueError(f"spacing must be three positive numbers (axes i, j, k), got {spacing!r}")
    return _np.diag([s[0], s[1], s[2], 1.0]), "spacing"


class MaskVolume:
    """A label volume ready for comparisons: its labels copied once (i
    fastest) with its voxel-to-world affine. Pass one to compare_masks or
    MaskEngine.compare to reuse it (a reference compared with many
    predictions is then converted once).

    data: a 3-D array (bool, int8..int64, uint8..uint64, float16/32/64
    holding integers; any memory order; axes 0, 1, 2 = i, j, k as the .npy
    loader) or a nibabel spatial image (np.asanyarray(img.dataobj) and
    img.affine: scl_slope/inter applied by nibabel, a 4-D image with one
    volume accepted). spacing (three voxel sizes, origin 0; default 1, 1, 1)
    or affine (4 x 4 or 3 x 4 voxel-to-world) apply to arrays only.
    name: what errors call it (default: the image's file name, else "mask").
    """

    def __init__(self, data, *, spacing=None, affine=None, name=None):
        if isinstance(data, MaskVolume):
            self._v = data._v
            return
        if _is_image(data):
            if spacing is not None or affine is not None:
                raise ValueError("a nibabel image carries its affine: spacing/affine apply to arrays only")
            array, m, label, transform = _image_data(data, name or "mask")
            name = name or label
        else:
            m, transform = _affine_of(spacing, affine, name or "mask")
            array = data
        name = _os.fspath(name) if name is not None else "mask"
        self._v = _rthdist._mask_volume(_label_array(array, name), m, str(name), transform)

    @property
    def shape(self):
        """(n_i, n_j, n_k)."""
        return self._v.shape

    @property
    def affine(self):
        """The 4 x 4 voxel-to-world matrix: voxel (i, j, k) at affine @ (i, j, k, 1)."""
        return self._v.affine

    @property
    def spacing(self):
        """The column norms of the affine's 3 x 3 part (the spacing most tools measure with)."""
        return self._v.spacing

    @property
    def transform(self):
        """Where the affine came from: "spacing", "affine", "sform", "qform" or "image"."""
        return self._v.transform

    @property
    def name(self):
        return self._v.name

    def labels_present(self):
        """Sorted distinct non-zero labels."""
        return self._v.labels_present()

    def __repr__(self):
        return f"MaskVolume(name={self.name!r}, shape={self.shape}, spacing={self.spacing}, " \
               f"transform={self.transform!r})"


def _volumes(a, b, spacing, affine):
    """a and b as MaskVolumes. An array takes affine, else spacing, else (when
    the other input is a nibabel image or MaskVolume) the other's affine, else
    spacing 1, 1, 1."""
    known = {"a": a, "b": b}
    given = spacing is not None or affine is not None
    if given and all(_is_image(x) or isinstance(x, MaskVolume) for x in (a, b)):
        raise ValueError("spacing/affine apply to arrays; both inputs carry their own affine")
    out = {}
    for name, x in known.items():
        if isinstance(x, MaskVolume):
            out[name] = x
        elif _is_image(x):
            filename = x.get_filename() if hasattr(x, "get_filename") else None
            out[name] = MaskVolume(x, name=filename or name)
    for name, x in known.items():
        if name in out:
            continue
        other = out.get("b" if name == "a" else "a")
        if not given and other is not None:
            out[name] = MaskVolume(x, affine=other.affine, name=name)
        else:
            out[name] = MaskVolume(x, spacing=spacing, affine=affine, name=name)
    return out["a"], out["b"]


def _conventions(convention):
    if isinstance(convention, str):
        return list(CONVENTIONS) if convention == "all" else [convention]
    names = [str(c) for c in convention]
    if not names:
        raise ValueError("convention: give at least one name")
    return names


def _selection(label, labels):
    """(what the module takes, whether one row per label is asked)."""
    if label is not None and labels is not None:
        raise ValueError("label and labels exclude each other")
    if label is not None:
        if isinstance(label, (bool, _np.bool_)) or not isinstance(label, (int, _np.integer)):
            raise ValueError(f"label must be an int32, got {label!r}")
        return [int(label)], False
    if labels is None:
        return None, False
    if isinstance(labels, str):
        if labels != "all":
            raise ValueError(f"labels must be 'all' or a list of int32 labels, got {labels!r}")
        return "all", True
    out = []
    for v in labels:
        if isinstance(v, (bool, _np.bool_)) or not isinstance(v, (int, _np.integer)):
            raise ValueError(f"labels must be int32 values, got {v!r}")
        out.append(int(v))
    return out, True


def _percentiles(percentiles):
    if isinstance(percentiles, (int, float, _np.integer, _np.floating)):
        percentiles = (percentiles,)
    return [float(p) for p in percentiles]


class PreparedReference:
    """A reference (ground-truth) mask prepared once on a MaskEngine
    (MaskEngine.prepare_reference; include/rthdist/masks.hpp): its
    boundary voxels (itk: also its foreground) extracted and indexed on the
    engine's device (deepmind: its surfels extracted), so that each
    comparison with a prediction extracts and indexes only the prediction.

    Pass it as a or b to that engine's compare() (or to compare_masks, which
    then runs on that engine): as a, the rows equal compare(reference,
    prediction) value for value; as b, those of compare(prediction,
    reference) (the directions exchanged; bit for bit when the two affines
    are equal, as when the prediction is an array taking the reference's
    affine). A label or convention not prepared yet is prepared on first use
    and kept (the reference's MaskVolume is kept for that).

    volume: the reference's MaskVolume. prepared: one dict per prepared
    (label, convention): label (None: every non-zero voxel), convention,
    connectivity, points, selected_voxels, host_bytes, device_bytes,
    prepare_ms, extraction. host_bytes / device_bytes: their sums. The memory
    is released with the object (and its engine's device with the last of
    them and the engine).
    """

    def __init__(self, engine, handle):
        self._engine = engine
        self._p = handle

    @property
    def engine(self):
        """The MaskEngine it was prepared on (and is compared on)."""
        return self._engine

    @property
    def volume(self):
        v = MaskVolume.__new__(MaskVolume)
        v._v = self._p.volume
        return v

    @property
    def prepared(self):
        return self._p.sets()

    @property
    def host_bytes(self):
        return sum(s["host_bytes"] for s in self._p.sets())

    @property
    def device_bytes(self):
        return sum(s["device_bytes"] for s in self._p.sets())

    def __repr__(self):
        sets = self._p.sets()
        return (f"PreparedReference(name={self._p.volume.name!r}, sets={len(sets)}, "
                f"points={sum(s['points'] for s in sets)}, host_bytes={self.host_bytes}, "
                f"device_bytes={self.device_bytes})")


class MaskEngine(DeviceOwner):
    """The masks' engine kept between calls: the Vulkan device (and, with
    device_extraction=True on a GPU backend, the boundary compute pass)
    opened once. Boundary voxels are found on the host by default (measured
    faster than the compute pass: docs/bench/masks).

        with rthdist.MaskEngine("ray-query") as engine:
            ref = rthdist.MaskVolume(nib.load("gt.nii.gz"))      # converted once
            for path in predictions:
                r = engine.compare(nib.load(path), ref, convention="monai")

    compare() takes compare_masks's arguments but backend/device/threads.
    prepare_reference() prepares a reference compared with many predictions
    (PreparedReference: extracted and indexed once):

        with rthdist.MaskEngine("ray-query") as engine:
            ref = engine.prepare_reference(nib.load("gt.nii.gz"), convention="monai")
            rows = [engine.compare(nib.load(p), ref, convention="monai") for p in predictions]

    One call at a time (threads wait for each other); close() or the with
    block releases the device.
    """

    def __init__(self, backend="auto", *, device=None, threads=0, validation=False, device_extraction=False):
        self._engine = _rthdist._MaskEngine(str(backend), device, int(threads), bool(validation),
                                            bool(device_extraction))

    def prepare_reference(self, reference, *, spacing=None, affine=None, convention="rthdist",
                          connectivity=None, label=None, labels=None, host_extraction=False):
        """A PreparedReference of `reference` (compare_masks's inputs: a 3-D
        label array with spacing/affine, a nibabel image or a MaskVolume) on
        this engine, for every convention (a name, a list, or "all") and
        label (label=N, labels=[...] or "all": those present in the
        reference; default every non-zero voxel) asked now; others are
        prepared when a comparison first asks for them."""
        if isinstance(reference, MaskVolume):
            if spacing is not None or affine is not None:
                raise ValueError("a MaskVolume carries its affine: spacing/affine apply to arrays only")
            volume = reference
        elif _is_image(reference):
            volume = MaskVolume(reference, spacing=spacing, affine=affine)
        else:
            volume = MaskVolume(reference, spacing=spacing, affine=affine, name="reference")
        selection, _ = _selection(label, labels)
        handle = self._engine.prepare(volume._v, selection, _conventions(convention),
                                      0 if connectivity is None else int(connectivity), bool(host_extraction))
        return PreparedReference(self, handle)

    def compare(self, a, b, *, spacing=None, affine=None, convention="rthdist", percentiles=(95,),
                connectivity=None, tolerance=1.0, label=None, labels=None, host_extraction=False):
        """As rthdist.compare_masks on this engine's device; a or b may be a
        PreparedReference of this engine."""
        names = _conventions(convention)
        selection, per_label = _selection(label, labels)
        settings = (names, _percentiles(percentiles), 0 if connectivity is None else int(connectivity),
                    float(tolerance), bool(host_extraction))
        prepared = a if isinstance(a, PreparedReference) else b if isinstance(b, PreparedReference) else None
        if prepared is not None:
            if isinstance(a, PreparedReference) and isinstance(b, PreparedReference):
                raise ValueError("compare a PreparedReference with a mask, not with another PreparedReference")
            if prepared.engine is not self:
                raise ValueError("this PreparedReference was prepared on another MaskEngine: compare it there")
            ref = prepared.volume
            other = b if prepared is a else a
            _, vo = _volumes(ref, other, spacing, affine)
            rows = self._engine.compare_prepared(prepared._p, vo._v, prepared is b, selection, *settings)
        else:
            va, vb = _volumes(a, b, spacing, affine)
            rows = self._engine.compare(va._v, vb._v, selection, *settings)
        backend, device = self.backend, self.device
        results = [MaskResult(row, backend, device) for row in rows]
        if len(names) == 1 and not per_label:
            return results[0]
        return results

    @property
    def device_extraction(self):
        """Whether boundary voxels are found by the compute pass (GPU backends)."""
        return self._engine.device_extraction


def compare_masks(a, b, *, spacing=None, affine=None, convention="rthdist", percentiles=(95,),
                  connectivity=None, tolerance=1.0, label=None, labels=None, backend="auto", device=None,
                  threads=0, host_extraction=False, validation=False, device_extraction=False):
    """HD, HD-p, ASSD/MSD and surface Dice between two segmentation masks.

    a, b: 3-D label arrays (axes i, j, k; bool, integer or integral float
        dtypes; C or Fortran order), nibabel spatial images, or MaskVolumes.
        A is the prediction (MONAI's y_pred), B the reference.
    spacing / affine: the arrays' voxel sizes (origin 0) or 4 x 4 (3 x 4)
        voxel-to-world matrix; an array beside an image (or MaskVolume) takes
        that one's affine when neither is given; default spacing 1, 1, 1.
        Both masks must share a grid (dims and affine to 1e-5): else
        ValueError naming both (nothing is resampled).
    convention: "rthdist" (default), "monai", "medpy", "plastimatch", "itk",
        "deepmind", a list of them, or "all" (CONVENTIONS).
    percentiles: the HD-p values to report (each in [0, 100]).
    connectivity: 6, 18 or 26 (None = 6) for rthdist and medpy boundaries.
    tolerance: surface Dice tolerance in mm.
    label: compare label N in both; labels: "all" (every label present in
        either, one result each) or a list; default every non-zero voxel.
    backend, device, threads, validation: as rthdist.hausdorff;
    device_extraction: GPU backends: boundary voxels by a compute shader
        (default: on the host, measured faster);
    host_extraction: with device_extraction, on the host all the same.

    Returns a MaskResult, or a list of them (label-major, as the CLI's rows)
    when several conventions or labels="all"/a list are asked. A temporary
    device is created per call (under "auto", small masks, at most 2^18
    nonzero voxels a host thread, run on the CPU backend instead, which
    answers before a GPU has opened its device); keep a MaskEngine for
    repeated calls.
    Raises ValueError (shapes or affines that differ, not 3-D, non-integral
    or non-int32 labels, bad convention or options), DeviceError,
    OutOfMemoryError, InternalError.

    With a PreparedReference as a or b (MaskEngine.prepare_reference), the
    comparison runs on the engine that prepared it (backend, device, threads
    and validation are not used).
    """
    for x in (a, b):
        if isinstance(x, PreparedReference):
            return x.engine.compare(a, b, spacing=spacing, affine=affine, convention=convention,
                                    percentiles=percentiles, connectivity=connectivity, tolerance=tolerance,
                                    label=label, labels=labels, host_extraction=host_extraction)
    if backend == "auto" and not device_extraction:
        # A one-shot call: the backend a call of the run's points would take
        # (at most the masks' nonzero voxels, eight a voxel for surfels, over
        # the conventions): the CPU for small masks, which it answers before a
        # GPU has opened its device (README, rthdist-masks).
        a, b = _volumes(a, b, spacing, affine)
        spacing = affine = None
        backend = _rthdist._one_shot_mask_backend(a._v, b._v, _conventions(convention), backend, device,
                                                  threads, validation)
    with MaskEngine(backend, device=device, threads=threads, validation=validation,
                    device_extraction=device_extraction) as engine:
        return engine.compare(a, b, spacing=spacing, affine=affine, convention=convention,
                              percentiles=percentiles, connectivity=connectivity, tolerance=tolerance,
                              label=label, labels=labels, host_extraction=host_extraction)


class DirectedMask:
    """One direction X -> Y of a MaskResult (the CLI's a_to_b / b_to_a).

    points: X's points under the convention. hd, mean, surface_overlap,
    percentiles ([{"p", "value"}]), voxel / nearest_voxel (grid indices of
    the witness pair; deepmind: surfel corners, also as corner /
    nearest_corner), point / nearest_point (world coordinates, float64),
    area_mm2 (deepmind). None where the status is not "ok".
    """

    __slots__ = ("_d",)

    def __init__(self, d):
        self._d = d

    def _get(self, key):
        return self._d.get(key)

    points = property(lambda self: self._d["points"])
    hd = property(lambda self: self._get("hd"))
    mean = property(lambda self: self._get("mean"))
    surface_overlap = property(lambda self: self._get("surface_overlap"))
    percentiles = property(lambda self: self._get("percentiles"))
    area_mm2 = property(lambda self: self._get("area_mm2"))
    corner = property(lambda self: _tuple(self._get("corner")))
    nearest_corner = property(lambda self: _tuple(self._get("nearest_corner")))

    @property
    def voxel(self):
        return _tuple(self._d.get("voxel", self._d.get("corner")))

    @property
    def nearest_voxel(self):
        return _tuple(self._d.get("nearest_voxel", self._d.get("nearest_corner")))

    @property
    def point(self):
        return _point(self._get("point"))

    @property
    def nearest_point(self):
        return _point(self._get("nearest_point"))

    def to_dict(self):
        return _copy(self._d)

    def __repr__(self):
        return f"DirectedMask(points={self.points}, hd={self.hd}, voxel={self.voxel})"


def _tuple(v):
    return None if v is None else tuple(v)


def _point(v):
    return None if v is None else _np.array([_math.nan if x is None else x for x in v], dtype=_np.float64)


def _copy(x):
    if isinstance(x, dict):
        return {k: _copy(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_copy(v) for v in x]
    return x


class MaskResult:
    """One row of `rthdist-masks --json` (label, convention): to_dict() is
    that row, key for key; the attributes below read it.

    status: "ok", "both_empty", "a_empty" or "b_empty". Unless "ok", every
    number is None and convention_value says, as text, what the convention
    itself reports ("nan", "inf", "0", "undefined", "error"): an empty mask
    is never a NaN inside a number. itk has no ASSD, surface Dice or
    percentiles (None / []).
    label: the label compared (None: every non-zero voxel; to_dict() has the
    CLI's text, "nonzero" or the number). hd, assd, msd, surface_dice;
    hd_percentile ([{"p", "value"}]; percentile(p), hd95); a_to_b, b_to_a
    (DirectedMask); convention, rule, connectivity, geometry ("world" or
    "spacing"), points_are; extraction ("device" or "host"); timings_ms
    (extract, distance, total), engine_ms; backend and device of the engine.
    """

    def __init__(self, row, backend, device):
        self._row = row
        self.backend = backend
        self.device = device
        self.a_to_b = DirectedMask(row["a_to_b"])
        self.b_to_a = DirectedMask(row["b_to_a"])

    label = property(lambda self: None if self._row["label"] == "nonzero" else int(self._row["label"]))
    convention = property(lambda self: self._row["convention"])
    rule = property(lambda self: self._row["rule"])
    connectivity = property(lambda self: self._row["connectivity"])
    geometry = property(lambda self: self._row["geometry"])
    points_are = property(lambda self: self._row["points_are"])
    status = property(lambda self: self._row["status"])
    ok = property(lambda self: self._row["status"] == "ok", doc="status == 'ok'")
    convention_value = property(lambda self: _copy(self._row.get("convention_value")))
    hd = property(lambda self: self._row["hd"])
    hd_percentile = property(lambda self: _copy(self._row["hd_percentile"]))
    assd = property(lambda self: self._row["assd"])
    msd = property(lambda self: self._row["msd"])
    surface_dice = property(lambda self: self._row["surface_dice"])
    extraction = property(lambda self: self._row["extraction"])
    timings_ms = property(lambda self: dict(self._row["timings_ms"]))
    engine_ms = property(lambda self: dict(self._row["engine_ms"]))

    def percentile(self, p):
        """HD-p for a requested p (the convention's combination of the two
        directions); None unless status is "ok"."""
        for e in self._row["hd_percentile"]:
            if e["p"] == float(p):
                return e["value"]
        asked = [e["p"] for e in self._row["hd_percentile"]]
        raise ValueError(f"percentile {p} was not asked for (percentiles={asked}; itk has none)")

    @property
    def hd95(self):
        """percentile(95)."""
        return self.percentile(95)

    def to_dict(self):
        """The CLI's JSON row (a copy): NaN/inf as None, as `--json` writes null."""
        return _copy(self._row)

    def __repr__(self):
        label = "nonzero" if self.label is None else self.label
        if not self.ok:
            return (f"MaskResult(label={label}, convention={self.convention!r}, status={self.status!r}, "
                    f"convention_value={self.convention_value})")
        p = ", ".join(f"hd{e['p']:g}={e['value']}" for e in self._row["hd_percentile"])
        return (f"MaskResult(label={label}, convention={self.convention!r}, hd={self.hd}"
                + (f", {p}" if p else "") + f", assd={self.assd}, surface_dice={self.surface_dice})")
