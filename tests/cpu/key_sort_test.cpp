// The CPU index's key sorts (cpu/key_sort.hpp) against std::stable_sort of
// the same values by the same key bits: radixSortKeys (parallel LSD),
// radixSortKeysSerial, and sortPointsByKey (MSD buckets moving the points
// with their keys). Fixed seeds, printed on failure through the test names
// and SCOPED_TRACE; degenerate inputs are named tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "cpu/key_sort.hpp"
#include "cpu/target_index.hpp"

namespace rthdist::cpu {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

uint32_t keyBitsOf(uint64_t v, int keyBits) {
    const uint32_t key = uint32_t(v >> 32);
    return keyBits >= 32 ? key : key & ((1u << keyBits) - 1);
}

// What radixSortKeys must produce: a stable sort by the key bits only.
std::vector<uint64_t> reference(std::vector<uint64_t> v, int keyBits) {
    std::stable_sort(v.begin(), v.end(), [keyBits](uint64_t a, uint64_t b) {
        return keyBitsOf(a, keyBits) < keyBitsOf(b, keyBits);
    });
    return v;
}

// (key << 32 | payload) with random keys below 2^keyBits (plus noise above
// them when `highNoise`), payloads numbering the values in input order, so a
// stable sort and an unstable one differ wherever keys repeat.
std::vector<uint64_t> randomValues(size_t n, int keyBits, uint32_t distinctKeys, bool highNoise,
                                   uint32_t seed) {
    std::mt19937 rng(seed);
    const uint32_t mask = keyBits >= 32 ? ~0u : (1u << keyBits) - 1;
    std::vector<uint32_t> palette(std::max<uint32_t>(distinctKeys, 1));
    for (uint32_t& k : palette) k = uint32_t(rng()) & mask;
    std::vector<uint64_t> v(n);
    for (size_t i = 0; i < n; ++i) {
        uint32_t key = palette[rng() % palette.size()];
        if (highNoise) key |= uint32_t(rng()) & ~mask;
        v[i] = (uint64_t(key) << 32) | uint32_t(i);
    }
    return v;
}

void expectRadixSortsLikeStableSort(const std::vector<uint64_t>& input, int keyBits) {
    const std::vector<uint64_t> expected = reference(input, keyBits);
    for (int threads : {1, 2, 3}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        std::vector<uint64_t> parallel = input;
        radixSortKeys(parallel, keyBits, threads);
        EXPECT_EQ(parallel, expected);
    }
    std::vector<uint64_t> serial = input, scratch;
    radixSortKeysSerial(serial, keyBits, scratch);
    EXPECT_EQ(serial, expected);
}

TEST(RadixSortKeys, Empty) { expectRadixSortsLikeStableSort({}, 30); }

TEST(RadixSortKeys, OneElement) { expectRadixSortsLikeStableSort({(uint64_t(12345) << 32) | 7u}, 30); }

TEST(RadixSortKeys, AllKeysEqualKeepInputOrder) {
    std::vector<uint64_t> v(200000);
    for (size_t i = 0; i < v.size(); ++i) v[i] = (uint64_t(0x2aaaaaa) << 32) | uint32_t(v.size() - i);
    expectRadixSortsLikeStableSort(v, 30);
}

TEST(RadixSortKeys, KeysUsingAllBits) {
    expectRadixSortsLikeStableSort(randomValues(150001, 32, 1u << 20, false, 11), 32);
}

TEST(RadixSortKeys, ManyRepeatedKeysAreStable) {
    // 3 * 65536 + 5 values: several parts per pass, not a multiple of any
    // thread count tried.
    expectRadixSortsLikeStableSort(randomValues(3 * 65536 + 5, 30, 100, false, 12), 30);
}

TEST(RadixSortKeys, BitsAboveKeyBitsAreIgnored) {
    for (int keyBits : {0, 1, 9, 17, 24, 30}) {
        SCOPED_TRACE("keyBits " + std::to_string(keyBits));
        expectRadixSortsLikeStableSort(randomValues(70001, keyBits, 5000, true, 13 + uint32_t(keyBits)),
                                       keyBits);
    }
}

TEST(RadixSortKeys, SmallInputsAtEveryLength) {
    for (size_t n = 0; n < 70; ++n) {
        SCOPED_TRACE("n " + std::to_string(n));
        expectRadixSortsLikeStableSort(randomValues(n, 30, 8, false, 100 + uint32_t(n)), 30);
    }
}

// sortPointsByKey against the stable sort of input indices by key, with the
// points scaled as cpu::scaled does and `padding` entries of +inf after them.
void expectPointsSortedLikeStableSort(const std::vector<uint32_t>& keys, int keyBits,
                                      const std::vector<glm::vec3>& points, double scale, size_t padding) {
    std::vector<uint32_t> order(keys.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return keyBitsOf(uint64_t(keys[a]) << 32, keyBits) < keyBitsOf(uint64_t(keys[b]) << 32, keyBits);
    });
    for (int threads : {1, 2, 3}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        const OrderedPoints out = sortPointsByKey(keys, keyBits, points, scale, threads, padding);
        ASSERT_EQ(out.keyed.size(), keys.size());
        ASSERT_EQ(out.x.size(), keys.size() + padding);
        ASSERT_EQ(out.y.size(), keys.size() + padding);
        ASSERT_EQ(out.z.size(), keys.size() + padding);
        size_t wrong = 0;
        for (size_t i = 0; i < order.size(); ++i) {
            const uint32_t from = order[i];
            const glm::vec3 p = scaled(points[from], scale);
            wrong += out.keyed[i] != ((uint64_t(keys[from]) << 32) | from) || out.x[i] != p.x ||
                     out.y[i] != p.y || out.z[i] != p.z;
        }
        EXPECT_EQ(wrong, 0u);
        for (size_t i = keys.size(); i < keys.size() + padding; ++i) {
            EXPECT_EQ(out.x[i], kInf);
            EXPECT_EQ(out.y[i], kInf);
            EXPECT_EQ(out.z[i], kInf);
        }
    }
}

