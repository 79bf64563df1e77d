// The host extraction's row packing of 8-bit labels (masks/byte_rows.hpp):
// the AVX2 version (where this CPU has it) and the portable one give the same
// words and counts, and both equal the definition, bit by bit, on every row
// length from 1 to 200 (whole words, a partial last word, a row shorter than
// one word), for "any non-zero" and for one label value.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "masks/byte_rows.hpp"

namespace rthdist::masks::detail {
namespace {

TEST(ByteRows, FastAndPortablePackingEqualTheDefinition) {
    std::mt19937 rng(5);
    for (int64_t nx = 1; nx <= 200; ++nx) {
        for (int trial = 0; trial < 4; ++trial) {
            // Mostly background with runs of labels 1-3 (and 255: a signed byte's -1).
            std::vector<uint8_t> labels(size_t(nx) + 64,
                                        7);  // the bytes past the row are never read as voxels
            for (int64_t x = 0; x < nx; ++x) {
                const uint32_t r = rng() % 16;
                labels[size_t(x)] = r < 9 ? 0 : r < 15 ? uint8_t(1 + r % 3) : 255;
            }
            for (const ByteSelect select :
                 {ByteSelect{true, 0}, ByteSelect{false, 2}, ByteSelect{false, 255}}) {
                const size_t words = size_t((nx + 63) / 64);
                std::vector<uint64_t> want(words, 0);
                uint64_t wantCount = 0;
                for (int64_t x = 0; x < nx; ++x) {
                    const uint8_t l = labels[size_t(x)];
                    if (select.any ? l != 0 : l == select.key) {
                        want[size_t(x / 64)] |= uint64_t(1) << (x % 64);
                        ++wantCount;
                    }
                }
                std::vector<uint64_t> fast(words, ~uint64_t(0)), portable(words, ~uint64_t(0));
                EXPECT_EQ(packByteRow(labels.data(), nx, select, fast.data()), wantCount) << nx;
                EXPECT_EQ(packByteRowPortable(labels.data(), nx, select, portable.data()), wantCount) << nx;
                EXPECT_EQ(fast, want) << nx << " avx2 " << packByteRowUsesAvx2();
                EXPECT_EQ(portable, want) << nx;
            }
        }
    }
}

}  // namespace
}  // namespace rthdist::masks::detail
