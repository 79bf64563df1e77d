#include "masks.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "engine.hpp"
#include "errors.hpp"
#include "rthdist/masks.hpp"

namespace py = pybind11;

namespace rthdist::python {
namespace {

using masks::Convention;
using masks::MaskResult;

// A label volume for Python: the masks library's Volume (labels copied once).
struct PyVolume {
    std::shared_ptr<const masks::Volume> volume;
};

// The NumPy kind of a label dtype ("u1", "i4", "f8", ...); ValueError for others.
std::string labelKind(const py::array& array, const std::string& name) {
    const py::dtype dtype = array.dtype();
    const char kind = dtype.kind();
    const char order = dtype.byteorder();
    const bool native = order == '=' || order == '|' || (order == '<' && PY_LITTLE_ENDIAN) ||
                        (order == '>' && !PY_LITTLE_ENDIAN);
    if ((kind != 'b' && kind != 'u' && kind != 'i' && kind != 'f') || !native)
        throw py::value_error(name + ": dtype " + std::string(py::str(py::handle(dtype))) +
                              " is not a label type (bool, integers, float32/float64 in native byte order)");
    return std::string(1, kind) + std::to_string(dtype.itemsize());
}

// `array` (3-D, C or Fortran contiguous) with its 4x4 voxel-to-world matrix.
PyVolume volumeOf(const py::array& array, const py::array_t<double, py::array::forcecast>& affine,
                  const std::string& name, const std::string& transform) {
    if (array.ndim() != 3)
        throw py::value_error(name + ": expected a 3-D label array (axes i, j, k), got shape " +
                              std::string(py::str(array.attr("shape"))));
    if (affine.ndim() != 2 || affine.shape(0) != 4 || affine.shape(1) != 4)
        throw py::value_error(name + ": the affine must be 4 x 4");
    const std::string kind = labelKind(array, name);
    masks::LabelArray view;
    view.data = array.data();
    view.dims = {int64_t(array.shape(0)), int64_t(array.shape(1)), int64_t(array.shape(2))};
    view.kind = kind;
    if (array.flags() & py::array::c_style) {
        view.fortran = false;
    } else if (array.flags() & py::array::f_style) {
        view.fortran = true;
    } else {
        throw py::value_error(name +
                              ": the label array must be C or Fortran contiguous (np.ascontiguousarray)");
    }
    glm::dmat4 m(1.0);
    auto a = affine.unchecked<2>();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[c][r] = a(r, c);
    std::optional<Result<masks::Volume>> v;
    {
        py::gil_scoped_release release;
        v.emplace(masks::volumeFromArray(view, m, name, transform));
    }
    return PyVolume{std::make_shared<const masks::Volume>(valueOrRaise(std::move(*v)))};
}

py::array_t<double> affineOf(const masks::Volume& v) {
    py::array_t<double> out({4, 4});
    auto w = out.mutable_unchecked<2>();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) w(r, c) = v.voxelToWorld[c][r];
    return out;
}

// A number as the CLI's JSON writes it: NaN and infinities as None (null).
py::object number(double v) { return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none()); }

py::list triple(const glm::dvec3& p) {
    py::list out;
    for (int i = 0; i < 3; ++i) out.append(number(p[i]));
    return out;
}

py::list percentileRows(const std::vector<double>& p, const std::vector<double>& values) {
    py::list out;
    for (size_t i = 0; i < values.size() && i < p.size(); ++i)
        out.append(py::dict(py::arg("p") = p[i], py::arg("value") = number(values[i])));
    return out;
}

// directedJson of tools/cli/masks/masks_main.cpp.
py::dict directedDict(const masks::DirectedMask& d, const MaskResult& r, bool ok) {
    py::dict out;
    out["points"] = d.points;
    if (!ok) return out;
    out["hd"] = number(d.hd);
    out["mean"] = number(d.mean);
    out["surface_overlap"] = number(d.surfaceOverlap);
    const bool corners = masks::conventionRules(r.convention).points == masks::PointSet::kSurfels;
    if (corners) out["area_mm2"] = number(d.area);
    out["percentiles"] = percentileRows(r.percentiles, d.percentiles);
    out[corners ? "corner" : "voxel"] = py::cast(d.voxel);
    out["point"] = triple(d.point);
    out[corners ? "nearest_corner" : "nearest_voxel"] = py::cast(d.nearestVoxel);
    out["nearest_point"] = triple(d.nearestPoint);
    return out;
}

