// Voxel selection and boundary extraction on the CPU (multithreaded): the
// boundary from the selection packed one bit per voxel (row_bits.hpp), the
// other passes read straight from the label volume.
// Internal to rthdist_masks.
//
// Boundary under connectivity c (6, 18, 26): a selected voxel with at least
// one of its c neighbours not selected or outside the volume (the volume's
// outside counts as background, as SciPy's binary_erosion with
// border_value=0 does). Equals mask AND NOT erosion(mask, c-structure).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/uninit_vector.hpp"

#include "masks/masks.hpp"

namespace rthdist::masks::detail {

using Dims = std::array<int64_t, 3>;

struct Extraction {
    uint64_t count = 0;                     // selected voxels
    core::UninitVector<uint64_t> boundary;  // ascending linear indices of the boundary voxels
};

// One pass over the volume: the selected voxels' count and boundary.
[[nodiscard]] Extraction extractBoundary(const Volume& v, LabelSelect select, int connectivity, int threads);

// Ascending linear indices of voxels selected in `a` and not in `b` (same grid).
[[nodiscard]] std::vector<uint64_t> differenceVoxels(const Volume& a, LabelSelect sa, const Volume& b,
                                                     LabelSelect sb, int threads);

// The first voxel selected in both, if any.
[[nodiscard]] std::optional<uint64_t> firstCommonVoxel(const Volume& a, LabelSelect sa, const Volume& b,
                                                       LabelSelect sb);

[[nodiscard]] inline std::array<int64_t, 3> voxelOf(uint64_t linear, Dims dims) {
    const int64_t i = int64_t(linear % uint64_t(dims[0]));
    const uint64_t rest = linear / uint64_t(dims[0]);
    return {i, int64_t(rest % uint64_t(dims[1])), int64_t(rest / uint64_t(dims[1]))};
}

// voxelOf for many voxels of one grid (the per-voxel loops of the distance
// stage): each division by a dimension is a multiplication by its reciprocal
// in double, corrected by one step. Exact for linear indices below 2^50
// (the product's error stays below one); past that, voxelOf's divisions.
class VoxelDecoder {
public:
    explicit VoxelDecoder(Dims dims)
        : m_nx(uint64_t(dims[0])),
          m_ny(uint64_t(dims[1])),
          m_invX(1.0 / double(dims[0])),
          m_invY(1.0 / double(dims[1])),
          m_dims(dims) {}

    [[nodiscard]] std::array<int64_t, 3> operator()(uint64_t linear) const {
        if (linear >= kExactBelow) return voxelOf(linear, m_dims);
        const uint64_t row = quotient(linear, m_nx, m_invX);
        const uint64_t z = quotient(row, m_ny, m_invY);
        return {int64_t(linear - row * m_nx), int64_t(row - z * m_ny), int64_t(z)};
    }

private:
    static constexpr uint64_t kExactBelow = uint64_t(1) << 50;

    static uint64_t quotient(uint64_t n, uint64_t d, double inverse) {
        uint64_t q = uint64_t(double(n) * inverse);
        if (q * d > n) {
            --q;
        } else if ((q + 1) * d <= n) {
            ++q;
        }
        return q;
    }

    uint64_t m_nx, m_ny;
    double m_invX, m_invY;
    Dims m_dims;
};

}  // namespace rthdist::masks::detail
