#include "engine.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "errors.hpp"
#include "points.hpp"
#include "result.hpp"
#include "rthdist/rthdist.hpp"
#include "surface.hpp"

namespace py = pybind11;

namespace rthdist::python {
namespace {

Backend backendFrom(const std::string& name) {
    Backend b;
    if (!parseBackend(name, b)) {
        throw py::value_error("unknown backend '" + name +
                              "' (expected 'auto', 'ray-query', 'rt-pipeline' or 'cpu')");
    }
    return b;
}

}  // namespace

Options engineOptions(const std::string& backend, std::optional<int> device, int threads, bool validation) {
    Options o;
    o.backend = backendFrom(backend);
    if (device && (*device < 0 || *device > 1023))
        throw py::value_error("device must be in 0..1023 (or None)");
    o.deviceIndex = device.value_or(-1);
    if (threads < 0 || threads > 1024) throw py::value_error("threads must be in 0..1024 (0 = all)");
    o.threads = threads;
    o.validation = validation;
    return o;
}

namespace {

// The settings of one call, checked against the CLI's ranges.
struct CallSettings {
    int bits = 0;
    bool directed = false;
    bool perPoint = false;
    double radiusGrowth = 2.0;

    void check() const {
        if (bits < 0 || bits > 8) throw py::value_error("bits must be in 0..8 (0 = from the data)");
        if (!(radiusGrowth >= 1.1 && radiusGrowth <= 16.0))
            throw py::value_error("radius_growth must be in 1.1..16");
    }
    bool operator==(const CallSettings&) const = default;
};

Options optionsFrom(const Options& engine, const CallSettings& call) {
    Options o = engine;
    o.bits = call.bits;
    o.directedOnly = call.directed;
    o.perPointDistances = call.perPoint;
    o.radiusGrowth = float(call.radiusGrowth);
    return o;
}

// Progress and cancellation of one call while the GIL is released. report()
// runs on the calling thread (the library's contract for progress).
class CallMonitor {
public:
    explicit CallMonitor(py::object progress) : m_progress(std::move(progress)) {}

    void report(const char* stage, double fraction) {
        py::gil_scoped_acquire gil;
        if (m_pending) return;
        if (PyErr_CheckSignals() != 0) {  // Ctrl-C: KeyboardInterrupt is now set
            fail();
            return;
        }
        if (m_progress.is_none()) return;
        try {
            m_progress(stage, fraction);
        } catch (py::error_already_set& e) {
            m_pending.emplace(std::move(e));
            m_cancel.store(true);
        }
    }

    const std::atomic<bool>* cancelFlag() const { return &m_cancel; }

    // After the call, with the GIL held: a pending exception wins over the result.
    void raisePending() {
        if (!m_pending) return;
        py::error_already_set e = std::move(*m_pending);
        m_pending.reset();
        throw e;
    }

private:
    void fail() {
        m_pending.emplace();  // fetches the current Python error
        m_cancel.store(true);
    }

