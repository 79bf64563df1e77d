#include "cpu/key_sort.hpp"

#include <algorithm>
#include <limits>

#include "core/parallel.hpp"
#include "cpu/target_index.hpp"

namespace rthdist::cpu {

using core::parallelChunks;
using core::resolveThreads;
namespace {

constexpr int kMaxDigit = 12;                    // 16 KiB of counts per part (8-bit digits measured slower)
constexpr size_t kMinPerPart = size_t(1) << 16;  // values per part of a parallel pass
constexpr int kTopDigit = 10;                    // buckets of the MSD pass: 1024 write streams per part
constexpr uint32_t kWideBucket = 1u << 16;       // buckets this large are sorted by all threads
constexpr uint32_t kInsertionSort = 32;          // buckets this small: insertion sort
constexpr uint32_t kComparisonSort = 512;        // then std::sort (unique values), then radix
constexpr uint64_t kLow32 = 0xffffffffull;
constexpr float kInf = std::numeric_limits<float>::infinity();

// Equal digits of at most kMaxDigit bits covering keyBits: 30 bits -> 3 x 10.
int digitBits(int keyBits) {
    const int passes = (keyBits + kMaxDigit - 1) / kMaxDigit;
    return passes == 0 ? 0 : (keyBits + passes - 1) / passes;
}

// Contiguous parts of n values for a parallel pass: kPartsPerThread per
// worker, pulled dynamically, so a worker that the OS preempts (cores shared
// with other work) holds up the pass by one small part, not by half of it.
struct Parts {
    static constexpr size_t kPartsPerThread = 8;
    size_t count = 1, size = 0;
    Parts(size_t n, int threads)
        : count(std::clamp<size_t>(n / kMinPerPart, 1, size_t(resolveThreads(threads)) * kPartsPerThread)),
          size((n + count - 1) / count) {}
    [[nodiscard]] size_t begin(size_t p, size_t n) const { return std::min(n, p * size); }
    [[nodiscard]] size_t end(size_t p, size_t n) const { return std::min(n, (p + 1) * size); }
};

// Turns per-part digit counts (part-major: counts[p * digits + d]) into each
// part's first slot per digit, digit by digit and parts in order (stable).
// Returns whether every value has the same digit (the pass is the identity).
bool exclusiveOffsets(std::vector<uint32_t>& counts, size_t parts, uint32_t digits, size_t n) {
    uint32_t sum = 0;
    bool oneDigit = false;
    for (uint32_t d = 0; d < digits; ++d) {
        const uint32_t before = sum;
        for (size_t p = 0; p < parts; ++p) {
            const uint32_t c = counts[p * digits + d];
            counts[p * digits + d] = sum;
            sum += c;
        }
        oneDigit = oneDigit || sum - before == n;
    }
    return oneDigit;
}

// A bucket's values sorted on their key bits below restBits, in place
// (stable: the scatter left them by ascending input index, and the values'
// higher key bits are the bucket's). `threads` > 1: the parallel sort, in
// `scratch` (at least the bucket's size) and back.
void sortBucket(std::span<uint64_t> values, int restBits, int threads, std::span<uint64_t> scratch,
                std::vector<uint64_t>& serialScratch) {
    const size_t count = values.size();
    if (restBits == 0 || count < 2) return;  // the stable scatter left it sorted
    if (threads > 1) {
        if (radixSortKeys(values, scratch, restBits, threads)) {
            parallelChunks(count, 1 << 16, threads, [&](size_t begin, size_t end, int) {
                std::copy(scratch.begin() + ptrdiff_t(begin), scratch.begin() + ptrdiff_t(end),
                          values.begin() + ptrdiff_t(begin));
            });
        }
        return;
    }
    if (count <= kComparisonSort) {
        // (rest, input index): the values' order within one bucket.
        const uint64_t restMask = restBits >= 32 ? kLow32 : (uint64_t(1) << restBits) - 1;
        const auto rank = [restMask](uint64_t v) { return (((v >> 32) & restMask) << 32) | (v & kLow32); };
        if (count <= kInsertionSort) {
            for (size_t i = 1; i < count; ++i) {
                const uint64_t x = values[i];
                size_t j = i;
                for (; j > 0 && rank(values[j - 1]) > rank(x); --j) values[j] = values[j - 1];
                values[j] = x;
            }
        } else {
            std::sort(values.begin(), values.end(),
                      [&](uint64_t a, uint64_t b) { return rank(a) < rank(b); });
        }
        return;
    }
    radixSortKeysSerial(values, restBits, serialScratch);
}

}  // namespace

bool radixSortKeys(std::span<uint64_t> values, std::span<uint64_t> scratch, int keyBits, int threads) {
    const int digit = digitBits(keyBits);
    const uint32_t digits = 1u << digit;
    const size_t n = values.size();
    const Parts parts(n, threads);
    std::vector<uint32_t> offsets(parts.count * digits);
    std::span<uint64_t> from = values, to = scratch.first(n);
    for (int shift = 32; shift < 32 + keyBits; shift += digit) {
        std::fill(offsets.begin(), offsets.end(), 0u);
        // The last digit may reach past keyBits: those bits are not part of the key.
        const uint32_t mask = (1u << std::min(digit, 32 + keyBits - shift)) - 1;
        auto digitOf = [shift, mask](uint64_t v) { return uint32_t(v >> shift) & mask; };
        parallelChunks(parts.count, 1, threads, [&](size_t p, size_t, int) {
            uint32_t* h = &offsets[p * digits];
            for (size_t i = parts.begin(p, n); i < parts.end(p, n); ++i) ++h[digitOf(from[i])];
        });
        if (exclusiveOffsets(offsets, parts.count, digits, n)) continue;
        parallelChunks(parts.count, 1, threads, [&](size_t p, size_t, int) {
            uint32_t* h = &offsets[p * digits];
            for (size_t i = parts.begin(p, n); i < parts.end(p, n); ++i) to[h[digitOf(from[i])]++] = from[i];
        });
        std::swap(from, to);
    }
    return from.data() != values.data();
}

void radixSortKeys(std::vector<uint64_t>& values, int keyBits, int threads) {
    std::vector<uint64_t> scratch(values.size());
    if (radixSortKeys(values, scratch, keyBits, threads)) values.swap(scratch);
}

void radixSortKeysSerial(std::span<uint64_t> values, int keyBits, std::vector<uint64_t>& scratch) {
    const int digit = digitBits(keyBits);
    const uint32_t digits = 1u << digit;
    const size_t n = values.size();
    scratch.resize(n);
    std::vector<uint32_t> offsets(digits);
    std::span<uint64_t> from = values, to = scratch;
    for (int shift = 32; shift < 32 + keyBits; shift += digit) {
        std::fill(offsets.begin(), offsets.end(), 0u);
        // The last digit may reach past keyBits: those bits are not part of the key.
        const uint32_t mask = (1u << std::min(digit, 32 + keyBits - shift)) - 1;
        auto digitOf = [shift, mask](uint64_t v) { return uint32_t(v >> shift) & mask; };
        for (const uint64_t v : from) ++offsets[digitOf(v)];
        if (exclusiveOffsets(offsets, 1, digits, n)) continue;
        for (const uint64_t v : from) to[offsets[digitOf(v)]++] = v;
        std::swap(from, to);
    }
    if (from.data() != values.data()) std::copy(from.begin(), from.end(), values.begin());
}

OrderedPoints sortPointsByKey(std::span<const uint32_t> keys, int keyBits, std::span<const glm::vec3> points,
                              double scale, int threads, size_t padding) {
    OrderedPoints out;
    const size_t n = keys.size();
    if (n == 0) return out;
    threads = resolveThreads(threads);
    const int topBits = std::min(keyBits, kTopDigit);
    const int restBits = keyBits - topBits;
    const uint32_t buckets = 1u << topBits;
    auto bucketOf = [restBits, buckets](uint32_t key) {
        return uint32_t(uint64_t(key) >> restBits) & (buckets - 1);
    };

    // MSD pass: stable scatter of the points into buckets by the top bits,
    // reading them in input order.
    const Parts parts(n, threads);
    std::vector<uint32_t> offsets(parts.count * buckets, 0u);
    parallelChunks(parts.count, 1, threads, [&](size_t p, size_t, int) {
        uint32_t* h = &offsets[p * buckets];
        for (size_t i = parts.begin(p, n); i < parts.end(p, n); ++i) ++h[bucketOf(keys[i])];
    });
    std::vector<uint32_t> bucketFirst(buckets + 1);
    for (uint32_t b = 0, sum = 0; b <= buckets; ++b) {
        bucketFirst[b] = sum;
        for (size_t p = 0; b < buckets && p < parts.count; ++p) sum += offsets[p * buckets + b];
    }
    exclusiveOffsets(offsets, parts.count, buckets, n);
    out.keyed.resize(n);  // every entry written by the scatter
    parallelChunks(parts.count, 1, threads, [&](size_t p, size_t, int) {
        uint32_t* h = &offsets[p * buckets];
        for (size_t i = parts.begin(p, n); i < parts.end(p, n); ++i)
            out.keyed[h[bucketOf(keys[i])]++] = (uint64_t(keys[i]) << 32) | i;
    });

    // Each bucket's values on their remaining bits, in place: wide ones with
    // every thread, one at a time, then the rest in parallel, each on one
    // thread. The values alone move (8 bytes each); the coordinates are
    // gathered once, below.
    // On a 100M-point torus (2 cores) the scatter 738 -> 142 ms and the wide
    // buckets 1203 -> 471 ms against moving the coordinates with the values
    // (20 bytes an entry through the scatter, each bucket copied out and
    // gathered back), for a gather of 839 ms: the sort 1977 -> 1481 ms.
    uint32_t widest = 0;
    for (uint32_t b = 0; b < buckets && threads > 1; ++b)
        widest = std::max(widest, bucketFirst[b + 1] - bucketFirst[b]);
    UninitVector<uint64_t> wideScratch(widest >= kWideBucket ? widest : 0);
    std::vector<std::vector<uint64_t>> serialScratch(static_cast<size_t>(threads));
    const std::span<uint64_t> keyed(out.keyed.data(), n);
    for (uint32_t b = 0; b < buckets && threads > 1; ++b) {
        const uint32_t count = bucketFirst[b + 1] - bucketFirst[b];
        if (count < kWideBucket) continue;
        sortBucket(keyed.subspan(bucketFirst[b], count), restBits, threads, wideScratch, serialScratch[0]);
    }
    parallelChunks(buckets, 16, threads, [&](size_t begin, size_t end, int w) {
        for (size_t b = begin; b < end; ++b) {
            const uint32_t count = bucketFirst[b + 1] - bucketFirst[b];
            if (count >= kWideBucket && threads > 1) continue;  // done above
            sortBucket(keyed.subspan(bucketFirst[b], count), restBits, 1, {}, serialScratch[size_t(w)]);
        }
    });

    // The scaled coordinates in the sorted order, read from the input by
    // index (the lines of points a few entries ahead asked for early: in a
    // set in random order each read is a miss).
    for (UninitVector<float>* v : {&out.x, &out.y, &out.z}) {
        v->reserve(n + padding);
        v->resize(n);
    }
    constexpr size_t kAhead = 32;
    parallelChunks(n, 1 << 14, threads, [&](size_t begin, size_t end, int) {
        for (size_t j = begin; j < end; ++j) {
            if (j + kAhead < end) __builtin_prefetch(&points[size_t(keyed[j + kAhead] & kLow32)]);
            const glm::vec3 s = scaled(points[size_t(keyed[j] & kLow32)], scale);
            out.x[j] = s.x, out.y[j] = s.y, out.z[j] = s.z;
        }
    });
    for (UninitVector<float>* v : {&out.x, &out.y, &out.z}) v->resize(n + padding, kInf);
    return out;
}

}  // namespace rthdist::cpu
