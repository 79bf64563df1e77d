// The CPU backend's kept tree (cpu/kept_surface_tree.hpp): reused only for
// a mesh equal to the kept one bit for bit (vertex values in double,
// indices), float or double alike; rebuilt for any other, a sign of zero
// included; the kept tree's answers are a fresh tree's.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/input_frame.hpp"
#include "core/point_triangle.hpp"
#include "cpu/kept_surface_tree.hpp"

namespace rthdist {
namespace {

struct Mesh {
    std::vector<glm::dvec3> vertices{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {4, 4, 1}};
    std::vector<uint32_t> indices{0, 1, 2, 1, 3, 2};
    [[nodiscard]] MeshView view() const { return MeshView{PointView(vertices), indices}; }
};

// The Engine's use (api/surface.cpp): the kept tree where it holds the mesh,
// else one kept now with the mesh's checked summary.
const cpu::TriangleBvh& treeFor(cpu::KeptSurfaceTree& kept, const MeshView& mesh, int threads, bool& reused) {
    reused = kept.holds(mesh, threads);
    if (!reused) {
        const Result<core::SetSummary> summary = core::summarizeSet(mesh.vertices, "B", threads);
        EXPECT_TRUE(summary.has_value());
        (void)kept.keep(mesh, *summary, threads);
    }
    return kept.tree();
}

TEST(KeptSurfaceTree, ReusedForTheSameMeshOnly) {
    cpu::KeptSurfaceTree kept;
    bool reused = true;
    Mesh m;
    const cpu::TriangleBvh* first = &treeFor(kept, m.view(), 2, reused);
    EXPECT_FALSE(reused) << "nothing kept yet";
    EXPECT_EQ(&treeFor(kept, m.view(), 2, reused), first);
    EXPECT_TRUE(reused);

    const Mesh other;  // the same values from other arrays
    (void)treeFor(kept, other.view(), 1, reused);
    EXPECT_TRUE(reused);

    std::vector<glm::vec3> floats(m.vertices.begin(), m.vertices.end());
    (void)treeFor(kept, MeshView{PointView(floats), m.indices}, 2, reused);
    EXPECT_TRUE(reused) << "float values equal to the kept doubles";

    m.vertices[0].x = -0.0;  // == 0.0, another bit pattern
    (void)treeFor(kept, m.view(), 2, reused);
    EXPECT_FALSE(reused) << "-0.0 for 0.0";
    (void)treeFor(kept, m.view(), 2, reused);
    EXPECT_TRUE(reused);

    m.indices[5] = 0;
    (void)treeFor(kept, m.view(), 2, reused);
    EXPECT_FALSE(reused) << "an index";

    m.indices.resize(3);
    (void)treeFor(kept, m.view(), 2, reused);
    EXPECT_FALSE(reused) << "a triangle fewer";
    // The summary kept is the kept mesh's (its vertices' box).
    EXPECT_EQ(kept.summary().box.lo, glm::dvec3(-0.0, 0, 0));
    EXPECT_EQ(kept.summary().box.hi, glm::dvec3(4, 4, 1));
    const cpu::TriangleBvh& tree = treeFor(kept, m.view(), 2, reused);
    EXPECT_TRUE(reused);
    EXPECT_EQ(tree.triangleCount(), 1u);

    // The kept tree answers as a fresh one over the same mesh.
    const cpu::TriangleBvh fresh(m.view(), 2);
    const glm::dvec3 p(3, 3, 2);
    const double slack = core::closestSlack(8.0);
    EXPECT_EQ(tree.nearest(p, slack).distance2, fresh.nearest(p, slack).distance2);
    EXPECT_EQ(tree.nearest(p, slack).triangle, fresh.nearest(p, slack).triangle);
}

}  // namespace
}  // namespace rthdist
