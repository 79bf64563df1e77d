#include "io.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "errors.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"

namespace py = pybind11;

namespace rthdist::python {
namespace {

// An (N, 3) array over the vector's memory; the array owns the vector.
template <class Vec>
py::array adopt(io::PointArray<Vec>&& points) {
    using Scalar = typename Vec::value_type;
    static_assert(sizeof(Vec) == 3 * sizeof(Scalar));
    auto* owned = new io::PointArray<Vec>(std::move(points));
    py::capsule owner(owned, [](void* p) { delete static_cast<io::PointArray<Vec>*>(p); });
    const auto n = py::ssize_t(owned->size());
    return py::array_t<Scalar>({n, py::ssize_t(3)}, {py::ssize_t(sizeof(Vec)), py::ssize_t(sizeof(Scalar))},
                               reinterpret_cast<const Scalar*>(owned->data()), owner);
}

py::array load(const std::string& path, const std::vector<int>& lasClasses) {
    io::LoadOptions options;
    options.lasClasses = lasClasses;
    std::optional<Result<io::PointCloud>> cloud;
    {
        py::gil_scoped_release release;
        cloud.emplace(io::loadPointCloud(path, options));
    }
    io::PointCloud c = valueOrRaise(std::move(*cloud));
    if (c.scalar == Scalar::kFloat64) return adopt(std::move(c.doubles));
    return adopt(std::move(c.floats));
}

py::list devices() {
    const std::vector<DeviceInfo> list = valueOrRaise(listDevices());
    py::list out;
    for (const DeviceInfo& d : list) {
        py::dict e;
        e["index"] = d.index;
        e["name"] = d.name;
        e["type"] = d.type;
        e["driver"] = d.driver;
        e["ray_query"] = d.rayQuery;
        e["rt_pipeline"] = d.rtPipeline;
        e["missing"] = d.missing;
        py::dict limits;
        for (const auto& [key, value] : d.limits) limits[py::str(key)] = value;
        e["limits"] = limits;
        out.append(e);
    }
    return out;
}

}  // namespace

void bindIo(py::module_& m) {
    m.def("_load", &load, py::arg("path"), py::arg("las_classes"),
          "The points of a file (rthdist/io.hpp formats) in its precision; rthdist.load wraps it.");
    m.def("list_devices", &devices,
          "Every Vulkan device as a dict: index, name, type, driver, ray_query, rt_pipeline, missing "
          "(why a backend is unusable), limits.");
}

}  // namespace rthdist::python
