#include "core/input_frame.hpp"

#include "core/certificate.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>
#include <type_traits>

#include "core/packed_float_scan.hpp"
#include "core/parallel.hpp"

namespace rthdist::core {

namespace {

constexpr size_t kChunk = size_t(1) << 16;

struct ChunkSummary {
    glm::dvec3 lo{0.0}, hi{0.0};
    size_t firstBad = ~size_t(0);
    bool any = false;
    bool floatExact = true;
};

Error setError(const char* name, const std::string& what) {
    return Error{ErrorCode::kInvalidArgument, std::string("point set ") + name + what};
}

// One chunk of a set with scalars T: min/max per axis in T (exact), the
// first non-finite point. Reads the caller's memory once, in place.
template <class T>
ChunkSummary summarizeChunk(const char* base, size_t stride, size_t begin, size_t end) {
    // Branch-free over the points (packed floats four at a time:
    // core/packed_float_scan.hpp); a chunk with a bad point is scanned
    // again for its first one.
    T lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    bool finite = true, floatExact = true;
    size_t from = begin;  // the points left to the loop below
    if constexpr (std::is_same_v<T, float>) {
        if (stride == 3 * sizeof(float)) {
            const PackedScan scan = scanPackedFloats(reinterpret_cast<const float*>(base) + 3 * begin,
                                                     end - begin, glm::vec3(-INFINITY), glm::vec3(INFINITY));
            for (int k = 0; k < 3; ++k) {
                lo[k] = scan.box.lo[k];
                hi[k] = scan.box.hi[k];
            }
            finite = !scan.nonFinite;
            from = end;  // scanned
        }
    }
    for (size_t i = from; i < end; ++i) {
        T v[3];
        std::memcpy(v, base + i * stride, sizeof(v));
        for (int k = 0; k < 3; ++k) {
            finite &= v[k] - v[k] == 0;  // 0 for finite values, NaN otherwise
            floatExact &= T(float(v[k])) == v[k];
            lo[k] = v[k] < lo[k] ? v[k] : lo[k];
            hi[k] = v[k] > hi[k] ? v[k] : hi[k];
        }
    }
    ChunkSummary s;
    s.any = true;
    s.floatExact = floatExact;
    s.lo = glm::dvec3(lo[0], lo[1], lo[2]);
    s.hi = glm::dvec3(hi[0], hi[1], hi[2]);
    if (!finite) {
        for (size_t i = begin; i < end && s.firstBad == ~size_t(0); ++i) {
            T v[3];
            std::memcpy(v, base + i * stride, sizeof(v));
            if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]))) s.firstBad = i;
        }
    }
    return s;
}

// (lo + hi) / 2 per axis without overflow near the double range
// (std::midpoint: the same value as 0.5 * (lo + hi) wherever that is finite).
glm::dvec3 boxCentre(const glm::dvec3& lo, const glm::dvec3& hi) {
    return glm::dvec3(std::midpoint(lo.x, hi.x), std::midpoint(lo.y, hi.y), std::midpoint(lo.z, hi.z));
}

void merge(ChunkSummary& into, const ChunkSummary& part) {
    into.firstBad = std::min(into.firstBad, part.firstBad);
    into.floatExact = into.floatExact && part.floatExact;
    if (!part.any) return;
    into.lo = into.any ? glm::min(into.lo, part.lo) : part.lo;
    into.hi = into.any ? glm::max(into.hi, part.hi) : part.hi;
    into.any = true;
}

}  // namespace

std::optional<Error> checkShape(const PointView& points, const char* name) {
    if (points.empty()) return setError(name, " is empty: the Hausdorff distance is undefined");
    if (points.count > kMaxSetPoints) return setError(name, " has more than 2^40 points");
    const size_t scalar = scalarBytes(points.scalar);
    if (points.data == nullptr || points.strideBytes < 3 * scalar || points.strideBytes % scalar != 0)
        return setError(name, ": a stride of " + std::to_string(points.strideBytes) +
                                  " bytes cannot hold three " + (scalar == 8 ? "doubles" : "floats") +
                                  " per point (or the data pointer is null)");
    if (points.count - 1 > (SIZE_MAX - 3 * scalar) / points.strideBytes)
        return setError(name, ": " + std::to_string(points.count) + " points of " +
                                  std::to_string(points.strideBytes) +
                                  " bytes span more than the address space");
    return std::nullopt;
}