py::dict engineMs(const Timings& e) {
    py::dict d;
    const std::pair<const char*, double> entries[] = {
        {"upload", e.upload},    {"index", e.index},          {"cull", e.cull},
        {"search", e.search},    {"refine", e.refine},        {"check", e.check},
        {"total", e.total},      {"gpu_upload", e.gpuUpload}, {"gpu_index", e.gpuIndex},
        {"gpu_cull", e.gpuCull}, {"gpu_search", e.gpuSearch}, {"gpu_refine", e.gpuRefine}};
    for (const auto& [key, value] : entries) d[key] = number(value);
    return d;
}

py::list percentileTexts(const std::vector<double>& p, const std::vector<std::string>& texts) {
    py::list out;
    for (size_t i = 0; i < texts.size() && i < p.size(); ++i)
        out.append(py::dict(py::arg("p") = p[i], py::arg("value") = texts[i]));
    return out;
}

py::dict emptyDirectedDict(const masks::EmptyDirected& d, const std::vector<double>& p) {
    py::dict out;
    out["hd"] = d.hd;
    out["mean"] = d.mean;
    out["surface_overlap"] = d.surfaceOverlap;
    out["percentiles"] = percentileTexts(p, d.percentiles);
    return out;
}

// emptyJson of tools/cli/masks/masks_main.cpp.
py::dict emptyDict(const MaskResult& r) {
    const masks::EmptyValues& e = r.emptyValues;
    py::dict out;
    out["hd"] = e.hd;
    out["hd_percentile"] = percentileTexts(r.percentiles, e.hdPercentile);
    out["assd"] = e.assd;
    out["msd"] = e.msd;
    out["surface_dice"] = e.surfaceDice;
    out["a_to_b"] = emptyDirectedDict(e.aToB, r.percentiles);
    out["b_to_a"] = emptyDirectedDict(e.bToA, r.percentiles);
    return out;
}

// rowJson of tools/cli/masks/masks_main.cpp (same keys, same order).
py::dict rowDict(const std::string& label, const MaskResult& r) {
    const bool ok = r.empty == masks::EmptyStatus::kNone;
    py::dict out;
    out["label"] = label;
    out["convention"] = masks::conventionName(r.convention);
    out["rule"] = masks::conventionRule(r.convention);
    out["connectivity"] = r.connectivity;
    out["geometry"] = masks::metricName(masks::conventionRules(r.convention).metric);
    out["points_are"] = masks::pointSetName(masks::conventionRules(r.convention).points);
    out["status"] = masks::emptyStatusName(r.empty);
    if (!ok) out["convention_value"] = emptyDict(r);
    out["hd"] = number(r.hd);
    out["hd_percentile"] = percentileRows(r.percentiles, r.hdPercentile);
    out["assd"] = number(r.assd);
    out["msd"] = number(r.msd);
    out["surface_dice"] = number(r.surfaceDice);
    out["a_to_b"] = directedDict(r.aToB, r, ok);
    out["b_to_a"] = directedDict(r.bToA, r, ok);
    out["extraction"] = r.extraction;
    py::dict timings;
    timings["extract"] = r.extractMs;
    timings["distance"] = r.distanceMs;
    timings["total"] = r.totalMs;
    out["timings_ms"] = timings;
    out["engine_ms"] = engineMs(r.engine);
    return out;
}

// 'rthdist', 'monai', ...: every convention's name, quoted, in table order.
std::string quotedNames() {
    std::string out;
    for (const masks::ConventionRules& row : masks::kConventionRules)
        out += (out.empty() ? "'" : ", '") + std::string(row.name) + "'";
    return out;
}

Convention conventionFrom(const std::string& name) {
    Convention c;
    if (!masks::parseConvention(name, c))
        throw py::value_error("unknown convention '" + name + "' (expected " + quotedNames() + " or 'all')");
    return c;
}

// One row's label: its name in the CLI's output and its selection.
struct Selection {
    std::string name;
    masks::LabelSelect select;
};