    py::object m_progress;
    std::optional<py::error_already_set> m_pending;
    std::atomic<bool> m_cancel{false};
};

std::unique_ptr<PyResult> wrap(HausdorffResult&& result, const py::array& a, const py::array& b,
                               bool perPoint) {
    auto out = std::make_unique<PyResult>();
    out->result = std::move(result);
    if (perPoint) {
        out->a = a;
        out->b = b;
    }
    return out;
}

std::unique_ptr<PyResult> hausdorffOnce(const py::array& a, const py::array& b, bool directed, bool perPoint,
                                        const std::string& backend, std::optional<int> device, int bits,
                                        double radiusGrowth, int threads, bool validation,
                                        py::object progress) {
    const CallSettings call{bits, directed, perPoint, radiusGrowth};
    call.check();
    Options options = optionsFrom(engineOptions(backend, device, threads, validation), call);
    const PointView va = viewOf(a, "a");
    const PointView vb = viewOf(b, "b");
    CallMonitor monitor(std::move(progress));
    options.progress = [&monitor](const char* stage, double fraction) { monitor.report(stage, fraction); };
    options.cancel = monitor.cancelFlag();
    std::optional<Result<HausdorffResult>> r;
    {
        py::gil_scoped_release release;
        const PointCopy ca(va), cb(vb);  // another thread's writes cannot reach the call (points.hpp)
        r.emplace(hausdorff(ca.view(), cb.view(), options));
    }
    monitor.raisePending();
    return wrap(valueOrRaise(std::move(*r)), a, b, perPoint);
}

// A set prepared by a PyEngine (Engine::prepare), with the array it came
// from (statistics of per-point results read its bounding box).
struct PyPrepared {
    PreparedSet set;
    const void* engine;  // the PyEngine that prepared it (identity only)
    py::array source;
};

// An Engine for Python: the device and pipelines live until close() (or the
// end of a `with` block); calls are serialized by m_mutex.
class PyEngine {
public:
    PyEngine(const std::string& backend, std::optional<int> device, int threads, bool validation,
             int64_t memoryBudget, const std::vector<int>& devices) {
        Options options = engineOptions(backend, device, threads, validation);
        if (memoryBudget < 0) throw py::value_error("memory_budget must be >= 0 bytes (0 = automatic)");
        options.memoryBudget = uint64_t(memoryBudget);
        for (int d : devices)
            if (d < 0 || d > 1023) throw py::value_error("devices must be device indices in 0..1023");
        options.devices = devices;
        std::optional<Result<Engine>> engine;
        {
            py::gil_scoped_release release;
            engine.emplace(Engine::create(static_cast<const EngineOptions&>(options)));
        }
        m_engine.emplace(valueOrRaise(std::move(*engine)));
    }

    // a and b: checked arrays or PyPrepared sets of this Engine. A mix
    // prepares the array for this call in the prepared set's frame.
    std::unique_ptr<PyResult> hausdorff(const py::object& a, const py::object& b, bool directed,
                                        bool perPoint, int bits, double radiusGrowth, py::object progress) {
        const CallSettings settings{bits, directed, perPoint, radiusGrowth};
        settings.check();
        const PyPrepared* pa = preparedOf(a, "a");
        const PyPrepared* pb = preparedOf(b, "b");
        const py::array arrayA = pa ? pa->source : a.cast<py::array>();
        const py::array arrayB = pb ? pb->source : b.cast<py::array>();
        const PointView va = pa ? PointView{} : viewOf(arrayA, "a");
        const PointView vb = pb ? PointView{} : viewOf(arrayB, "b");
        CallMonitor monitor(std::move(progress));
        CallOptions call = callOptions(settings, monitor);
        std::optional<Result<HausdorffResult>> r;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            const PointCopy ca(va), cb(vb);  // of the arrays only (a prepared set has its own copy)
            if (!m_engine) {
                r.emplace(Error{ErrorCode::kInvalidArgument, "this Engine is closed"});
            } else if (pa == nullptr && pb == nullptr) {
                r.emplace(m_engine->compute(ca.view(), cb.view(), call));
            } else {
                r.emplace(computePrepared(pa, ca.view(), pb, cb.view(), call));
            }
        }
        monitor.raisePending();
        return wrap(valueOrRaise(std::move(*r)), arrayA, arrayB, perPoint);
    }

    // h(points, surface) on this Engine (Engine::hausdorffToSurface): its
    // device, and on the CPU backend its last mesh's tree, kept.
    py::dict hausdorffToSurface(const py::array& points, const py::array& vertices, const py::array& faces,
                                bool perPoint) {
        const PointView vp = viewOf(points, "points"), vv = viewOf(vertices, "vertices");
        const std::vector<uint32_t> f = facesOf(faces, vv.count, "faces");
        SurfaceCallOptions call;
        call.perPointDistances = perPoint;
        std::optional<Result<SurfaceResult>> r;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            const PointCopy cp(vp), cv(vv);
            if (!m_engine) {
                r.emplace(Error{ErrorCode::kInvalidArgument, "this Engine is closed"});
            } else {
                r.emplace(m_engine->hausdorffToSurface(cp.view(), MeshView{cv.view(), f}, call));
            }
        }
        return surfaceResultDict(valueOrRaise(std::move(*r)), perPoint);
    }

