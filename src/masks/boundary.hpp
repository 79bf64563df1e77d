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

#include "rthdist/masks.hpp"

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
// stage), without a division instruction. Linear indices and dimensions
// below 2^32 (a 512 x 512 x 300 volume's): each quotient is the high word of
// one 64 x 64-bit product, n / d = (c n) >> 64 with c = ceil(2^64 / d),
// exact for every n, d < 2^32, d >= 2 (Lemire, Kaser & Kurz, "Faster
// remainder by direct computation", 2019; a dimension of 1 divides by
// nothing). Larger ones, below 2^50: a multiplication by the reciprocal in
// double, corrected by one step (the product's error stays below one); past
// that, voxelOf's divisions.
class VoxelDecoder {
public:
    explicit VoxelDecoder(Dims dims)
        : m_nx(uint64_t(dims[0])),
          m_ny(uint64_t(dims[1])),
          m_cx(reciprocal64(m_nx)),
          m_cy(reciprocal64(m_ny)),
          m_invX(1.0 / double(dims[0])),
          m_invY(1.0 / double(dims[1])),
          m_small(m_nx < kWordLimit && m_ny < kWordLimit),
          m_dims(dims) {}

    [[nodiscard]] std::array<int64_t, 3> operator()(uint64_t linear) const {
        if (m_small && linear < kWordLimit) {
            const uint64_t row = m_nx == 1 ? linear : highWord(m_cx, linear);
            const uint64_t z = m_ny == 1 ? row : highWord(m_cy, row);
            return {int64_t(linear - row * m_nx), int64_t(row - z * m_ny), int64_t(z)};
        }
        if (linear >= kExactBelow) return voxelOf(linear, m_dims);
        const uint64_t row = quotient(linear, m_nx, m_invX);
        const uint64_t z = quotient(row, m_ny, m_invY);
        return {int64_t(linear - row * m_nx), int64_t(row - z * m_ny), int64_t(z)};
    }

private:
    static constexpr uint64_t kWordLimit = uint64_t(1) << 32;
    static constexpr uint64_t kExactBelow = uint64_t(1) << 50;

    // ceil(2^64 / d) for 2 <= d < 2^32 (0 otherwise: not used).
    static uint64_t reciprocal64(uint64_t d) { return d >= 2 && d < kWordLimit ? ~uint64_t(0) / d + 1 : 0; }
    static uint64_t highWord(uint64_t c, uint64_t n) {
        return uint64_t((static_cast<unsigned __int128>(c) * n) >> 64);
    }
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
    uint64_t m_cx, m_cy;
    double m_invX, m_invY;
    bool m_small;
    Dims m_dims;
};

}  // namespace rthdist::masks::detail
