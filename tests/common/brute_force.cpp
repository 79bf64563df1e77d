#include "common/brute_force.hpp"

#include <cmath>
#include <limits>

#include "core/certificate.hpp"
#include "core/parallel.hpp"

namespace rthdist::oracle {

using core::parallelChunks;
using core::resolveThreads;
namespace {

struct Nearest {
    double distanceSquared;
    uint32_t targetIndex;
};

// Targets widened to double once, in SoA form (a plain copy, nothing clever).
struct Targets {
    std::vector<double> x, y, z;
    explicit Targets(std::span<const glm::vec3> t) : x(t.size()), y(t.size()), z(t.size()) {
        for (size_t j = 0; j < t.size(); ++j) {
            x[j] = t[j].x;
            y[j] = t[j].y;
            z[j] = t[j].z;
        }
    }
};

Nearest nearestOf(const glm::vec3& q, const Targets& t) {
    const double qx = q.x, qy = q.y, qz = q.z;
    const size_t n = t.x.size();
    Nearest best{std::numeric_limits<double>::infinity(), 0};
    for (size_t j = 0; j < n; ++j) {
        const double dx = qx - t.x[j];
        const double dy = qy - t.y[j];
        const double dz = qz - t.z[j];
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < best.distanceSquared) best = {d2, uint32_t(j)};  // strict: first index wins
    }
    return best;
}

constexpr size_t kChunk = 64;

}  // namespace

DirectedExact bruteForceDirected(std::span<const glm::vec3> queries, std::span<const glm::vec3> targets,
                                 int threads) {
    DirectedExact result;
    if (queries.empty() || targets.empty()) return result;
    const int workers = resolveThreads(threads, (queries.size() + kChunk - 1) / kChunk);
    struct Best {
        double d2 = -1.0;
        uint32_t query = 0;
        uint32_t target = 0;
    };
    const Targets soa(targets);
    std::vector<Best> perThread(static_cast<size_t>(workers));
    parallelChunks(queries.size(), kChunk, workers, [&](size_t begin, size_t end, int t) {
        Best& best = perThread[size_t(t)];
        for (size_t i = begin; i < end; ++i) {
            const Nearest n = nearestOf(queries[i], soa);
            if (n.distanceSquared > best.d2 || (n.distanceSquared == best.d2 && uint32_t(i) < best.query)) {
                best = {n.distanceSquared, uint32_t(i), n.targetIndex};
            }
        }
    });
    Best best;
    for (const Best& b : perThread) {
        if (b.d2 > best.d2 || (b.d2 == best.d2 && b.d2 >= 0.0 && b.query < best.query)) best = b;
    }
    result.distance = std::sqrt(best.d2);
    result.queryIndex = best.query;
    result.targetIndex = best.target;
    return result;
}

std::vector<double> bruteForceNearest(std::span<const glm::vec3> queries, std::span<const glm::vec3> targets,
                                      int threads) {
    std::vector<double> out(queries.size(), std::numeric_limits<double>::infinity());
    if (targets.empty()) return out;
    const Targets soa(targets);
    parallelChunks(queries.size(), kChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            out[i] = std::sqrt(nearestOf(queries[i], soa).distanceSquared);
        }
    });
    return out;
}

std::vector<NearestExact> bruteForceNearestIndexed(std::span<const glm::vec3> queries,
                                                   std::span<const glm::vec3> targets, int threads) {
    std::vector<NearestExact> out(queries.size(), {std::numeric_limits<double>::infinity(), 0});
    if (targets.empty()) return out;
    const Targets soa(targets);
    parallelChunks(queries.size(), kChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const Nearest n = nearestOf(queries[i], soa);
            out[i] = {std::sqrt(n.distanceSquared), n.targetIndex};
        }
    });
    return out;
}

NearestExact bruteForceNearestInDouble(const glm::dvec3& p, std::span<const glm::dvec3> targets) {
    NearestExact best{core::exactDistance(p, targets[0]), 0};
    for (size_t i = 1; i < targets.size(); ++i) {
        const double d = core::exactDistance(p, targets[i]);
        if (d < best.distance) best = {d, uint32_t(i)};
    }
    return best;
}

}  // namespace rthdist::oracle