    std::unique_ptr<PyPrepared> prepare(const py::array& points, int bits,
                                        std::optional<std::array<double, 3>> origin) {
        if (bits < 0 || bits > 8) throw py::value_error("bits must be in 0..8 (0 = from the data)");
        const PointView view = viewOf(points, "points");
        PrepareOptions options;
        options.bits = bits;
        if (origin) options.origin = glm::dvec3((*origin)[0], (*origin)[1], (*origin)[2]);
        std::optional<Result<PreparedSet>> r;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            const PointCopy copy(view);  // the set keeps copies of its own; this one is checked first
            if (!m_engine) {
                r.emplace(Error{ErrorCode::kInvalidArgument, "this Engine is closed"});
            } else {
                r.emplace(m_engine->prepare(copy.view(), options));
            }
        }
        return std::make_unique<PyPrepared>(PyPrepared{valueOrRaise(std::move(*r)), this, points});
    }

    // H of every pair (i, j) of `sets` (PyPrepared of this Engine) in one
    // call; the first failing pair's error is raised.
    py::list hausdorffMany(const std::vector<py::object>& sets,
                           const std::vector<std::pair<size_t, size_t>>& pairs, bool directed, bool perPoint,
                           int bits, double radiusGrowth, py::object progress) {
        const CallSettings settings{bits, directed, perPoint, radiusGrowth};
        settings.check();
        std::vector<PreparedSet> prepared;
        std::vector<const PyPrepared*> owners;
        for (size_t i = 0; i < sets.size(); ++i) {
            const PyPrepared* p = preparedOf(sets[i], "sets");
            if (p == nullptr) throw py::value_error("sets[" + std::to_string(i) + "] is not a PreparedSet");
            prepared.push_back(p->set);
            owners.push_back(p);
        }
        std::vector<PairRef> refs;
        for (const auto& [i, j] : pairs) {
            if (i >= sets.size() || j >= sets.size()) throw py::value_error("pairs: index past the sets");
            refs.push_back({i, j});
        }
        CallMonitor monitor(std::move(progress));
        CallOptions call = callOptions(settings, monitor);
        std::vector<Result<HausdorffResult>> results;
        bool closed = false;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            closed = !m_engine;
            if (!closed) results = m_engine->computeBatch(prepared, refs, call);
        }
        monitor.raisePending();
        if (closed) throw py::value_error("this Engine is closed");
        py::list out;
        for (size_t k = 0; k < results.size(); ++k) {
            auto r = wrap(valueOrRaise(std::move(results[k])), owners[refs[k].a]->source,
                          owners[refs[k].b]->source, perPoint);
            out.append(py::cast(std::move(r)));
        }
        return out;
    }

    void close() {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(m_mutex);
        m_engine.reset();
    }

    bool closed() {
        std::lock_guard<std::mutex> lock(m_mutex);
        return !m_engine;
    }

    std::string deviceName() {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_engine) throw py::value_error("this Engine is closed");
        return m_engine->deviceName();
    }

    std::string backend() {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_engine) throw py::value_error("this Engine is closed");
        return backendName(m_engine->backend());
    }

