// How compareMasks hands voxels to the engine and measures the pairs it
// finds. Internal to rthdist_masks.
//
// The engine searches float coordinates of the voxels relative to the
// volume's centre, through the affine's 3x3 part (the rthdist convention's
// world metric) or the spacing (every other convention): |p| <= D/2, D the
// volume's diagonal, so rounding to float moves each coordinate by at most
// 2^-24 D/2 and the search finds every query a neighbour within 2 eps
// (eps = sqrt(3) 2^-24 D, about 1e-7 D) of its nearest, the bound of the
// engine's own double path (rthdist.hpp). Packed floats take the engine's
// device ingest (no host pass over the points). Each distance is then
// recomputed in double from the two voxels' indices (translation leaves it
// alone), so every number reported comes from the grid, not from the floats.
#pragma once

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/uninit_vector.hpp"
#include "masks/boundary.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {

// Float search coordinates of voxels (kept between calls: core::UninitVector).
using SearchPoints = core::UninitVector<glm::vec3>;

class VoxelMetric {
public:
    // world: the affine's 3x3 part; else the spacing (column norms).
    VoxelMetric(const Volume& v, bool world);
    // deepmind's surfel corners of v's grid ((nx + 1) x (ny + 1) x (nz + 1),
    // corner c at voxel coordinates c - 1/2; surfels.hpp) in the spacing
    // metric, centred as the voxels are: linear indices passed to
    // searchPoints and distance are corner indices.
    [[nodiscard]] static VoxelMetric corners(const Volume& v);

    // Float coordinates of `voxels` (linear indices) in the search frame.
    [[nodiscard]] SearchPoints searchPoints(std::span<const uint64_t> voxels, int threads) const;
    // |linear (p - q)| in double.
    // A diagonal map (the spacing metric, an axis-aligned affine) scales
    // each component alone: the same double as the matrix product, whose
    // other terms are exact zeros (recompute's loop over 10^5 voxels: the
    // product and the call were most of it).
    [[nodiscard]] double distance(std::array<int64_t, 3> p, std::array<int64_t, 3> q) const {
        const glm::dvec3 delta(double(p[0] - q[0]), double(p[1] - q[1]), double(p[2] - q[2]));
        const glm::dvec3 d = m_diagonal ? m_scale * delta : m_linear * delta;
        return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    }

private:
    VoxelMetric(Dims dims, const glm::dmat3& linear, glm::dvec3 centre);
    void noteDiagonal();  // sets m_diagonal and m_scale from m_linear

    Dims m_dims;
    glm::dmat3 m_linear;      // voxel offset -> mm
    bool m_diagonal = false;  // m_linear's off-diagonal entries are all 0
    glm::dvec3 m_scale{0.0};  // its diagonal
    glm::dvec3 m_centre;      // voxel coordinates of the search frame's origin
};

// Every query's distance to the target the engine found for it
// (nearest[i]: index into targets), recomputed in double; the largest of
// them (smallest query index among ties) is the direction's witness; how
// many are within `tolerance` is counted in the same pass.
struct RecomputedDirection {
    core::UninitVector<double> distances;  // in query order
    double sum = 0.0;                      // summed in chunks of 2^13 queries, in query order
    size_t witness = 0;                    // query index of the largest distance
    double least = 0.0;                    // the smallest distance
    uint64_t atMost = 0;                   // distances <= the `tolerance` given
};
[[nodiscard]] RecomputedDirection recompute(const VoxelMetric& metric, Dims dims,
                                            std::span<const uint64_t> queries,
                                            std::span<const uint64_t> targets,
                                            std::span<const uint32_t> nearest, double tolerance, int threads);

}  // namespace rthdist::masks::detail
