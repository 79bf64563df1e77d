// core::KeptMesh: a mesh is "the same" as the kept one only when every
// vertex value and every index is, bit for bit; any difference, in place
// or in size, is seen on any thread count.
#include <gtest/gtest.h>

#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/kept_mesh.hpp"
#include "rthdist/mesh.hpp"

namespace rthdist::core {
namespace {

struct Mesh {
    std::vector<glm::dvec3> vertices;
    std::vector<uint32_t> indices;
    [[nodiscard]] MeshView view() const { return MeshView{PointView(vertices), indices}; }
};

// A strip of n triangles over n + 2 vertices (a few chunks of the worker
// pool's at the larger n).
Mesh strip(size_t n) {
    Mesh m;
    for (size_t i = 0; i < n + 2; ++i)
        m.vertices.emplace_back(double(i) * 0.5, double(i % 2), 0.25 * double(i % 3));
    for (uint32_t t = 0; t < n; ++t) m.indices.insert(m.indices.end(), {t, t + 1, t + 2});
    return m;
}

SetSummary summaryOf(const Mesh& m) {
    SetSummary s;
    s.box.lo = m.vertices.front();
    s.box.hi = m.vertices.back();
    return s;
}

TEST(KeptMesh, HoldsNothingUntilAMeshIsKept) {
    const Mesh m = strip(10);
    KeptMesh kept;
    EXPECT_FALSE(kept.holds(m.view(), 1));
    kept.keep(m.view(), summaryOf(m), 1);
    EXPECT_TRUE(kept.holds(m.view(), 1));
    EXPECT_EQ(kept.summary().box.hi, m.vertices.back());
}

TEST(KeptMesh, EveryBitOfEveryVertexAndIndexCounts) {
    for (const size_t n : {size_t(10), size_t(300000)}) {
        for (const int threads : {1, 4}) {
            Mesh m = strip(n);
            KeptMesh kept;
            kept.keep(m.view(), summaryOf(m), threads);
            const Mesh copy = m;  // another buffer, the same values
            EXPECT_TRUE(kept.holds(copy.view(), threads)) << n;
            // In place: the last vertex's z by one ulp, then 0.0 against -0.0.
            const size_t last = m.vertices.size() - 1;
            const double z = m.vertices[last].z;
            m.vertices[last].z = std::nextafter(z, 1.0);
            EXPECT_FALSE(kept.holds(m.view(), threads)) << n;
            m.vertices[last].z = z;
            EXPECT_TRUE(kept.holds(m.view(), threads)) << n;
            const size_t zero = 0;  // vertex 0 has z = 0.0
            m.vertices[zero].z = -0.0;
            EXPECT_FALSE(kept.holds(m.view(), threads)) << n;
            m.vertices[zero].z = 0.0;
            // An index, the same count.
            std::swap(m.indices[m.indices.size() - 1], m.indices[m.indices.size() - 2]);
            EXPECT_FALSE(kept.holds(m.view(), threads)) << n;
            std::swap(m.indices[m.indices.size() - 1], m.indices[m.indices.size() - 2]);
            // One triangle fewer, one vertex more.
            Mesh fewer = m;
            fewer.indices.resize(fewer.indices.size() - 3);
            EXPECT_FALSE(kept.holds(fewer.view(), threads)) << n;
            Mesh more = m;
            more.vertices.push_back(more.vertices.back());
            EXPECT_FALSE(kept.holds(more.view(), threads)) << n;
            EXPECT_TRUE(kept.holds(m.view(), threads)) << n;
        }
    }
}

}  // namespace
}  // namespace rthdist::core
