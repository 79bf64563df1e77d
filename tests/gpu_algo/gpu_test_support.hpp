// GPU test helpers: the backend under test comes from RTHDIST_TEST_BACKEND
// (ctest runs the suites once per backend); every engine runs with the
// Khronos validation layer and every message it emits fails the test.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "rthdist/rthdist.hpp"

namespace rthdist::test {

inline Backend backendUnderTest() {
    const char* env = std::getenv("RTHDIST_TEST_BACKEND");
    Backend b = Backend::kRayQuery;
    if (env && !parseBackend(env, b)) ADD_FAILURE() << "unknown RTHDIST_TEST_BACKEND=" << env;
    return b;
}

// Small one-shot pairs take the RT path (Tuning::smallPairWork = 0): these
// tests are the RT search's, the small-pair scan has its own.
inline Options gpuOptions() {
    Options o;
    o.backend = backendUnderTest();
    o.validation = true;
    o.tuning = tuningFromEnvironment();
    o.tuning->smallPairWork = 0;
    // The rays stay under test: the sweep (few open queries against every
    // target) has suites of its own (GpuEngine.Sweep*).
    o.tuning->sweepWork = 0;
    return o;
}

// Creates an engine (from Options or EngineOptions) or records why none could be created.
template <class EngineOrCallOptions>
std::optional<Engine> makeEngine(const EngineOrCallOptions& o, std::string& whyNot) {
    auto e = Engine::create(o);
    if (!e) {
        whyNot = e.error().message;
        return std::nullopt;
    }
    return std::move(e.value());
}

}  // namespace rthdist::test

// Skips (CI turns any skip into a failure: lavapipe must be there) when no
// device can run the backend, with the rejection reasons.
#define RTHDIST_REQUIRE_ENGINE(engine, options)                       \
    std::string rthdist_why_;                                         \
    auto engine = ::rthdist::test::makeEngine(options, rthdist_why_); \
    if (!engine) GTEST_SKIP() << "no device for this backend: " << rthdist_why_
