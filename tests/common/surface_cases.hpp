// Point-to-surface oracle cases (design.md §11): triangle meshes with the
// degenerate triangles the rule must measure (slivers, zero area, repeated
// and duplicate triangles), far-apart and georeferenced placements, and
// query points on the surface, on edges and at vertices. Fixed seeds.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace rthdist::test {

struct SurfaceCase {
    std::string name;
    uint64_t seed = 0;
    std::vector<glm::dvec3> vertices;
    std::vector<uint32_t> indices;  // 3 per triangle
    std::vector<glm::dvec3> queries;
};

// A height field of n x n quads (two triangles each) over [0, size]^2,
// heights from the seed: a closed-form-free but well-shaped surface.
[[nodiscard]] SurfaceCase heightField(uint64_t seed, int n, double size);

// Families: random soups, a height field with queries above and on it,
// slivers, zero-area triangles, duplicates, a surface far from its queries,
// georeferenced (x ~ 5e5, y ~ 5.4e6), points exactly on the surface.
[[nodiscard]] std::vector<SurfaceCase> makeSurfaceCases();

}  // namespace rthdist::test