Result<SetSummary> summarizeSet(const PointView& points, const char* name, int threads) {
    if (auto err = checkShape(points, name)) return *err;
    const char* base = static_cast<const char*>(points.data);
    const size_t chunk = core::balancedChunk(points.count, threads, size_t(1) << 12, kChunk);
    threads = core::resolveThreads(threads, points.count / chunk + 1);
    std::vector<ChunkSummary> parts(static_cast<size_t>(threads));
    core::parallelChunks(points.count, chunk, threads, [&](size_t begin, size_t end, int t) {
        merge(parts[size_t(t)], points.scalar == Scalar::kFloat64
                                    ? summarizeChunk<double>(base, points.strideBytes, begin, end)
                                    : summarizeChunk<float>(base, points.strideBytes, begin, end));
    });
    ChunkSummary all;
    for (const ChunkSummary& part : parts) merge(all, part);
    if (all.firstBad != ~size_t(0))
        return setError(name,
                        ": point " + std::to_string(all.firstBad) + " has a NaN or infinite coordinate");
    return SetSummary{Bounds{all.lo, all.hi}, all.floatExact};
}

glm::dvec3 searchOrigin(const SetSummary& a, const SetSummary& b) {
    if (a.floatExact && b.floatExact) return glm::dvec3(0.0);
    return boxCentre(glm::min(a.box.lo, b.box.lo), glm::max(a.box.hi, b.box.hi));
}

glm::dvec3 preparedOrigin(const SetSummary& set, const std::optional<glm::dvec3>& wanted) {
    if (set.floatExact) return glm::dvec3(0.0);
    return wanted ? *wanted : boxCentre(set.box.lo, set.box.hi);
}

bool frameKeepsBound(const SetSummary& a, const SetSummary& b, const glm::dvec3& origin) {
    const glm::dvec3 lo = glm::min(a.box.lo, b.box.lo), hi = glm::max(a.box.hi, b.box.hi);
    const double diagonal = glm::length(hi - lo);
    double m = 0.0;
    for (const SetSummary* s : {&a, &b}) {
        if (s->floatExact && origin == glm::dvec3(0.0)) continue;  // searched as it is
        const glm::dvec3 far = glm::max(glm::abs(s->box.lo - origin), glm::abs(s->box.hi - origin));
        m = std::max({m, far.x, far.y, far.z});
    }
    return m <= 4.0 * diagonal;
}

double searchMagnitude(const SetSummary& set, const glm::dvec3& origin) {
    // The box rounded to float as the points are (glm::vec3 of p - origin).
    const Bounds rounded{glm::dvec3(glm::vec3(set.box.lo - origin)),
                         glm::dvec3(glm::vec3(set.box.hi - origin))};
    return largestMagnitude(rounded);
}

std::vector<glm::vec3> roundedCopy(const PointView& points, const glm::dvec3& origin, int threads) {
    std::vector<glm::vec3> out(points.count);
    const size_t chunk = core::balancedChunk(points.count, threads, size_t(1) << 12, kChunk);
    threads = core::resolveThreads(threads, points.count / chunk + 1);
    core::parallelChunks(points.count, chunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) out[i] = glm::vec3(points.at(i) - origin);
    });
    return out;
}

FloatSet::FloatSet(const PointView& points, const glm::dvec3& origin, int threads) {
    if (points.packedFloat() && origin == glm::dvec3(0.0)) {
        m_span = std::span<const glm::vec3>(static_cast<const glm::vec3*>(points.data), points.count);
        return;
    }
    m_copy = roundedCopy(points, origin, threads);
    m_span = m_copy;
}

void restoreOriginal(HausdorffResult& r, const PointView& a, const PointView& b, int threads) {
    proveFromViews(r, a, b, threads);  // the certificate from these coordinates
    auto restore = [](Directed& d, const PointView& q, const PointView& t) {
        d.queryPoint = q.at(d.queryIndex);
        d.targetPoint = t.at(d.targetIndex);
        d.distance = exactDistance(d.queryPoint, d.targetPoint);
    };
    restore(r.aToB, a, b);
    r.hausdorff = r.aToB.distance;
    if (!r.directedOnly) {
        restore(r.bToA, b, a);
        r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
    }
    auto perPoint = [threads](PerPoint& pp, const PointView& q, const PointView& t) {
        if (pp.distance.empty()) return;  // nearest only
        const int workers = core::resolveThreads(threads, pp.nearest.size() / kChunk + 1);
        core::parallelChunks(pp.nearest.size(), kChunk, workers, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) pp.distance[i] = exactDistance(q.at(i), t.at(pp.nearest[i]));
        });
    };
    perPoint(r.aNearest, a, b);
    perPoint(r.bNearest, b, a);
}

}  // namespace rthdist::core