private:
    const PyPrepared* preparedOf(const py::object& o, const char* name) const {
        if (!py::isinstance<PyPrepared>(o)) return nullptr;
        const PyPrepared* p = o.cast<const PyPrepared*>();
        if (p->engine != this) throw py::value_error(std::string(name) + ": prepared by another Engine");
        return p;
    }

    static CallOptions callOptions(const CallSettings& settings, CallMonitor& monitor) {
        CallOptions call;
        call.bits = settings.bits;
        call.directedOnly = settings.directed;
        call.perPointDistances = settings.perPoint;
        call.radiusGrowth = float(settings.radiusGrowth);
        call.progress = [&monitor](const char* stage, double fraction) { monitor.report(stage, fraction); };
        call.cancel = monitor.cancelFlag();
        return call;
    }

    // A prepared set against an array: the array is prepared for this call
    // in the prepared set's frame (so both indexes are reused as they are).
    Result<HausdorffResult> computePrepared(const PyPrepared* pa, PointView va, const PyPrepared* pb,
                                            PointView vb, const CallOptions& call) {
        std::optional<PreparedSet> tmpA, tmpB;
        if (pa == nullptr || pb == nullptr) {
            const PyPrepared* known = pa ? pa : pb;
            PrepareOptions options;
            options.bits = call.bits;
            options.origin = known->set.origin();
            Result<PreparedSet> t = m_engine->prepare(pa ? vb : va, options);
            if (!t) return t.error();
            (pa ? tmpB : tmpA).emplace(std::move(t).value());
        }
        return m_engine->compute(pa ? pa->set : *tmpA, pb ? pb->set : *tmpB, call);
    }

    std::mutex m_mutex;
    std::optional<Engine> m_engine;
};

}  // namespace

void bindEngine(py::module_& m) {
    m.def("_hausdorff", &hausdorffOnce, py::arg("a"), py::arg("b"), py::arg("directed"), py::arg("per_point"),
          py::arg("backend"), py::arg("device"), py::arg("bits"), py::arg("radius_growth"),
          py::arg("threads"), py::arg("validation"), py::arg("progress"),
          "One-shot H(A, B) of two checked arrays (rthdist.hausdorff converts its inputs first).");

    py::class_<PyPrepared>(m, "PreparedSet",
                           "A point set prepared once by an Engine (Engine.prepare): its frame, scale and "
                           "index, reused by every call that gets it.")
        .def_property_readonly("size", [](const PyPrepared& p) { return p.set.size(); })
        .def("__len__", [](const PyPrepared& p) { return p.set.size(); })
        .def_property_readonly(
            "bits", [](const PyPrepared& p) { return p.set.bits(); }, "bit count of its index grid")
        .def_property_readonly(
            "origin",
            [](const PyPrepared& p) {
                const glm::dvec3 o = p.set.origin();
                return py::make_tuple(o.x, o.y, o.z);
            },
            "its frame: subtracted before the float search (0 for float32 data)")
        .def_property_readonly("device_bytes", [](const PyPrepared& p) { return p.set.deviceBytes(); })
        .def_property_readonly("host_bytes", [](const PyPrepared& p) { return p.set.hostBytes(); })
        .def_property_readonly(
            "points", [](const PyPrepared& p) { return p.source; }, "the array it was prepared from")
        .def("__repr__", [](const PyPrepared& p) {
            return "PreparedSet(size=" + std::to_string(p.set.size()) +
                   ", bits=" + std::to_string(p.set.bits()) + ")";
        });

    py::class_<PyEngine>(m, "_Engine", "A device and its pipelines kept between calls (rthdist.Engine).")
        .def(py::init<const std::string&, std::optional<int>, int, bool, int64_t, const std::vector<int>&>(),
             py::arg("backend"), py::arg("device"), py::arg("threads"), py::arg("validation"),
             py::arg("memory_budget"), py::arg("devices"))
        .def("hausdorff", &PyEngine::hausdorff, py::arg("a"), py::arg("b"), py::arg("directed"),
             py::arg("per_point"), py::arg("bits"), py::arg("radius_growth"), py::arg("progress"))
        .def("prepare", &PyEngine::prepare, py::arg("points"), py::arg("bits"), py::arg("origin"))
        .def("hausdorff_to_surface", &PyEngine::hausdorffToSurface, py::arg("points"), py::arg("vertices"),
             py::arg("faces"), py::arg("per_point"))
        .def("hausdorff_many", &PyEngine::hausdorffMany, py::arg("sets"), py::arg("pairs"),
             py::arg("directed"), py::arg("per_point"), py::arg("bits"), py::arg("radius_growth"),
             py::arg("progress"))
        .def("close", &PyEngine::close)
        .def_property_readonly("closed", &PyEngine::closed)
        .def_property_readonly("device", &PyEngine::deviceName)
        .def_property_readonly("backend", &PyEngine::backend);
}

}  // namespace rthdist::python
