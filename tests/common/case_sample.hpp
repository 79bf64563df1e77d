// Sampling of the longest oracle loops under the sanitizers: with
// RTHDIST_TEST_SAMPLE=k in the environment (the asan test preset sets it,
// CMakePresets.json) such a loop keeps every k-th of its cases, so that the
// sanitizer step of .ci/run stays within its time; the release step and
// tools/test.sh run every case (k = 1 when the variable is absent).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace rthdist::test {

[[nodiscard]] inline size_t caseStride() {
    const char* s = std::getenv("RTHDIST_TEST_SAMPLE");
    if (s == nullptr) return 1;
    const unsigned long k = std::strtoul(s, nullptr, 10);
    return k == 0 ? 1 : size_t(k);
}

// Every caseStride()-th of `cases` (all of them without the variable); says
// so on stdout when it keeps fewer.
template <class Case>
[[nodiscard]] std::vector<Case> sampledCases(std::vector<Case> cases) {
    const size_t k = caseStride();
    if (k == 1) return cases;
    std::vector<Case> kept;
    for (size_t i = 0; i < cases.size(); i += k) kept.push_back(std::move(cases[i]));
    std::printf("RTHDIST_TEST_SAMPLE=%zu: %zu of %zu cases\n", k, kept.size(), cases.size());
    return kept;
}

}  // namespace rthdist::test
