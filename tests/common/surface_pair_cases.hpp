// Surface-to-surface test support (tests/api/surface_bounds_test.cpp on the
// CPU backend, tests/api/surface_pair_gpu_test.cpp on the GPU backends):
// meshes whose H is known in closed form and the independent check by dense
// exact sampling. Header only: the checks call the public library.
#pragma once

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <utility>
#include <vector>

#include "common/surface_cases.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::test {

struct PairMesh {
    std::vector<glm::dvec3> vertices;
    std::vector<uint32_t> indices;
    [[nodiscard]] MeshView view() const { return MeshView{PointView(vertices), indices}; }
};

inline PairMesh fromCase(const SurfaceCase& c) { return PairMesh{c.vertices, c.indices}; }

inline PairMesh translated(PairMesh m, const glm::dvec3& by) {
    for (glm::dvec3& v : m.vertices) v += by;
    return m;
}

inline PairMesh scaled(PairMesh m, double s) {
    for (glm::dvec3& v : m.vertices) v *= s;
    return m;
}

// An icosahedron subdivided `levels` times, every vertex projected onto the
// unit sphere: a convex polytope whose vertices lie on the sphere (up to
// one rounding).
inline PairMesh icosphere(int levels) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    PairMesh m;
    for (const glm::dvec3& v :
         {glm::dvec3(-1, t, 0), glm::dvec3(1, t, 0), glm::dvec3(-1, -t, 0), glm::dvec3(1, -t, 0),
          glm::dvec3(0, -1, t), glm::dvec3(0, 1, t), glm::dvec3(0, -1, -t), glm::dvec3(0, 1, -t),
          glm::dvec3(t, 0, -1), glm::dvec3(t, 0, 1), glm::dvec3(-t, 0, -1), glm::dvec3(-t, 0, 1)})
        m.vertices.push_back(glm::normalize(v));
    m.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                 4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                 6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto middle = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto [it, inserted] = mid.try_emplace(key, uint32_t(m.vertices.size()));
            if (inserted) m.vertices.push_back(glm::normalize(m.vertices[a] + m.vertices[b]));
            return it->second;
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < m.indices.size(); i += 3) {
            const uint32_t a = m.indices[i], b = m.indices[i + 1], c = m.indices[i + 2];
            const uint32_t ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
            next.insert(next.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
        }
        m.indices = std::move(next);
    }
    return m;
}

// lower <= known <= upper and upper - lower <= tolerance; `known` within
// `knownError` (the rounding of the test's own construction).
inline void expectBrackets(const SurfaceBoundsResult& r, double known, double knownError = 0.0) {
    std::printf("%s: bounds [%.17g, %.17g] width %.3g, tolerance %.3g, known %.17g, queries %llu + %llu\n",
                backendName(r.backend), r.lower, r.upper, r.upper - r.lower, r.tolerance, known,
                static_cast<unsigned long long>(r.aToB.counters.queries),
                static_cast<unsigned long long>(r.bToA.counters.queries));
    EXPECT_LE(r.lower, known + knownError);
    EXPECT_GE(r.upper, known - knownError);
    EXPECT_LE(r.upper - r.lower, r.tolerance);
    EXPECT_LE(r.lower, r.upper);
}

// Every point of the mesh's triangles at barycentric coordinates (i, j, n - i - j) / n.
inline std::vector<glm::dvec3> denseSamples(const PairMesh& m, int n) {
    std::vector<glm::dvec3> points;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::dvec3 &p = m.vertices[m.indices[t]], &q = m.vertices[m.indices[t + 1]],
                         &s = m.vertices[m.indices[t + 2]];
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j)
                points.push_back((p * double(n - i - j) + q * double(i) + s * double(j)) / double(n));
    }
    return points;
}

inline double longestEdge(const PairMesh& m) {
    double e = 0.0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        for (int k = 0; k < 3; ++k)
            e = std::max(e, glm::distance(m.vertices[m.indices[t + size_t(k)]],
                                          m.vertices[m.indices[t + size_t(k + 1) % 3]]));
    }
    return e;
}

// Dense exact sampling on the CPU backend, independent of the refinement:
// h(A, B) >= the largest sampled distance (a lower bound), and <= it plus
// 2/3 of the longest edge of the sampling grid (the Lipschitz bound, an
// upper bound); the witness realizes the lower bound (its own exact
// distance).
inline void checkAgainstSampling(const PairMesh& a, const PairMesh& b, const SurfaceBoundsDirected& d) {
    const int n = 24;
    const std::vector<glm::dvec3> samples = denseSamples(a, n);
    Result<SurfaceResult> sampled = hausdorffToSurface(PointView(samples), b.view());
    ASSERT_TRUE(sampled) << sampled.error().message;
    const double sampledUpper = sampled->hausdorff + longestEdge(a) / n * (2.0 / 3.0) * (1 + 1e-12);
    std::printf("sampled %.17g (upper %.17g), bounds [%.17g, %.17g]\n", sampled->hausdorff, sampledUpper,
                d.lower, d.upper);
    EXPECT_LE(sampled->hausdorff, d.upper);
    EXPECT_LE(d.lower, sampledUpper);
    Result<SurfaceResult> w = hausdorffToSurface(PointView(std::vector<glm::dvec3>{d.fromPoint}), b.view());
    ASSERT_TRUE(w) << w.error().message;
    EXPECT_NEAR(w->hausdorff, d.distance, 1e-12);
    EXPECT_NEAR(glm::distance(d.fromPoint, d.toPoint), d.distance, 1e-12);
}

// The height-field pair of the dense-sampling tests: seed's 7 x 7 field
// over [0, 5]^2 and seed + 100's 9 x 9 one moved by (0.3, -0.2, 0.4).
inline std::pair<PairMesh, PairMesh> heightFieldPair(uint64_t seed) {
    return {fromCase(heightField(seed, 7, 5.0)),
            translated(fromCase(heightField(seed + 100, 9, 5.0)), {0.3, -0.2, 0.4})};
}

// H's bounds within `tolerance` and each the larger of the directions',
// both directions against dense sampling.
inline void expectSampledBothWays(const PairMesh& a, const PairMesh& b, const SurfaceBoundsResult& r,
                                  double tolerance) {
    EXPECT_LE(r.upper - r.lower, tolerance);
    EXPECT_EQ(r.lower, std::max(r.aToB.lower, r.bToA.lower));
    EXPECT_EQ(r.upper, std::max(r.aToB.upper, r.bToA.upper));
    checkAgainstSampling(a, b, r.aToB);
    checkAgainstSampling(b, a, r.bToA);
}

}  // namespace rthdist::test
