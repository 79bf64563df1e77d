// Helpers of the masks tests: the backend under test.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>

#include "rthdist/masks.hpp"

namespace rthdist::masks {

// RTHDIST_TEST_BACKEND (cpu, ray-query, rt-pipeline), the CPU backend when unset.
inline Backend backendUnderTest() {
    const char* env = std::getenv("RTHDIST_TEST_BACKEND");
    Backend b = Backend::kCpu;
    if (env && !parseBackend(env, b)) ADD_FAILURE() << "unknown RTHDIST_TEST_BACKEND=" << env;
    return b;
}

}  // namespace rthdist::masks