std::vector<glm::vec3> randomPoints(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    std::vector<glm::vec3> p(n);
    for (glm::vec3& q : p) q = {u(rng), u(rng), u(rng)};
    return p;
}

std::vector<uint32_t> keysOf(const std::vector<uint64_t>& values) {
    std::vector<uint32_t> k(values.size());
    for (size_t i = 0; i < k.size(); ++i) k[i] = uint32_t(values[i] >> 32);
    return k;
}

TEST(SortPointsByKey, Empty) {
    const OrderedPoints out = sortPointsByKey({}, 30, {}, 1.0, 2, 8);
    EXPECT_TRUE(out.keyed.empty());
    EXPECT_TRUE(out.x.empty());
}

TEST(SortPointsByKey, OnePoint) { expectPointsSortedLikeStableSort({77}, 30, {{1.0f, -2.0f, 0.5f}}, 4.0, 8); }

TEST(SortPointsByKey, AllKeysEqualKeepInputOrder) {
    const size_t n = 100000;  // one bucket wider than 2^16: sorted by all threads
    expectPointsSortedLikeStableSort(std::vector<uint32_t>(n, 0x1234567u), 30, randomPoints(n, 21), 1.0, 8);
}

TEST(SortPointsByKey, RandomKeysWithRepeats) {
    const size_t n = 3 * 65536 + 7;
    expectPointsSortedLikeStableSort(keysOf(randomValues(n, 30, 20000, false, 22)), 30, randomPoints(n, 23),
                                     0.5, 8);
}

TEST(SortPointsByKey, KeysUsingAllBits) {
    const size_t n = 100003;
    expectPointsSortedLikeStableSort(keysOf(randomValues(n, 32, 200000, false, 24)), 32, randomPoints(n, 25),
                                     1.0, 0);
}

TEST(SortPointsByKey, SkewedBucketsAndFewKeyBits) {
    // Most keys in one top bucket (wide: all threads), the rest spread; then
    // key widths where the MSD pass alone decides (no bits left per bucket).
    std::vector<uint32_t> keys = keysOf(randomValues(150000, 30, 1u << 16, false, 26));
    for (size_t i = 0; i < keys.size(); i += 4) keys[i] &= 0xfffffu;  // top 10 of 30 bits zero
    expectPointsSortedLikeStableSort(keys, 30, randomPoints(keys.size(), 27), 1.0, 8);
    for (int keyBits : {0, 3, 10, 13}) {
        SCOPED_TRACE("keyBits " + std::to_string(keyBits));
        const size_t n = 20000;
        expectPointsSortedLikeStableSort(keysOf(randomValues(n, keyBits, 600, true, 28 + uint32_t(keyBits))),
                                         keyBits, randomPoints(n, 40), 1.0, 8);
    }
}

TEST(SortPointsByKey, BucketSizesAroundTheSortThresholds) {
    // Buckets of 2..2000 points: insertion, comparison and radix sorts inside.
    std::mt19937 rng(29);
    std::vector<uint32_t> keys;
    for (uint32_t bucket = 0; bucket < 64; ++bucket) {
        const uint32_t size = 2 + uint32_t(rng() % 2000);
        for (uint32_t j = 0; j < size; ++j) keys.push_back((bucket << 20) | (uint32_t(rng()) & 0xffu));
    }
    std::shuffle(keys.begin(), keys.end(), rng);
    expectPointsSortedLikeStableSort(keys, 30, randomPoints(keys.size(), 30), 2.0, 8);
}

}  // namespace
}  // namespace rthdist::cpu
