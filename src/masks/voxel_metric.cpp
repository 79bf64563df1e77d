// The search frame and the recomputed distances (voxel_metric.hpp).
#include "masks/voxel_metric.hpp"

#include <cmath>

#include "core/parallel.hpp"

namespace rthdist::masks::detail {
namespace {

constexpr size_t kChunk = size_t(1) << 13;

glm::dvec3 asVector(std::array<int64_t, 3> ijk) {
    return glm::dvec3(double(ijk[0]), double(ijk[1]), double(ijk[2]));
}

}  // namespace

VoxelMetric::VoxelMetric(const Volume& v, bool world)
    : m_dims(v.dims),
      m_linear(1.0),
      m_centre(0.5 * double(v.dims[0] - 1), 0.5 * double(v.dims[1] - 1), 0.5 * double(v.dims[2] - 1)) {
    if (world) {
        m_linear = glm::dmat3(v.voxelToWorld);
    } else {
        const glm::dvec3 s = v.spacing();
        m_linear = glm::dmat3(s.x, 0.0, 0.0, 0.0, s.y, 0.0, 0.0, 0.0, s.z);
    }
}

VoxelMetric::VoxelMetric(Dims dims, const glm::dmat3& linear, glm::dvec3 centre)
    : m_dims(dims), m_linear(linear), m_centre(centre) {}

VoxelMetric VoxelMetric::corners(const Volume& v) {
    const glm::dvec3 s = v.spacing();
    // Corner (n - 1) / 2 + 1/2 of an axis is the voxels' centre (n - 1) / 2.
    return VoxelMetric({v.dims[0] + 1, v.dims[1] + 1, v.dims[2] + 1},
                       glm::dmat3(s.x, 0.0, 0.0, 0.0, s.y, 0.0, 0.0, 0.0, s.z),
                       glm::dvec3(0.5 * double(v.dims[0]), 0.5 * double(v.dims[1]), 0.5 * double(v.dims[2])));
}

std::vector<glm::vec3> VoxelMetric::searchPoints(const std::vector<uint64_t>& voxels, int threads) const {
    std::vector<glm::vec3> out(voxels.size());
    core::parallelChunks(voxels.size(), kChunk, threads, [&](size_t b, size_t e, int) {
        for (size_t i = b; i < e; ++i)
            out[i] = glm::vec3(m_linear * (asVector(voxelOf(voxels[i], m_dims)) - m_centre));
    });
    return out;
}

double VoxelMetric::distance(std::array<int64_t, 3> p, std::array<int64_t, 3> q) const {
    const glm::dvec3 d = m_linear * glm::dvec3(double(p[0] - q[0]), double(p[1] - q[1]), double(p[2] - q[2]));
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

RecomputedDirection recompute(const VoxelMetric& metric, Dims dims, const std::vector<uint64_t>& queries,
                              const std::vector<uint64_t>& targets, const std::vector<uint32_t>& nearest,
                              int threads) {
    RecomputedDirection r;
    r.distances.resize(queries.size());
    core::parallelChunks(queries.size(), kChunk, threads, [&](size_t b, size_t e, int) {
        for (size_t i = b; i < e; ++i)
            r.distances[i] = metric.distance(voxelOf(queries[i], dims), voxelOf(targets[nearest[i]], dims));
    });
    for (size_t i = 0; i < r.distances.size(); ++i) {
        r.sum += r.distances[i];
        if (r.distances[i] > r.distances[r.witness]) r.witness = i;
    }
    return r;
}

}  // namespace rthdist::masks::detail
