#include "errors.hpp"

namespace py = pybind11;

namespace rthdist::python {
namespace {

// Owned by the module (its attributes); borrowed here for the module's life.
PyObject* g_error = nullptr;
PyObject* g_deviceError = nullptr;
PyObject* g_outOfMemoryError = nullptr;
PyObject* g_internalError = nullptr;
PyObject* g_cancelledError = nullptr;

PyObject* newException(py::module_& m, const char* name, PyObject* base, const char* doc) {
    const std::string qualified = std::string("rthdist.") + name;
    PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
    if (type == nullptr) throw py::error_already_set();
    m.add_object(name, py::handle(type));
    return type;
}

}  // namespace

void bindErrors(py::module_& m) {
    g_error =
        newException(m, "Error", PyExc_RuntimeError, "Base of rthdist's runtime errors (a RuntimeError).");
    g_deviceError =
        newException(m, "DeviceError", g_error,
                     "No Vulkan device offers what the chosen backend needs (ErrorCode::kNoDevice).");
    g_outOfMemoryError = newException(m, "OutOfMemoryError", g_error,
                                      "The inputs do not fit the device or host memory (kOutOfMemory).");
    g_internalError =
        newException(m, "InternalError", g_error, "A Vulkan call failed or a self-check broke (kInternal).");
    g_cancelledError = newException(m, "CancelledError", g_error, "The call was cancelled (kCancelled).");
}

void raise(const Error& error) {
    PyObject* type = g_internalError;
    switch (error.code) {
        case ErrorCode::kInvalidArgument:
        case ErrorCode::kBadInput: type = PyExc_ValueError; break;
        case ErrorCode::kNoDevice: type = g_deviceError; break;
        case ErrorCode::kOutOfMemory: type = g_outOfMemoryError; break;
        case ErrorCode::kInternal: type = g_internalError; break;
        case ErrorCode::kCancelled: type = g_cancelledError; break;
    }
    PyErr_SetString(type, error.message.c_str());
    throw py::error_already_set();
}

}  // namespace rthdist::python