// A reference prepared on one _MaskEngine: its volume (kept, so that a label
// or convention asked later is prepared on first use) and one
// masks::PreparedReference per (label, convention, connectivity).
struct PyPrepared {
    using Key = std::tuple<int32_t, bool, int, int>;  // label, any non-zero, convention, connectivity
    PyVolume volume;
    const void* owner = nullptr;  // the _MaskEngine that prepared it
    std::map<Key, masks::PreparedReference> sets;

    static Key key(masks::LabelSelect s, const masks::MaskOptions& o) {
        return {s.anyNonZero ? 0 : s.value, s.anyNonZero, int(o.convention), o.connectivity};
    }
};

// The result of compare(b, a) from compare(a, b): the directions and the
// empty sides exchanged (the numbers of both directions are symmetric).
MaskResult swapped(MaskResult r) {
    std::swap(r.aToB, r.bToA);
    std::swap(r.emptyValues.aToB, r.emptyValues.bToA);
    if (r.empty == masks::EmptyStatus::kAEmpty) {
        r.empty = masks::EmptyStatus::kBEmpty;
    } else if (r.empty == masks::EmptyStatus::kBEmpty) {
        r.empty = masks::EmptyStatus::kAEmpty;
    }
    return r;
}

// The rows' labels as the CLI chooses them: every non-zero voxel (None),
// the given labels, or ("all") every label present in either volume (every
// non-zero voxel when there is none).
std::vector<Selection> selectionsOf(const py::object& labels, const masks::Volume& a,
                                    const masks::Volume& b) {
    std::vector<Selection> out;
    if (labels.is_none()) return {{"nonzero", masks::LabelSelect{1, true}}};
    if (py::isinstance<py::str>(labels)) {
        if (labels.cast<std::string>() != "all")
            throw py::value_error("labels must be 'all', a list of int32 labels or None");
        std::set<int32_t> present;
        {
            py::gil_scoped_release release;
            for (int32_t l : masks::labelsPresent(a)) present.insert(l);
            for (int32_t l : masks::labelsPresent(b)) present.insert(l);
        }
        for (int32_t l : present) out.push_back({std::to_string(l), masks::LabelSelect{l, false}});
        if (out.empty()) out.push_back({"nonzero", masks::LabelSelect{1, true}});
        return out;
    }
    for (const py::handle l : labels) {
        const int64_t v = l.cast<int64_t>();
        if (v < INT32_MIN || v > INT32_MAX)
            throw py::value_error("label " + std::to_string(v) + " is not an int32");
        out.push_back({std::to_string(v), masks::LabelSelect{int32_t(v), false}});
    }
    return out;
}

// The masks' Engine (and boundary pass) for Python, until close().
class PyMaskEngine {
public:
    PyMaskEngine(const std::string& backend, std::optional<int> device, int threads, bool validation,
                 bool devicePass) {
        const Options options = engineOptions(backend, device, threads, validation);
        std::optional<Result<masks::MaskEngine>> engine;
        {
            py::gil_scoped_release release;
            engine.emplace(masks::makeMaskEngine(options, devicePass));
        }
        m_engine.emplace(valueOrRaise(std::move(*engine)));
        m_threads = threads;
    }

    // One dict per (label, convention), label-major as the CLI's rows.
    py::list compare(const PyVolume& a, const PyVolume& b, const py::object& labels,
                     const std::vector<std::string>& conventions, const std::vector<double>& percentiles,
                     int connectivity, double tolerance, bool hostExtraction) {
        const std::vector<Convention> list =
            checkedConventions(conventions, percentiles, connectivity, tolerance);
        if (auto e = masks::checkSameGrid(*a.volume, *b.volume)) raise(*e);
        const std::vector<Selection> rows = selectionsOf(labels, *a.volume, *b.volume);
        const Settings settings{percentiles, connectivity, tolerance, hostExtraction};
        return rowsOf(rows, list, settings, [&](const Selection& row, const masks::MaskOptions& mo) {
            return masks::compareMasks(*m_engine, *a.volume, row.select, *b.volume, row.select, mo);
        });
    }

