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

void insertionSort(std::span<uint64_t> v) {
    for (size_t i = 1; i < v.size(); ++i) {
        const uint64_t x = v[i];
        size_t j = i;
        for (; j > 0 && v[j - 1] > x; --j) v[j] = v[j - 1];
        v[j] = x;
    }
}

// A bucket's entries before it is permuted (kept per worker: no allocation
// per bucket).
struct BucketCopy {
    std::vector<uint64_t> order, scratch, keyed;
    std::vector<float> x, y, z;
};

// Sorts one bucket of `out` (in input order after the scatter) on the key
// bits below restBits, in place. The local order values (rest << 32 |
// position in the bucket) are unique and positions ascend with the input
// index, so sorting them sorts by (key, index).
void sortBucket(OrderedPoints& out, uint32_t first, uint32_t end, int restBits, int threads,
                BucketCopy& copy) {
    const uint32_t count = end - first;
    if (restBits == 0 || count < 2) return;  // the stable scatter left it sorted
    const uint32_t restMask = restBits >= 32 ? ~0u : (1u << restBits) - 1;
    std::vector<uint64_t>& order = copy.order;
    order.resize(count);
    copy.keyed.resize(count), copy.x.resize(count), copy.y.resize(count), copy.z.resize(count);
    parallelChunks(count, 1 << 14, threads, [&](size_t begin, size_t stop, int) {
        for (size_t j = begin; j < stop; ++j) {
            const size_t i = first + j;
            order[j] = (uint64_t(uint32_t(out.keyed[i] >> 32) & restMask) << 32) | j;
            copy.keyed[j] = out.keyed[i];
            copy.x[j] = out.x[i], copy.y[j] = out.y[i], copy.z[j] = out.z[i];
        }
    });
    if (threads > 1) {
        radixSortKeys(order, restBits, threads);
    } else if (count <= kInsertionSort) {
        insertionSort(order);
    } else if (count <= kComparisonSort) {
        std::sort(order.begin(), order.end());
    } else {
        radixSortKeysSerial(order, restBits, copy.scratch);
    }
    parallelChunks(count, 1 << 14, threads, [&](size_t begin, size_t stop, int) {
        for (size_t j = begin; j < stop; ++j) {
            const size_t i = first + j, from = size_t(order[j] & kLow32);
            out.keyed[i] = copy.keyed[from];
            out.x[i] = copy.x[from], out.y[i] = copy.y[from], out.z[i] = copy.z[from];
        }
    });
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
    for (UninitVector<float>* v : {&out.x, &out.y, &out.z}) {
        v->reserve(n + padding);
        v->resize(n);
    }
    parallelChunks(parts.count, 1, threads, [&](size_t p, size_t, int) {
        uint32_t* h = &offsets[p * buckets];
        for (size_t i = parts.begin(p, n); i < parts.end(p, n); ++i) {
            const uint32_t at = h[bucketOf(keys[i])]++;
            const glm::vec3 s = scaled(points[i], scale);
            out.keyed[at] = (uint64_t(keys[i]) << 32) | i;
            out.x[at] = s.x, out.y[at] = s.y, out.z[at] = s.z;
        }
    });

    // Each bucket on its remaining bits: wide ones with every thread, one at
    // a time, then the rest in parallel, each on one thread.
    std::vector<BucketCopy> copies(static_cast<size_t>(threads));
    for (uint32_t b = 0; b < buckets && threads > 1; ++b) {
        if (bucketFirst[b + 1] - bucketFirst[b] >= kWideBucket) {
            sortBucket(out, bucketFirst[b], bucketFirst[b + 1], restBits, threads, copies[0]);
        }
    }
    parallelChunks(buckets, 16, threads, [&](size_t begin, size_t end, int w) {
        for (size_t b = begin; b < end; ++b) {
            if (bucketFirst[b + 1] - bucketFirst[b] >= kWideBucket && threads > 1) continue;  // done above
            sortBucket(out, bucketFirst[b], bucketFirst[b + 1], restBits, 1, copies[size_t(w)]);
        }
    });
    for (UninitVector<float>* v : {&out.x, &out.y, &out.z}) v->resize(n + padding, kInf);
    return out;
}

}  // namespace rthdist::cpu
