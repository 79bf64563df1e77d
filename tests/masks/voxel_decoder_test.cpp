// VoxelDecoder (masks/boundary.hpp), the distance stage's linear index ->
// (i, j, k), equals voxelOf's divisions on grids whose dimensions are 1, 2,
// powers of two and their neighbours, primes, a 512 x 512 x 300 volume and
// dimensions near 2^32, for linear indices at the ends of the grid, at every
// row and slice boundary of a small grid, around 2^32 (where the product
// path hands over to the double one) and at random.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "masks/boundary.hpp"

namespace rthdist::masks::detail {
namespace {

void expectDecodes(const Dims& dims, uint64_t linear) {
    const VoxelDecoder decode(dims);
    ASSERT_EQ(decode(linear), voxelOf(linear, dims))
        << "dims " << dims[0] << " x " << dims[1] << " x " << dims[2] << ", linear " << linear;
}

TEST(VoxelDecoder, EqualsTheDivisions) {
    const uint64_t big = uint64_t(1) << 32;
    const std::vector<int64_t> sides = {1,
                                        2,
                                        3,
                                        7,
                                        63,
                                        64,
                                        65,
                                        255,
                                        256,
                                        257,
                                        300,
                                        511,
                                        512,
                                        513,
                                        65535,
                                        65536,
                                        99991,
                                        1 << 20,
                                        (1 << 20) + 7,
                                        int64_t(big - 1),
                                        int64_t(big - 5)};
    std::mt19937_64 rng(11);
    for (int64_t nx : sides) {
        for (int64_t ny : sides) {
            const Dims dims{nx, ny, 300};
            const unsigned __int128 count =
                static_cast<unsigned __int128>(uint64_t(nx) * uint64_t(ny)) * 300u;
            if (uint64_t(nx) >= big / 2 && uint64_t(ny) >= big / 2) continue;  // past 2^64 voxels
            ASSERT_LT(count, static_cast<unsigned __int128>(~uint64_t(0)));
            const uint64_t voxels = uint64_t(count);
            std::vector<uint64_t> at = {0, 1, voxels - 1, big - 1, big, big + 1, voxels / 2};
            for (int r = 0; r < 200; ++r) at.push_back(rng() % voxels);
            for (uint64_t row : {uint64_t(1), uint64_t(ny), uint64_t(ny) * 7}) {
                const uint64_t edge = row * uint64_t(nx);
                for (uint64_t d : {edge - 1, edge, edge + 1}) at.push_back(d % voxels);
            }
            for (uint64_t linear : at) {
                if (linear >= voxels) continue;
                expectDecodes(dims, linear);
            }
        }
    }
    // Every voxel of a small odd grid.
    const Dims small{13, 7, 5};
    for (uint64_t linear = 0; linear < 13u * 7u * 5u; ++linear) expectDecodes(small, linear);
    // The masks' volume, every 997th voxel.
    const Dims volume{512, 512, 300};
    for (uint64_t linear = 0; linear < 512u * 512u * 300u; linear += 997) expectDecodes(volume, linear);
}

}  // namespace
}  // namespace rthdist::masks::detail