    // The reference's labels (selectionsOf(labels, reference, reference)) x
    // conventions, prepared now.
    PyPrepared prepare(const PyVolume& reference, const py::object& labels,
                       const std::vector<std::string>& conventions, int connectivity, bool hostExtraction) {
        const std::vector<Convention> list = checkedConventions(conventions, {}, connectivity, 0.0);
        const std::vector<Selection> rows = selectionsOf(labels, *reference.volume, *reference.volume);
        PyPrepared out{reference, this, {}};
        std::optional<Error> error;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            for (const Selection& row : rows) {
                for (Convention c : list) {
                    if (!error)
                        error = prepared(out, row.select, options(c, {}, connectivity, 0.0, hostExtraction))
                                    .error;
                }
            }
        }
        if (error) raise(*error);
        return out;
    }

    // compare() with a prepared reference as A (or, referenceIsB, as B: the
    // rows of compare(other, reference)).
    py::list comparePrepared(PyPrepared& reference, const PyVolume& other, bool referenceIsB,
                             const py::object& labels, const std::vector<std::string>& conventions,
                             const std::vector<double>& percentiles, int connectivity, double tolerance,
                             bool hostExtraction) {
        if (reference.owner != this)
            throw py::value_error(
                "this PreparedReference was prepared on another MaskEngine: compare it there");
        const std::vector<Convention> list =
            checkedConventions(conventions, percentiles, connectivity, tolerance);
        const masks::Volume& ref = *reference.volume.volume;
        auto e = referenceIsB ? masks::checkSameGrid(*other.volume, ref)
                              : masks::checkSameGrid(ref, *other.volume);
        if (e) raise(*e);
        const std::vector<Selection> rows = selectionsOf(labels, ref, *other.volume);
        const Settings settings{percentiles, connectivity, tolerance, hostExtraction};
        return rowsOf(rows, list, settings, [&](const Selection& row, const masks::MaskOptions& mo) {
            Prepared p = prepared(reference, row.select, mo);
            if (p.error) return Result<MaskResult>(*p.error);
            Result<MaskResult> r = masks::compareMasks(*m_engine, *p.set, *other.volume, row.select, mo);
            if (r && referenceIsB) return Result<MaskResult>(swapped(std::move(*r)));
            return r;
        });
    }

    void close() {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(m_mutex);
        m_engine.reset();
    }

    // The getters release the GIL before the lock: compare() takes the GIL
    // back between rows while it holds the lock.
    bool closed() {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(m_mutex);
        return !m_engine;
    }

    std::string deviceName() {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_engine) throw std::invalid_argument("this MaskEngine is closed");
        return m_engine->engine.deviceName();
    }

    std::string backend() {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_engine) throw std::invalid_argument("this MaskEngine is closed");
        return backendName(m_engine->engine.backend());
    }

    bool deviceExtraction() {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_engine && m_engine->boundaryPass != nullptr;
    }

