// The point-to-surface oracle: every query against EVERY triangle, in
// triangle order, in double, measured by the one shared rule
// (core::closestOnTriangle); no index, no pruning, no early break, so that
// it can be trusted. Ties: the smallest triangle index among a query's
// equally near triangles, the smallest query index among the queries
// realizing the maximum. Serial.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace rthdist::oracle {

struct SurfaceNearest {
    double distance2 = 0.0;
    uint32_t triangle = 0;
    glm::dvec3 point{0.0};
    glm::dvec3 barycentric{0.0};  // of point w.r.t. the triangle's vertices, index order
};

[[nodiscard]] SurfaceNearest bruteNearestTriangle(const glm::dvec3& q, std::span<const glm::dvec3> vertices,
                                                  std::span<const uint32_t> indices);

struct SurfaceDirectedExact {
    double distance = 0.0;  // sqrt of the largest squared nearest distance
    uint64_t queryIndex = 0;
    SurfaceNearest nearest;
    std::vector<SurfaceNearest> perQuery;
};

[[nodiscard]] SurfaceDirectedExact bruteForceSurface(std::span<const glm::dvec3> queries,
                                                     std::span<const glm::dvec3> vertices,
                                                     std::span<const uint32_t> indices);

}  // namespace rthdist::oracle
