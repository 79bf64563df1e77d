#include "api/narrowed_targets.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

#include "api/route_planner.hpp"
#include "core/parallel.hpp"

namespace rthdist::api {
namespace {

constexpr size_t kChunk = size_t(1) << 16;

double largestAbs(const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 m = glm::max(glm::abs(lo), glm::abs(hi));
    return std::max({m.x, m.y, m.z});
}

// Squared distance from p to the box (0 inside).
double boxDistance2(const glm::dvec3& p, const core::Bounds& box) {
    const glm::dvec3 d = glm::max(glm::max(box.lo - p, p - box.hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

}  // namespace

double frameMagnitude(const core::Bounds& box, bool floatExact) {
    const glm::dvec3 origin = floatExact ? glm::dvec3(0.0) : (box.lo + box.hi) * 0.5;
    return largestAbs(box.lo - origin, box.hi - origin);
}

std::optional<NarrowedTargets> narrowTargets(const PointView& q, const core::Bounds& qBox, bool qFloatExact,
                                             const PointView& t, const core::Bounds& tBox, bool tFloatExact,
                                             int threads) {
    if (q.count == 0 || t.count < 2) return std::nullopt;
    const bool floatExact = qFloatExact && tFloatExact;
    const core::Bounds both{glm::min(qBox.lo, tBox.lo), glm::max(qBox.hi, tBox.hi)};
    const double whole = frameMagnitude(both, floatExact);
    // The narrowed pair holds Q's box at least: no gain, no pass.
    if (!narrowingPays(whole, frameMagnitude(qBox, floatExact))) return std::nullopt;

    // d(q0, T) in double over every target.
    const glm::dvec3 q0 = q.at(0);
    double nearest2 = std::numeric_limits<double>::infinity();
    std::mutex merge;
    const int workers = core::resolveThreads(threads, t.count / kChunk + 1);
    core::parallelChunks(t.count, kChunk, workers, [&](size_t begin, size_t end, int) {
        double local = std::numeric_limits<double>::infinity();
        for (size_t i = begin; i < end; ++i) {
            const glm::dvec3 d = t.at(i) - q0;
            local = std::min(local, glm::dot(d, d));
        }
        const std::lock_guard<std::mutex> lock(merge);
        nearest2 = std::min(nearest2, local);
    });
    const double radius = (glm::length(qBox.hi - qBox.lo) + std::sqrt(nearest2)) * (1.0 + 0x1p-30);
    if (!std::isfinite(radius)) return std::nullopt;
    const core::Bounds reach{glm::max(qBox.lo - radius, tBox.lo), glm::min(qBox.hi + radius, tBox.hi)};
    const core::Bounds narrowed{glm::min(qBox.lo, reach.lo), glm::max(qBox.hi, reach.hi)};
    if (!narrowingPays(whole, frameMagnitude(narrowed, floatExact))) return std::nullopt;

    // The targets within R of Q's box, in input order.
    const double radius2 = radius * radius;
    const size_t chunks = (t.count + kChunk - 1) / kChunk;
    std::vector<std::vector<uint64_t>> parts(chunks);
    core::parallelChunks(t.count, kChunk, workers, [&](size_t begin, size_t end, int) {
        std::vector<uint64_t>& mine = parts[begin / kChunk];
        for (size_t i = begin; i < end; ++i)
            if (boxDistance2(t.at(i), qBox) <= radius2) mine.push_back(i);
    });
    NarrowedTargets out;
    out.original = core::concatenateParts<std::vector<uint64_t>>(parts);
    if (out.original.empty() || out.original.size() == t.count) return std::nullopt;
    out.radius = radius;
    const size_t pointBytes = 3 * scalarBytes(t.scalar);
    out.bytes.resize(out.original.size() * pointBytes);
    core::parallelChunks(out.original.size(), kChunk, workers, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k)
            std::memcpy(out.bytes.data() + k * pointBytes,
                        static_cast<const unsigned char*>(t.data) + out.original[k] * t.strideBytes,
                        pointBytes);
    });
    out.view =
        t.scalar == Scalar::kFloat64
            ? PointView::doubles(reinterpret_cast<const double*>(out.bytes.data()), out.original.size())
            : PointView::floats(reinterpret_cast<const float*>(out.bytes.data()), out.original.size());
    return out;
}

}  // namespace rthdist::api
