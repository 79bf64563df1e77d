#include "engine.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "errors.hpp"
#include "points.hpp"
#include "result.hpp"
#include "rthdist/rthdist.hpp"

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

// The device part of Options (backend, device, threads, validation).
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
    std::optional<Result<HausdorffResult>> r;
    {
        py::gil_scoped_release release;
        r.emplace(hausdorff(va, vb, options));
    }
    monitor.raisePending();
    return wrap(valueOrRaise(std::move(*r)), a, b, perPoint);
}

// An Engine for Python: the device and pipelines live until close() (or the
// end of a `with` block); calls are serialized by m_mutex.
class PyEngine {
public:
    PyEngine(const std::string& backend, std::optional<int> device, int threads, bool validation)
        : m_options(engineOptions(backend, device, threads, validation)) {
        Result<Engine> engine = [&] {
            py::gil_scoped_release release;
            return create(CallSettings{});
        }();
        m_engine.emplace(valueOrRaise(std::move(engine)));
    }

    std::unique_ptr<PyResult> hausdorff(const py::array& a, const py::array& b, bool directed, bool perPoint,
                                        int bits, double radiusGrowth, py::object progress) {
        const CallSettings call{bits, directed, perPoint, radiusGrowth};
        call.check();
        const PointView va = viewOf(a, "a");
        const PointView vb = viewOf(b, "b");
        CallMonitor monitor(std::move(progress));
        std::optional<Result<HausdorffResult>> r;
        {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(m_mutex);
            if (!m_engine) {
                r.emplace(Error{ErrorCode::kInvalidArgument, "this Engine is closed"});
            } else {
                r.emplace(computeLocked(va, vb, call, monitor));
            }
        }
        monitor.raisePending();
        return wrap(valueOrRaise(std::move(*r)), a, b, perPoint);
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
    // The settings of a call are fixed when an Engine is created (this
    // release's Engine::create(Options)): a call with other settings creates
    // the engine again. The progress of every call goes through m_monitor.
    Result<Engine> create(const CallSettings& call) {
        Options options = optionsFrom(m_options, call);
        options.progress = [this](const char* stage, double fraction) {
            if (m_monitor != nullptr) m_monitor->report(stage, fraction);
        };
        Result<Engine> engine = Engine::create(options);
        if (engine) m_call = call;
        return engine;
    }

    Result<HausdorffResult> computeLocked(PointView a, PointView b, const CallSettings& call,
                                          CallMonitor& monitor) {
        if (!(call == m_call)) {
            m_engine.reset();
            Result<Engine> engine = create(call);
            if (!engine) return engine.error();
            m_engine.emplace(std::move(engine).value());
        }
        m_monitor = &monitor;
        Result<HausdorffResult> r = m_engine->compute(a, b);
        m_monitor = nullptr;
        return r;
    }

    Options m_options;  // the device part
    CallSettings m_call;
    std::mutex m_mutex;
    std::optional<Engine> m_engine;
    CallMonitor* m_monitor = nullptr;
};

}  // namespace

void bindEngine(py::module_& m) {
    m.def("_hausdorff", &hausdorffOnce, py::arg("a"), py::arg("b"), py::arg("directed"), py::arg("per_point"),
          py::arg("backend"), py::arg("device"), py::arg("bits"), py::arg("radius_growth"),
          py::arg("threads"), py::arg("validation"), py::arg("progress"),
          "One-shot H(A, B) of two checked arrays (rthdist.hausdorff converts its inputs first).");

    py::class_<PyEngine>(m, "_Engine", "A device and its pipelines kept between calls (rthdist.Engine).")
        .def(py::init<const std::string&, std::optional<int>, int, bool>(), py::arg("backend"),
             py::arg("device"), py::arg("threads"), py::arg("validation"))
        .def("hausdorff", &PyEngine::hausdorff, py::arg("a"), py::arg("b"), py::arg("directed"),
             py::arg("per_point"), py::arg("bits"), py::arg("radius_growth"), py::arg("progress"))
        .def("close", &PyEngine::close)
        .def_property_readonly("closed", &PyEngine::closed)
        .def_property_readonly("device", &PyEngine::deviceName)
        .def_property_readonly("backend", &PyEngine::backend);
}

}  // namespace rthdist::python