private:
    struct Settings {
        std::vector<double> percentiles;
        int connectivity = 0;
        double tolerance = 1.0;
        bool hostExtraction = false;
    };
    using CompareOne = std::function<Result<MaskResult>(const Selection&, const masks::MaskOptions&)>;

    static std::vector<Convention> checkedConventions(const std::vector<std::string>& conventions,
                                                      const std::vector<double>& percentiles,
                                                      int connectivity, double tolerance) {
        if (conventions.empty()) throw py::value_error("no convention given");
        std::vector<Convention> list;
        for (const std::string& name : conventions) list.push_back(conventionFrom(name));
        for (double p : percentiles)
            if (!(p >= 0.0 && p <= 100.0))
                throw py::value_error("percentile outside [0, 100]: " + std::string(py::str(py::float_(p))));
        if (connectivity != 0 && connectivity != 6 && connectivity != 18 && connectivity != 26)
            throw py::value_error("connectivity must be 6, 18 or 26 (or None: 6)");
        if (!(tolerance >= 0.0 && std::isfinite(tolerance)))
            throw py::value_error("tolerance must be a finite number >= 0 (mm)");
        return list;
    }

    masks::MaskOptions options(Convention c, const std::vector<double>& percentiles, int connectivity,
                               double tolerance, bool hostExtraction) const {
        masks::MaskOptions mo;
        mo.convention = c;
        mo.connectivity = connectivity;
        mo.percentiles = percentiles;
        mo.tolerance = tolerance;
        mo.threads = m_threads;
        mo.hostExtraction = hostExtraction;
        return mo;
    }

    // The reference's set for (select, options), prepared on first use. Holds m_mutex.
    struct Prepared {
        const masks::PreparedReference* set = nullptr;
        std::optional<Error> error;
    };
    Prepared prepared(PyPrepared& reference, masks::LabelSelect select, const masks::MaskOptions& mo) {
        if (!m_engine) return {nullptr, Error{ErrorCode::kInvalidArgument, "this MaskEngine is closed"}};
        const PyPrepared::Key key = PyPrepared::key(select, mo);
        auto it = reference.sets.find(key);
        if (it == reference.sets.end()) {
            Result<masks::PreparedReference> p =
                masks::prepareReference(*m_engine, *reference.volume.volume, select, mo);
            if (!p) return {nullptr, p.error()};
            it = reference.sets.emplace(key, std::move(*p)).first;
        }
        return {&it->second, std::nullopt};
    }

    // compareOne(row, options) per (label, convention), label-major, without
    // the GIL (taken back between rows for Ctrl-C); the rows as dicts.
    py::list rowsOf(const std::vector<Selection>& rows, const std::vector<Convention>& list,
                    const Settings& s, const CompareOne& compareOne) {
        std::vector<std::pair<std::string, MaskResult>> results;
        std::optional<Error> error;
        std::optional<py::error_already_set> interrupt;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            for (size_t i = 0; i < rows.size() * list.size() && !error && !interrupt; ++i) {
                const Selection& row = rows[i / list.size()];
                if (!m_engine) {
                    error = Error{ErrorCode::kInvalidArgument, "this MaskEngine is closed"};
                    break;
                }
                const Convention c = list[i % list.size()];
                Result<MaskResult> r =
                    compareOne(row, options(c, s.percentiles, s.connectivity, s.tolerance, s.hostExtraction));
                if (!r) {
                    error = r.error();
                    error->message = "label " + row.name + ": " + error->message;
                    break;
                }
                results.emplace_back(row.name, std::move(*r));
                py::gil_scoped_acquire gil;  // Ctrl-C between rows
                if (PyErr_CheckSignals() != 0) interrupt.emplace();
            }
        }
        if (interrupt) throw std::move(*interrupt);
        if (error) raise(*error);
        py::list out;
        for (const auto& [name, r] : results) out.append(rowDict(name, r));
        return out;
    }

    std::mutex m_mutex;
    std::optional<masks::MaskEngine> m_engine;
    int m_threads = 0;
};

}  // namespace

