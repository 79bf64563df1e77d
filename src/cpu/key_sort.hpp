// Sorting by cell key, the first step of every CPU index build (the adaptive
// order of cpu/adaptive_order.hpp starts from it).
//
// Two sorts, both stable and linear in the number of keys:
// - radixSortKeys: LSD radix sort of (key << 32 | payload) values by their
//   key bits, in ceil(keyBits / 12) passes of equal digits; parallel when
//   `threads` > 1 (workers count and scatter contiguous parts; a digit's slots
//   are handed out in part order, which keeps every pass stable). A pass whose
//   digit is the same for every value is skipped (it would be the identity).
//   radixSortKeysSerial is the same sort on one thread with caller-owned
//   scratch, for ranges that fit in cache.
// - sortPointsByKey: points by a key per point. One MSD pass on the top (at
//   most 10) key bits scatters the (key << 32 | index) values into buckets,
//   reading the keys in order; each bucket's values are then sorted on their
//   remaining bits in place (buckets in parallel, in cache; a bucket of more
//   than 2^16 points by all threads); then the scaled coordinates are
//   gathered from the input in the sorted order, once (in a set in random
//   order each read is a miss: one pass of them costs less than carrying 12
//   bytes of coordinates through the scatter and each bucket's sort).
//   Ties keep ascending input index, so the result depends neither on the
//   thread count nor on the bucket sizes.
//
// Threading: `threads` workers (0 = all hardware threads) inside each call;
// the calls themselves are not meant to run concurrently on the same data.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

#include "core/uninit_vector.hpp"

namespace rthdist::cpu {

using core::UninitVector;

// Points in key order: what sortPointsByKey produces and the adaptive order
// refines (cpu/adaptive_order.hpp).
struct OrderedPoints {
    UninitVector<uint64_t> keyed;  // (key << 32 | input index), ascending key, ties by ascending index
    UninitVector<float> x, y, z;   // the points' scaled coordinates in the same order, then padding
};

// Sorts (key << 32 | payload) values by their key bits [32, 32 + keyBits)
// (keyBits in 0..32; higher key bits are ignored), stably.
void radixSortKeys(std::vector<uint64_t>& values, int keyBits, int threads = 1);
// The same in caller-owned memory (scratch: at least values.size()): true
// when the sorted values ended in scratch's first values.size() entries
// (an odd count of passes ran), false when in values.
[[nodiscard]] bool radixSortKeys(std::span<uint64_t> values, std::span<uint64_t> scratch, int keyBits,
                                 int threads);

// The same sort on the calling thread; `scratch` is resized as needed.
void radixSortKeysSerial(std::span<uint64_t> values, int keyBits, std::vector<uint64_t>& scratch);

// Sorts points[i] (multiplied by `scale` as cpu::scaled does) by keys[i]
// (only its low keyBits bits, keyBits in 0..32, are compared; the keyed
// values carry the key as given), stably. keys.size() == points.size().
// x, y and z end with `padding` entries of +inf after the points (room for
// reads past the end; keyed has none).
[[nodiscard]] OrderedPoints sortPointsByKey(std::span<const uint32_t> keys, int keyBits,
                                            std::span<const glm::vec3> points, double scale, int threads,
                                            size_t padding = 0);

}  // namespace rthdist::cpu
