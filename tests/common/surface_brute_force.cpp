#include "common/surface_brute_force.hpp"

#include <cmath>
#include <limits>

#include "core/point_triangle.hpp"

namespace rthdist::oracle {

SurfaceNearest bruteNearestTriangle(const glm::dvec3& q, std::span<const glm::dvec3> vertices,
                                    std::span<const uint32_t> indices) {
    SurfaceNearest best;
    best.distance2 = std::numeric_limits<double>::infinity();
    for (size_t t = 0; 3 * t + 2 < indices.size(); ++t) {
        const core::TriangleClosest r = core::closestOnTriangle(
            q, vertices[indices[3 * t]], vertices[indices[3 * t + 1]], vertices[indices[3 * t + 2]]);
        if (r.distance2 < best.distance2) {
            best.distance2 = r.distance2;
            best.triangle = uint32_t(t);
            best.point = r.point;
            best.barycentric = r.barycentric;
        }
    }
    return best;
}

SurfaceDirectedExact bruteForceSurface(std::span<const glm::dvec3> queries,
                                       std::span<const glm::dvec3> vertices,
                                       std::span<const uint32_t> indices) {
    SurfaceDirectedExact out;
    out.perQuery.reserve(queries.size());
    double max2 = -1.0;
    for (size_t i = 0; i < queries.size(); ++i) {
        out.perQuery.push_back(bruteNearestTriangle(queries[i], vertices, indices));
        if (out.perQuery.back().distance2 > max2) {
            max2 = out.perQuery.back().distance2;
            out.queryIndex = i;
            out.nearest = out.perQuery.back();
        }
    }
    out.distance = std::sqrt(max2);
    return out;
}

}  // namespace rthdist::oracle
