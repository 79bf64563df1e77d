// rthdist Python module — the entry points that compute: the one-shot
// hausdorff(), the Engine class (one device and its pipelines kept between
// calls; per-call settings, CallOptions) and its PreparedSets (a set indexed
// once, Engine::prepare, reused by any number of calls and batches).
//
// Every call releases the GIL while the library works, so other Python
// threads run (each with its own Engine: an Engine serializes its calls
// behind a mutex, it is never used by two threads at once). The library's
// progress callback re-acquires the GIL, checks for signals (Ctrl-C in the
// main thread) and calls the user's progress callable; a KeyboardInterrupt or
// an exception from the callable sets the call's cancel flag
// (CallOptions::cancel: the library stops at its next check) and is raised
// when the call returns.
#pragma once

#include <pybind11/pybind11.h>

#include <optional>
#include <string>

#include "rthdist/rthdist.hpp"

namespace rthdist::python {

// The device part of Options (backend, device, threads, validation), checked
// against the CLI's ranges (ValueError); also the masks' engines (masks.cpp).
Options engineOptions(const std::string& backend, std::optional<int> device, int threads, bool validation);

void bindEngine(pybind11::module_& m);

}  // namespace rthdist::python
