// Sampling of the longest oracle loops under the sanitizers: with
// RTHDIST_TEST_SAMPLE=k in the environment (the asan test preset sets it,
// CMakePresets.json) such a loop keeps every k-th of its cases, so that the
// sanitizer step of .ci/run stays within its time; the release step and
// tools/test.sh run every case (k = 1 when the variable is absent).
#pragma once

#include <cstdlib>
#include <string>

namespace rthdist::test {

[[nodiscard]] inline size_t caseStride() {
    const char* s = std::getenv("RTHDIST_TEST_SAMPLE");
    if (s == nullptr) return 1;
    const unsigned long k = std::strtoul(s, nullptr, 10);
    return k == 0 ? 1 : size_t(k);
}

}  // namespace rthdist::test
