// Selection instead of sorting (order_statistics.hpp).
#include "masks/order_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include "core/nearest_rank.hpp"
#include "core/parallel.hpp"
#include "core/uninit_vector.hpp"

namespace rthdist::masks::detail {
namespace {

constexpr size_t kParallelFrom = size_t(1) << 15;
constexpr size_t kChunk = size_t(1) << 13;
constexpr size_t kBuckets = 4096;

// The least and greatest of `values`, one parallel pass.
std::pair<double, double> rangeOf(std::span<const double> values, int threads) {
    const size_t chunks = (values.size() + kChunk - 1) / kChunk;
    std::vector<double> lows(chunks), highs(chunks);
    core::parallelChunks(values.size(), kChunk, threads, [&](size_t b, size_t e, int) {
        double lo = values[b], hi = values[b];
        for (size_t i = b; i < e; ++i) {
            lo = values[i] < lo ? values[i] : lo;
            hi = values[i] > hi ? values[i] : hi;
        }
        lows[b / kChunk] = lo;
        highs[b / kChunk] = hi;
    });
    return {*std::min_element(lows.begin(), lows.end()), *std::max_element(highs.begin(), highs.end())};
}

// The k-th and (k+1)-th smallest of non-empty `values` (the k-th twice when
// k is the last) by nth_element: the values are reordered.
std::pair<double, double> nthAndNext(std::span<double> values, size_t k) {
    const auto at = values.begin() + std::ptrdiff_t(k);
    std::nth_element(values.begin(), at, values.end());
    // After selecting k, the (k + 1)-th smallest is the least of what follows it.
    return {*at, k + 1 < values.size() ? *std::min_element(at + 1, values.end()) : *at};
}

// The k-th and (k+1)-th smallest of `values` (at least kParallelFrom of
// them; the k-th twice when k is the last) on `threads` threads: the range
// [min, max] cut into kBuckets equal buckets (the bucket of a value never
// decreases as the value grows), a histogram, and selection among the
// values of the buckets that hold ranks k and k + 1. Three parallel passes
// (two when the range is known); a histogram per thread.
std::pair<double, double> bucketSelect(std::span<const double> values, size_t k, int threads,
                                       ValueRange range) {
    const size_t n = values.size(), chunks = (n + kChunk - 1) / kChunk;
    const auto [lo, hi] = range ? *range : rangeOf(values, threads);
    if (!(hi > lo)) return {lo, lo};  // all equal
    const double scale = double(kBuckets) / (hi - lo);
    if (!std::isfinite(scale)) {  // a range of subnormal width
        std::vector<double> copy(values.begin(), values.end());
        return nthAndNext(copy, k);
    }
    const double low = lo;  // (a structured binding is not captured by clang 14)
    const auto bucketOf = [low, scale](double v) {
        return std::min(kBuckets - 1, size_t((v - low) * scale));
    };
    const int workers = core::resolveThreads(threads, chunks);
    // Each thread zeroes its own histogram at its first chunk (kept blocks:
    // core::UninitVector, no fresh pages per call).
    core::UninitVector<uint64_t> histograms;
    histograms.resize(size_t(workers) * kBuckets);
    std::vector<char> used(size_t(workers), 0);  // entry t: thread t's only
    core::parallelChunks(n, kChunk, workers, [&](size_t b, size_t e, int t) {
        uint64_t* h = histograms.data() + size_t(t) * kBuckets;
        if (!used[size_t(t)]) {
            std::fill(h, h + kBuckets, uint64_t(0));
            used[size_t(t)] = 1;
        }
        for (size_t i = b; i < e; ++i) ++h[bucketOf(values[i])];
    });
    std::vector<uint64_t> total(kBuckets, 0);
    for (int t = 0; t < workers; ++t)
        if (used[size_t(t)])
            for (size_t j = 0; j < kBuckets; ++j) total[j] += histograms[size_t(t) * kBuckets + j];
    // first: the bucket holding rank k (below: the values before it); last:
    // the one holding rank k + 1 (the same or a later one).
    const size_t next = std::min(k + 1, n - 1);
    size_t below = 0, first = 0;
    while (k >= below + total[first]) below += total[first++];
    size_t last = first, upTo = below + total[first];
    while (next >= upTo) upTo += total[++last];
    std::vector<std::vector<double>> inside(chunks);
    core::parallelChunks(n, kChunk, threads, [&](size_t b, size_t e, int) {
        std::vector<double> in;  // the thread's own (perSlice's note on shared lines)
        for (size_t i = b; i < e; ++i) {
            const size_t bucket = bucketOf(values[i]);
            if (bucket >= first && bucket <= last) in.push_back(values[i]);
        }
        inside[b / kChunk] = std::move(in);
    });
    std::vector<double> gathered = core::concatenateParts<std::vector<double>>(inside);
    // The values of ranks below .. upTo - 1: k and (unless k is the last) k + 1.
    return nthAndNext(gathered, k - below);
}

// The k-th and (k+1)-th smallest of non-empty `values` (the k-th twice when
// k is the last).
std::pair<double, double> kthAndNext(std::span<double> values, size_t k, int threads, ValueRange range) {
    const size_t n = values.size();
    if (n >= kParallelFrom && core::resolveThreads(threads, n / kChunk) > 1)
        return bucketSelect(values, k, threads, range);
    return nthAndNext(values, k);
}

}  // namespace

double kthSmallest(std::span<double> values, size_t k, int threads, ValueRange range) {
    return kthAndNext(values, k, threads, range).first;
}

double percentileLinear(std::span<double> values, double p, int threads, ValueRange range) {
    const size_t n = values.size();
    if (n == 0) return std::numeric_limits<double>::quiet_NaN();
    const double rank = (p / 100.0) * double(n - 1);
    const double lo = std::floor(rank);
    const size_t i = std::min(size_t(lo), n - 1);
    const double t = rank - lo;
    const auto [a, b] = kthAndNext(values, i, threads, range);
    const double diff = b - a;
    return t >= 0.5 ? b - diff * (1.0 - t) : a + diff * t;
}

double percentileTorchFloat32(std::span<double> values, double p, int threads, ValueRange range) {
    const size_t n = values.size();
    if (n == 0) return std::numeric_limits<double>::quiet_NaN();
    const float q = float(p / 100.0);
    const float rank = q * float(n - 1);  // one float32 product, as torch's q * last_index
    // torch indexes with the truncated rank and its ceiling; a rank that
    // float(n - 1) rounded past the last index (n > 2^24) is clamped.
    const size_t below = std::min(size_t(rank), n - 1);
    const size_t above = std::min(size_t(std::ceil(rank)), n - 1);
    const float weight = rank - float(below);
    const auto [a, next] = kthAndNext(values, below, threads, range);
    const double b = above == below ? a : next;
    const double w = double(weight);
    return w < 0.5 ? a + w * (b - a) : b - (b - a) * (1.0 - w);
}

double percentilePlastimatch(std::span<double> values, double p, int threads, ValueRange range) {
    const size_t n = values.size();
    if (n == 0) return 0.0;
    // As plastimatch's Hausdorff_distance computes it: a float fraction
    // times the count, minus 1, floored, all in float32. In double the rank
    // of p = 57 of n = 100 came out 55 (0.57 * 100 = 56.99999999999999),
    // float32's and the exact floor(pn/100 - 1) are 56.
    const float fraction = float(p / 100.0);
    const float rank = std::floor(fraction * float(n) - 1.0f);
    const double k = std::clamp(double(rank), 0.0, double(n - 1));
    return kthSmallest(values, size_t(k), threads, range);
}

double percentileNearestRank(std::span<double> values, double p, int threads, ValueRange range) {
    if (values.empty()) return 0.0;
    return kthSmallest(values, core::nearestRankIndex(values.size(), p), threads, range);
}

size_t countAtMost(std::span<const double> values, double limit, int threads) {
    const size_t chunks = (values.size() + kChunk - 1) / kChunk;
    std::vector<size_t> counts(chunks, 0);
    core::parallelChunks(values.size(), kChunk, threads, [&](size_t b, size_t e, int) {
        size_t c = 0;
        for (size_t i = b; i < e; ++i) c += values[i] <= limit;
        counts[b / kChunk] = c;
    });
    size_t total = 0;
    for (size_t c : counts) total += c;
    return total;
}

}  // namespace rthdist::masks::detail
