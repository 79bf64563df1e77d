#include "points.hpp"

#include <cstring>
#include <memory>
#include <string>

namespace py = pybind11;

namespace rthdist::python {

PointView viewOf(const py::array& array, const char* name) {
    auto fail = [name](const std::string& why) -> PointView {
        throw py::value_error(std::string(name) + ": " + why);
    };
    Scalar scalar;
    if (array.dtype().is(py::dtype::of<float>())) {
        scalar = Scalar::kFloat32;
    } else if (array.dtype().is(py::dtype::of<double>())) {
        scalar = Scalar::kFloat64;
    } else {
        return fail("expected float32 or float64 points, got dtype " + std::string(py::str(array.dtype())));
    }
    if (array.ndim() != 2 || array.shape(1) < 3) {
        return fail("expected an (N, 3) array of points, got shape " +
                    std::string(py::str(array.attr("shape"))));
    }
    const py::ssize_t item = py::ssize_t(scalarBytes(scalar));
    const py::ssize_t rows = array.shape(0);
    py::ssize_t stride = array.strides(0);
    // NumPy leaves the strides of an empty or one-row axis arbitrary: no
    // other row is read (and nothing of an empty array).
    if (rows <= 1) stride = array.shape(1) * item;
    if ((rows > 0 && array.strides(1) != item) || stride < 3 * item || stride % item != 0) {
        return fail(
            "x, y, z must be adjacent and rows a positive multiple of the element size apart "
            "(strides " +
            std::string(py::str(array.attr("strides"))) + "); rthdist._points.as_points copies such arrays");
    }
    PointView view;
    view.data = array.data();
    view.count = size_t(rows);
    view.strideBytes = size_t(stride);
    view.scalar = scalar;
    return view;
}

PointCopy::PointCopy(const PointView& view) : m_view(view) {
    const size_t point = 3 * scalarBytes(view.scalar);
    if (view.count == 0 || view.data == nullptr) return;  // the library names what is wrong
    m_bytes = std::make_unique_for_overwrite<std::byte[]>(view.count * point);
    const auto* from = static_cast<const std::byte*>(view.data);
    if (view.strideBytes == point) {
        std::memcpy(m_bytes.get(), from, view.count * point);
    } else {
        for (size_t i = 0; i < view.count; ++i)
            std::memcpy(m_bytes.get() + i * point, from + i * view.strideBytes, point);
    }
    m_view.data = m_bytes.get();
    m_view.strideBytes = point;
}

}  // namespace rthdist::python
