// The largest of a device search's distances by chunks (core/searched_tops.hpp):
// the order puts a distance that is not a number >= 0 first, ties go to the
// smaller index, and the chunks' summary gives the whole scan's answer
// whatever the chunk size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "common/rng.hpp"
#include "core/searched_tops.hpp"

namespace rthdist {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(SearchedTops, NoNumberComesFirst) {
    EXPECT_EQ(core::searchedKey(kNaN), kInf);
    EXPECT_EQ(core::searchedKey(-1.0f), kInf);
    EXPECT_EQ(core::searchedKey(kInf), kInf);
    EXPECT_EQ(core::searchedKey(2.5f), 2.5f);
    EXPECT_EQ(core::searchedKey(0.0f), 0.0f);
    EXPECT_EQ(core::searchedKey(-0.0f), 0.0f);  // a number >= 0
}

TEST(SearchedTops, TheFirstOfATieStays) {
    const std::vector<float> d2{1.0f, 3.0f, 3.0f, 2.0f};
    EXPECT_EQ(core::SearchedTops::topOf(d2, 0, 4), 1u);
    EXPECT_EQ(core::SearchedTops::topOf(d2, 2, 4), 2u);
    EXPECT_EQ(core::SearchedTops::topOf(d2, 3, 4), 3u);
    const std::vector<float> none{1.0f, kInf, 5.0f, kNaN, -2.0f};
    EXPECT_EQ(core::SearchedTops::topOf(none, 0, 5), 1u);  // +inf, NaN and -2 tie above 5
    EXPECT_EQ(core::SearchedTops::topOf(none, 2, 5), 3u);
}

TEST(SearchedTops, ChunksGiveTheWholeScansAnswer) {
    test::Rng rng(9127);
    for (int trial = 0; trial < 200; ++trial) {
        const size_t n = 1 + size_t(rng.uniform(0.0, 300.0));
        std::vector<float> d2(n);
        for (float& v : d2) {
            const double u = rng.uniform(0.0, 1.0);
            // Few distinct values (ties), and now and then no number.
            v = u < 0.02   ? kNaN
                : u < 0.03 ? kInf
                : u < 0.04 ? -1.0f
                           : float(std::floor(rng.uniform(0.0, 8.0)));
        }
        const uint64_t whole = core::SearchedTops::topOf(d2, 0, n);
        for (const size_t chunk : {size_t(1), size_t(2), size_t(7), size_t(64), n, n + 5}) {
            core::SearchedTops tops;
            tops.chunk = chunk;
            for (size_t begin = 0; begin < n; begin += chunk)
                tops.top.push_back(core::SearchedTops::topOf(d2, begin, std::min(n, begin + chunk)));
            ASSERT_TRUE(tops.covers(n)) << "seed 9127 trial " << trial;
            EXPECT_EQ(tops.overall(d2), whole) << "seed 9127 trial " << trial << " chunk " << chunk;
            EXPECT_FALSE(tops.covers(n + chunk)) << "seed 9127 trial " << trial;
        }
    }
    EXPECT_FALSE(core::SearchedTops{}.covers(1));  // chunk 0: nothing summarized
}

}  // namespace
}  // namespace rthdist
