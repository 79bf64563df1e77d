// Helpers of the Engine API tests: the backend under test (cpu, ray-query or
// rt-pipeline, from RTHDIST_TEST_BACKEND, with the validation layer on the
// GPU ones), and the comparison of two results that must be the same
// computation (prepared sets against the one-shot call).
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "gpu_algo/gpu_test_support.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::test {

// Engine options of the backend under test: RTHDIST_TEST_BACKEND, validation on.
inline EngineOptions engineUnderTest() {
    EngineOptions o;
    o.backend = backendUnderTest();
    o.validation = o.backend != Backend::kCpu;
    return o;
}

inline std::vector<glm::vec3> randomCloud(size_t n, uint64_t seed, glm::vec3 offset = glm::vec3(0.0f),
                                          float extent = 1.0f) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, extent);
    std::vector<glm::vec3> p(n);
    for (auto& v : p) v = glm::vec3(u(rng), u(rng), u(rng)) + offset;
    return p;
}

// The same computation: on the CPU backend (deterministic) the same values
// and witnesses; on a GPU backend, whose cells order their points by atomics,
// the same values up to ties: distances within `tolerance` (the oracle's
// float allowance), each witness any of the pairs that realize them.
inline void expectSameResult(const HausdorffResult& got, const HausdorffResult& want,
                             double tolerance = 0.0) {
    EXPECT_NEAR(got.hausdorff, want.hausdorff, tolerance);
    EXPECT_EQ(got.directedOnly, want.directedOnly);
    const bool exactTies = got.backend == Backend::kCpu;
    for (auto [g, w] : {std::pair{&got.aToB, &want.aToB}, std::pair{&got.bToA, &want.bToA}}) {
        EXPECT_NEAR(g->distance, w->distance, tolerance);
        if (!exactTies) continue;
        EXPECT_EQ(g->queryIndex, w->queryIndex);
        EXPECT_EQ(g->targetIndex, w->targetIndex);
        EXPECT_EQ(g->queryPoint, w->queryPoint);
        EXPECT_EQ(g->targetPoint, w->targetPoint);
    }
    for (auto [g, w] : {std::pair{&got.aNearest, &want.aNearest}, std::pair{&got.bNearest, &want.bNearest}}) {
        ASSERT_EQ(g->distance.size(), w->distance.size());
        for (size_t i = 0; i < g->distance.size(); ++i)
            ASSERT_NEAR(g->distance[i], w->distance[i], tolerance) << "point " << i;
        if (exactTies) EXPECT_EQ(g->nearest, w->nearest);
    }
    EXPECT_EQ(got.validationMessages, 0u);
}

}  // namespace rthdist::test

// An Engine of the backend under test (a skip, which CI fails, when the
// device is missing).
#define RTHDIST_REQUIRE_TEST_ENGINE(engine) RTHDIST_REQUIRE_ENGINE(engine, ::rthdist::test::engineUnderTest())