void bindMasks(py::module_& m) {
    py::class_<PyVolume>(m, "_MaskVolume", "A label volume: labels copied once, i fastest, with its affine.")
        .def_property_readonly("name", [](const PyVolume& v) { return v.volume->path; })
        .def_property_readonly("shape",
                               [](const PyVolume& v) {
                                   return py::make_tuple(v.volume->dims[0], v.volume->dims[1],
                                                         v.volume->dims[2]);
                               })
        .def_property_readonly("affine", [](const PyVolume& v) { return affineOf(*v.volume); })
        .def_property_readonly("spacing",
                               [](const PyVolume& v) {
                                   const glm::dvec3 s = v.volume->spacing();
                                   return py::make_tuple(s.x, s.y, s.z);
                               })
        .def_property_readonly("transform", [](const PyVolume& v) { return v.volume->transform; })
        .def("nonzero_voxels",
             [](const PyVolume& v) {
                 py::gil_scoped_release release;
                 return masks::nonzeroVoxels(*v.volume);
             })
        .def("labels_present", [](const PyVolume& v) {
            std::vector<int32_t> out;
            {
                py::gil_scoped_release release;
                out = masks::labelsPresent(*v.volume);
            }
            return out;
        });
    m.def("_mask_volume", &volumeOf, py::arg("array"), py::arg("affine"), py::arg("name"),
          py::arg("transform"),
          "A _MaskVolume of a 3-D label array (C or Fortran contiguous, native byte order) and its 4x4 "
          "voxel-to-world affine (rthdist.MaskVolume converts its inputs first).");
    m.def(
        "_one_shot_backend",
        [](uint64_t points, const std::string& backend, std::optional<int> device, int threads,
           bool validation) {
            return std::string(
                backendName(oneShotBackendFor(points, engineOptions(backend, device, threads, validation))));
        },
        py::arg("points"), py::arg("backend"), py::arg("device"), py::arg("threads"), py::arg("validation"),
        "The backend a one-shot call of `points` in all opens (rthdist::oneShotBackendFor): 'cpu' for a "
        "small pair under 'auto' with no device named and no validation, else the backend asked for.");
    m.def(
        "_one_shot_mask_backend",
        [](const PyVolume& a, const PyVolume& b, const std::vector<std::string>& names,
           const std::string& backend, std::optional<int> device, int threads, bool validation) {
            std::vector<Convention> conventions;
            for (const std::string& name : names) {
                Convention c;
                if (!masks::parseConvention(name, c))
                    throw py::value_error("unknown convention '" + name + "' (" + masks::conventionNames() +
                                          ")");
                conventions.push_back(c);
            }
            const Options options = engineOptions(backend, device, threads, validation);
            Backend chosen;
            {
                py::gil_scoped_release release;
                chosen = masks::oneShotMaskBackend(options, *a.volume, *b.volume, conventions);
            }
            return std::string(backendName(chosen));
        },
        py::arg("a"), py::arg("b"), py::arg("conventions"), py::arg("backend"), py::arg("device"),
        py::arg("threads"), py::arg("validation"),
        "The backend a one-shot comparison of two _MaskVolumes opens (masks::oneShotMaskBackend).");
    m.def("_conventions", [] {
        std::vector<std::string> out;
        for (Convention c : masks::kAllConventions) out.push_back(masks::conventionName(c));
        return out;
    });

    py::class_<PyPrepared>(m, "_PreparedReference",
                           "A reference prepared on one _MaskEngine (rthdist.PreparedReference).")
        .def_property_readonly("volume", [](const PyPrepared& p) { return p.volume; })
        .def("sets", [](const PyPrepared& p) {
            py::list out;
            for (const auto& [key, set] : p.sets) {
                py::dict d;
                d["label"] =
                    std::get<1>(key) ? py::object(py::none()) : py::object(py::int_(std::get<0>(key)));
                d["convention"] = masks::conventionName(set.convention());
                d["connectivity"] = set.connectivity();
                d["points"] = set.points();
                d["selected_voxels"] = set.selectedVoxels();
                d["host_bytes"] = set.hostBytes();
                d["device_bytes"] = set.deviceBytes();
                d["prepare_ms"] = set.prepareMs();
                d["extraction"] = set.extraction();
                out.append(d);
            }
            return out;
        });

    py::class_<PyMaskEngine>(m, "_MaskEngine",
                             "The masks' Engine and boundary pass kept between calls (rthdist.MaskEngine).")
        .def(py::init<const std::string&, std::optional<int>, int, bool, bool>(), py::arg("backend"),
             py::arg("device"), py::arg("threads"), py::arg("validation"), py::arg("device_extraction"))
        .def("compare", &PyMaskEngine::compare, py::arg("a"), py::arg("b"), py::arg("labels"),
             py::arg("conventions"), py::arg("percentiles"), py::arg("connectivity"), py::arg("tolerance"),
             py::arg("host_extraction"))
        .def("prepare", &PyMaskEngine::prepare, py::arg("reference"), py::arg("labels"),
             py::arg("conventions"), py::arg("connectivity"), py::arg("host_extraction"))
        .def("compare_prepared", &PyMaskEngine::comparePrepared, py::arg("reference"), py::arg("other"),
             py::arg("reference_is_b"), py::arg("labels"), py::arg("conventions"), py::arg("percentiles"),
             py::arg("connectivity"), py::arg("tolerance"), py::arg("host_extraction"))
        .def("close", &PyMaskEngine::close)
        .def_property_readonly("closed", &PyMaskEngine::closed)
        .def_property_readonly("device", &PyMaskEngine::deviceName)
        .def_property_readonly("backend", &PyMaskEngine::backend)
        .def_property_readonly("device_extraction", &PyMaskEngine::deviceExtraction);
}

}  // namespace rthdist::python
