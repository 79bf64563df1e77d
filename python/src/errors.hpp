// rthdist Python module — the library's Error values as Python exceptions.
//
// ValueError: bad arrays or options (kInvalidArgument) and bad files
// (kBadInput). rthdist.Error (a RuntimeError) and its subclasses for the rest:
// DeviceError (kNoDevice), OutOfMemoryError (kOutOfMemory), InternalError
// (kInternal), CancelledError (kCancelled without a pending KeyboardInterrupt).
#pragma once

#include <pybind11/pybind11.h>

#include "rthdist/result.hpp"

namespace rthdist::python {

// Creates the exception classes as attributes of `m`.
void bindErrors(pybind11::module_& m);

// Sets the Python exception for `error` and throws pybind11::error_already_set.
[[noreturn]] void raise(const Error& error);

// Unwraps a Result or raises its error.
template <class T>
T valueOrRaise(Result<T>&& result) {
    if (!result) raise(result.error());
    return std::move(result).value();
}

}  // namespace rthdist::python
