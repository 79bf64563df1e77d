// The search frame and the recomputed distances (voxel_metric.hpp).
#include "masks/voxel_metric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/parallel.hpp"

namespace rthdist::masks::detail {
namespace {

constexpr size_t kChunk = size_t(1) << 13;
constexpr size_t kPrefetchAhead = 16;  // queries (2 cores: the distances of the noisy pair 2.3-2.5 -> 2.1 ms)

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
    noteDiagonal();
}

VoxelMetric::VoxelMetric(Dims dims, const glm::dmat3& linear, glm::dvec3 centre)
    : m_dims(dims), m_linear(linear), m_centre(centre) {
    noteDiagonal();
}

void VoxelMetric::noteDiagonal() {
    const glm::dmat3& m = m_linear;
    m_diagonal = m[0][1] == 0.0 && m[0][2] == 0.0 && m[1][0] == 0.0 && m[1][2] == 0.0 && m[2][0] == 0.0 &&
                 m[2][1] == 0.0;
    m_scale = glm::dvec3(m[0][0], m[1][1], m[2][2]);
}

VoxelMetric VoxelMetric::corners(const Volume& v) {
    const glm::dvec3 s = v.spacing();
    // Corner (n - 1) / 2 + 1/2 of an axis is the voxels' centre (n - 1) / 2.
    return VoxelMetric({v.dims[0] + 1, v.dims[1] + 1, v.dims[2] + 1},
                       glm::dmat3(s.x, 0.0, 0.0, 0.0, s.y, 0.0, 0.0, 0.0, s.z),
                       glm::dvec3(0.5 * double(v.dims[0]), 0.5 * double(v.dims[1]), 0.5 * double(v.dims[2])));
}

SearchPoints VoxelMetric::searchPoints(std::span<const uint64_t> voxels, int threads) const {
    SearchPoints out;
    out.resize(voxels.size());
    const VoxelDecoder decode(m_dims);
    // The diagonal map as distance() applies it: the same coordinates.
    core::parallelChunks(voxels.size(), kChunk, threads, [&](size_t b, size_t e, int) {
        if (m_diagonal) {
            for (size_t i = b; i < e; ++i)
                out[i] = glm::vec3(m_scale * (asVector(decode(voxels[i])) - m_centre));
        } else {
            for (size_t i = b; i < e; ++i)
                out[i] = glm::vec3(m_linear * (asVector(decode(voxels[i])) - m_centre));
        }
    });
    return out;
}

RecomputedDirection recompute(const VoxelMetric& metric, Dims dims, std::span<const uint64_t> queries,
                              std::span<const uint64_t> targets, std::span<const uint32_t> nearest,
                              double tolerance, int threads) {
    RecomputedDirection r;
    r.distances.resize(queries.size());
    // Each chunk's sum and witness (largest, smallest index among ties),
    // combined in chunk order: the same for any thread count.
    const size_t chunks = (queries.size() + kChunk - 1) / kChunk;
    std::vector<double> sums(chunks, 0.0);
    std::vector<size_t> witnesses(chunks, 0);
    std::vector<double> leasts(chunks, 0.0);
    std::vector<uint64_t> atMost(chunks, 0);
    const VoxelDecoder decode(dims);
    core::parallelChunks(queries.size(), kChunk, threads, [&](size_t b, size_t e, int) {
        double sum = 0.0;
        size_t witness = b;
        double least = std::numeric_limits<double>::infinity();
        uint64_t within = 0;
        for (size_t i = b; i < e; ++i) {
            // The targets are read in the engine's order, not theirs: fetch a
            // few queries ahead.
            if (i + kPrefetchAhead < e) __builtin_prefetch(&targets[nearest[i + kPrefetchAhead]]);
            const double d = metric.distance(decode(queries[i]), decode(targets[nearest[i]]));
            r.distances[i] = d;
            sum += d;
            if (d > r.distances[witness]) witness = i;
            least = d < least ? d : least;
            within += d <= tolerance;
        }
        sums[b / kChunk] = sum;
        witnesses[b / kChunk] = witness;
        leasts[b / kChunk] = least;
        atMost[b / kChunk] = within;
    });
    r.least = chunks > 0 ? *std::min_element(leasts.begin(), leasts.end()) : 0.0;
    for (size_t c = 0; c < chunks; ++c) {
        r.sum += sums[c];
        r.atMost += atMost[c];
        if (r.distances[witnesses[c]] > r.distances[r.witness]) r.witness = witnesses[c];
    }
    return r;
}

}  // namespace rthdist::masks::detail
