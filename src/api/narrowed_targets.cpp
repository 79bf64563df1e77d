#include "api/narrowed_targets.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "api/route_planner.hpp"
#include "core/certificate.hpp"
#include "core/parallel.hpp"

namespace rthdist::api {
namespace {

constexpr size_t kChunk = size_t(1) << 16;

// Squared distance from p to the box (0 inside).
double boxDistance2(const glm::dvec3& p, const core::Bounds& box) {
    const glm::dvec3 d = glm::max(glm::max(box.lo - p, p - box.hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

}  // namespace

double frameMagnitude(const core::Bounds& box, bool floatExact) {
    const glm::dvec3 origin = floatExact ? glm::dvec3(0.0) : (box.lo + box.hi) * 0.5;
    return core::largestMagnitude(core::Bounds{box.lo - origin, box.hi - origin});
}

namespace {

// The points of `v` at `indices` (ascending), packed in v's scalar type.
PointSubset subsetOf(const PointView& v, std::vector<uint64_t> indices, int workers) {
    PointSubset out;
    out.original = std::move(indices);
    const size_t pointBytes = 3 * scalarBytes(v.scalar);
    out.bytes.resize(out.original.size() * pointBytes);
    core::parallelChunks(out.original.size(), kChunk, workers, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k)
            std::memcpy(out.bytes.data() + k * pointBytes,
                        static_cast<const unsigned char*>(v.data) + out.original[k] * v.strideBytes,
                        pointBytes);
    });
    out.view =
        v.scalar == Scalar::kFloat64
            ? PointView::doubles(reinterpret_cast<const double*>(out.bytes.data()), out.original.size())
            : PointView::floats(reinterpret_cast<const float*>(out.bytes.data()), out.original.size());
    return out;
}

// The indices of v's points for which keep(p) holds, in order.
template <class Keep>
std::vector<uint64_t> select(const PointView& v, int workers, const Keep& keep) {
    const size_t chunks = (v.count + kChunk - 1) / kChunk;
    std::vector<std::vector<uint64_t>> parts(chunks);
    core::parallelChunks(v.count, kChunk, workers, [&](size_t begin, size_t end, int) {
        std::vector<uint64_t>& mine = parts[begin / kChunk];
        for (size_t i = begin; i < end; ++i)
            if (keep(v.at(i))) mine.push_back(i);
    });
    return core::concatenateParts<std::vector<uint64_t>>(parts);
}

core::PointAt pointsOf(const PointView& v) {
    return [v](uint64_t i) { return v.at(i); };
}

// d(v[i], T) in double over every target (core::hostBruteForce).
double nearestDistance(const PointView& v, uint64_t i, const PointView& t, int threads) {
    core::BandNearest b{i};
    (void)core::hostBruteForce(pointsOf(v), pointsOf(t), t.count, threads)(std::span(&b, 1));
    return b.distance;
}

bool inside(const glm::dvec3& p, const core::Bounds& box) {
    return glm::all(glm::greaterThanEqual(p, box.lo)) && glm::all(glm::lessThanEqual(p, box.hi));
}

}  // namespace

Directed strayQueries(const PointSubset& strays, const PointView& t, PerPoint* perPoint, int threads) {
    const size_t n = strays.view.count;
    std::vector<core::BandNearest> nearest(n);
    std::vector<glm::dvec3> q(n);
    for (size_t k = 0; k < n; ++k) {
        nearest[k].query = k;
        q[k] = strays.view.at(k);
    }
    (void)core::hostBruteForce(pointsOf(strays.view), pointsOf(t), t.count, threads)(nearest);
    size_t win = 0;  // the largest distance, the smaller position on a tie
    for (size_t k = 1; k < n; ++k)
        if (nearest[k].distance > nearest[win].distance) win = k;
    Directed d;
    d.distance = nearest[win].distance;
    d.queryIndex = win;
    d.targetIndex = nearest[win].target;
    d.queryPoint = q[win];
    d.targetPoint = t.at(d.targetIndex);
    d.counters.queries = n;
    d.certificate.confirmed = true;
    d.certificate.query = d.queryIndex;
    d.certificate.nearest = d.targetIndex;
    d.certificate.distance = d.distance;
    d.certificate.band = n;
    if (perPoint != nullptr) {
        perPoint->nearest.resize(n);
        perPoint->distance.resize(n);
        for (size_t k = 0; k < n; ++k) {
            perPoint->nearest[k] = uint32_t(nearest[k].target);
            perPoint->distance[k] = nearest[k].distance;
        }
    }
    return d;
}

core::Bounds sampledCore(const PointView& q, size_t samples) {
    constexpr size_t kDrop = 8;
    const size_t step = std::max<size_t>(1, q.count / std::max<size_t>(samples, 1));
    std::vector<double> axis[3];
    for (size_t i = 0; i < q.count; i += step) {
        const glm::dvec3 p = q.at(i);
        for (int k = 0; k < 3; ++k) axis[k].push_back(p[k]);
    }
    core::Bounds box;
    for (int k = 0; k < 3; ++k) {
        std::vector<double>& v = axis[k];
        const size_t drop = v.size() > 4 * kDrop ? kDrop : 0;
        std::nth_element(v.begin(), v.begin() + ptrdiff_t(drop), v.end());
        const double lo = v[drop];
        std::nth_element(v.begin(), v.end() - 1 - ptrdiff_t(drop), v.end());
        const double hi = v[v.size() - 1 - drop], grow = hi - lo;
        box.lo[k] = lo - grow;
        box.hi[k] = hi + grow;
    }
    return box;
}

std::optional<NarrowedTargets> narrowTargets(const PointView& q, const core::Bounds& qBox, bool qFloatExact,
                                             const PointView& t, const core::Bounds& tBox, bool tFloatExact,
                                             int threads) {
    if (q.count == 0 || t.count < 2) return std::nullopt;
    const bool floatExact = qFloatExact && tFloatExact;
    const core::Bounds both{glm::min(qBox.lo, tBox.lo), glm::max(qBox.hi, tBox.hi)};
    const double whole = frameMagnitude(both, floatExact);
    const int workers = core::resolveThreads(threads, std::max(q.count, t.count) / kChunk + 1);
    NarrowedTargets out;

    // The core: every query when their own box can gain, else those within
    // a sampled box, when few lie outside it.
    core::Bounds coreBox = qBox;
    if (!narrowingPays(whole, frameMagnitude(qBox, floatExact))) {
        const core::Bounds sampled = sampledCore(q);
        if (!narrowingPays(whole, frameMagnitude(sampled, floatExact))) return std::nullopt;
        std::vector<uint64_t> strays =
            select(q, workers, [&](const glm::dvec3& p) { return !inside(p, sampled); });
        if (strays.empty() || strays.size() > kMaxStrayQueries || strays.size() == q.count)
            return std::nullopt;
        // A stray query far from every target makes h far larger than the
        // whole pair's slack (2^-20 of its magnitude): the whole search then
        // settles the core's queries at once (they cannot raise h), nothing
        // to gain. Checked before any copy.
        if (nearestDistance(q, strays.front(), t, threads) >= std::ldexp(whole, kNarrowGainLog2 - 20))
            return std::nullopt;
        std::vector<uint64_t> core;
        core.reserve(q.count - strays.size());
        for (uint64_t i = 0, k = 0; i < q.count; ++i) {
            if (k < strays.size() && strays[k] == i)
                ++k;
            else
                core.push_back(i);
        }
        out.core = subsetOf(q, std::move(core), workers);
        out.strays = subsetOf(q, std::move(strays), workers);
        coreBox = core::Bounds{out.core.view.at(0), out.core.view.at(0)};
        for (size_t i = 1; i < out.core.view.count; ++i) {
            const glm::dvec3 p = out.core.view.at(i);
            coreBox.lo = glm::min(coreBox.lo, p);
            coreBox.hi = glm::max(coreBox.hi, p);
        }
    }
    const PointView& coreView = out.strays.original.empty() ? q : out.core.view;

    const double radius =
        (glm::length(coreBox.hi - coreBox.lo) + nearestDistance(coreView, 0, t, threads)) * (1.0 + 0x1p-30);
    if (!std::isfinite(radius)) return std::nullopt;
    const core::Bounds reach{glm::max(coreBox.lo - radius, tBox.lo), glm::min(coreBox.hi + radius, tBox.hi)};
    const core::Bounds narrowed{glm::min(coreBox.lo, reach.lo), glm::max(coreBox.hi, reach.hi)};
    if (!narrowingPays(whole, frameMagnitude(narrowed, floatExact))) return std::nullopt;

    // The targets within R of the core's box, in input order.
    const double radius2 = radius * radius;
    std::vector<uint64_t> kept =
        select(t, workers, [&](const glm::dvec3& p) { return boxDistance2(p, coreBox) <= radius2; });
    if (kept.empty() || kept.size() == t.count) return std::nullopt;
    out.radius = radius;
    out.targets = subsetOf(t, std::move(kept), workers);
    return out;
}

}  // namespace rthdist::api
