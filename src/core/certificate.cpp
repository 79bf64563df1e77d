#include "core/certificate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>

#include "core/parallel.hpp"

namespace rthdist::core {
namespace {

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

}  // namespace

double bandThreshold2(double hf2, double slack) {
    const double lo = std::max(std::sqrt(std::max(hf2, 0.0)) - 2.0 * slack, 0.0);
    return lo * lo * (1.0 - kSlackPerMagnitude);
}

namespace {

// A host brute force over n targets: the band's queries gathered once, the
// targets cut into chunks on the pool, scan(begin, end, q, local) filling
// each chunk's nearest per query (`local`, fresh), merged under a lock
// (BandNearest::offer breaks ties by the smaller index, so the order of
// the merges does not matter).
template <class Scan>
BruteForce bruteForceBy(const PointAt& query, uint64_t n, int threads, Scan scan) {
    return [query, n, threads, scan](std::span<BandNearest> band) {
        if (band.empty()) return true;
        std::vector<glm::dvec3> q(band.size());
        for (size_t k = 0; k < band.size(); ++k) q[k] = query(band[k].query);
        std::mutex merge;
        constexpr size_t kChunk = size_t(1) << 15;
        const int workers = resolveThreads(threads, n / kChunk + 1);
        parallelChunks(n, kChunk, workers, [&](size_t begin, size_t end, int) {
            std::vector<BandNearest> local(band.size());
            scan(begin, end, q, local);
            const std::lock_guard<std::mutex> lock(merge);
            for (size_t k = 0; k < band.size(); ++k) band[k].offer(local[k].target, local[k].distance);
        });
        return true;
    };
}

// One chunk [begin, end) of a view's targets against the queries `q`, into
// `local`: see hostBruteForce's view form.
template <class T>
void scanChunk(const char* base, size_t stride, size_t begin, size_t end, const std::vector<glm::dvec3>& q,
               std::vector<BandNearest>& local) {
    std::vector<double> best2(q.size(), std::numeric_limits<double>::infinity());
    for (size_t t = begin; t < end; ++t) {
        T v[3];
        std::memcpy(v, base + t * stride, sizeof(v));
        const glm::dvec3 p(v[0], v[1], v[2]);
        for (size_t k = 0; k < q.size(); ++k) {
            const glm::dvec3 d = q[k] - p;  // as exactDistance
            const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            if (!(d2 < best2[k])) continue;
            local[k].offer(t, std::sqrt(d2));
            if (local[k].target == t) best2[k] = d2;
        }
    }
}

}  // namespace

BruteForce hostBruteForce(const PointAt& query, const PointAt& target, uint64_t n, int threads) {
    return bruteForceBy(query, n, threads,
                        [target](size_t begin, size_t end, const std::vector<glm::dvec3>& q,
                                 std::vector<BandNearest>& local) {
                            for (size_t t = begin; t < end; ++t) {
                                const glm::dvec3 p = target(t);
                                for (size_t k = 0; k < q.size(); ++k)
                                    local[k].offer(t, exactDistance(q[k], p));
                            }
                        });
}

BruteForce hostBruteForce(const PointAt& query, const PointView& targets, int threads) {
    return bruteForceBy(query, targets.size(), threads,
                        [targets](size_t begin, size_t end, const std::vector<glm::dvec3>& q,
                                  std::vector<BandNearest>& local) {
                            const auto* base = static_cast<const char*>(targets.data);
                            if (targets.scalar == Scalar::kFloat64)
                                scanChunk<double>(base, targets.strideBytes, begin, end, q, local);
                            else
                                scanChunk<float>(base, targets.strideBytes, begin, end, q, local);
                        });
}

DirectedProof proveDirection(const DirectionBand& band, const PointAt& query, const PointAt& target,
                             const BruteForce& bruteForce, size_t firstBatch) {
    DirectedProof p;
    p.band = band.queries.size();
    if (!band.failure.empty()) {
        p.failure = band.failure;
        return p;
    }
    if (band.queries.empty()) {
        p.failure = "the band is empty (the search's maximum has no query)";
        return p;
    }
    // U per band query, then in falling order (ties: the smaller query index).
    struct Entry {
        double upper;
        uint64_t query, best;
    };
    std::vector<Entry> order;
    order.reserve(band.queries.size());
    for (const BandQuery& b : band.queries)
        order.push_back({exactDistance(query(b.query), target(b.best)), b.query, b.best});
    std::sort(order.begin(), order.end(), [](const Entry& x, const Entry& y) {
        return x.upper > y.upper || (x.upper == y.upper && x.query < y.query);
    });
    // Indices into band.candidates, not pointers: a device brute force
    // appends to it while the proof runs (CertificatePass::bruteForce).
    std::vector<std::pair<uint64_t, size_t>> known;
    for (size_t k = 0; k < band.candidates.size(); ++k) known.emplace_back(band.candidates[k].first, k);
    std::sort(known.begin(), known.end());
    auto candidatesOf = [&](uint64_t q) -> const std::vector<uint64_t>* {
        auto it = std::lower_bound(known.begin(), known.end(), std::make_pair(q, size_t(0)));
        return it != known.end() && it->first == q ? &band.candidates[it->second].second : nullptr;
    };
    // Below (hf - e) / s a query cannot matter: the proof needs a value at or
    // above it, which no such query can exceed.
    const double floor = (band.hf - band.slack) / band.scale;
    BandNearest win;
    bool have = false;
    auto settles = [&](double upper) { return upper >= floor && (!have || upper > win.distance); };
    auto take = [&](const BandNearest& b) {
        if (!have || b.distance > win.distance || (b.distance == win.distance && b.query < win.query))
            win = b;
        have = true;
    };
    size_t i = 0;
    size_t batchSize = std::clamp<size_t>(firstBatch, 1, kBruteForceBatch);
    while (i < order.size()) {
        // A query whose bound does not exceed the largest exact distance so
        // far cannot raise it (nor win a tie: its index is larger, or it ties
        // a value already reached); neither can any after it.
        if (!settles(order[i].upper)) break;
        if (const std::vector<uint64_t>* list = candidatesOf(order[i].query)) {
            BandNearest b{order[i].query};
            const glm::dvec3 q = query(order[i].query);
            b.offer(order[i].best, order[i].upper);
            for (uint64_t t : *list) b.offer(t, exactDistance(q, target(t)));
            ++p.bruteForced;
            p.settled.push_back(b);
            take(b);
            ++i;
            continue;
        }
        std::vector<BandNearest> batch;
        for (size_t j = i; j < order.size() && batch.size() < batchSize; ++j) {
            if (!settles(order[j].upper)) break;
            if (candidatesOf(order[j].query) != nullptr) break;
            BandNearest b{order[j].query};
            b.offer(order[j].best, order[j].upper);  // the bound a device brute force needs
            batch.push_back(b);
        }
        if (!bruteForce || !bruteForce(batch)) {
            p.failure = "band query " + std::to_string(order[i].query) +
                        " needs a brute force in double that this route cannot run";
            return p;
        }
        p.bruteForced += batch.size();
        batchSize = std::min(2 * batchSize, kBruteForceBatch);
        for (const BandNearest& b : batch) {
            if (b.target == std::numeric_limits<uint64_t>::max()) {
                p.failure = "band query " + std::to_string(b.query) + " found no target in its brute force";
                return p;
            }
            p.settled.push_back(b);
            take(b);
        }
        i += batch.size();
    }
    if (!have) {
        p.failure = "no query of the band reaches the search's maximum " + number(band.hf / band.scale) +
                    " within the slack";
        return p;
    }
    p.query = win.query;
    p.target = win.target;
    p.distance = win.distance;
    // Outside the band every query is nearer than (hf - e) / s.
    if (!(win.distance * band.scale >= band.hf - band.slack)) {
        p.failure = "the search's maximum " + number(band.hf / band.scale) +
                    " is not reached in double: the largest nearest distance of the band is " +
                    number(win.distance) + " (query " + std::to_string(win.query) + ")";
        return p;
    }
    p.proven = true;
    return p;
}

void applyProof(Directed& d, const DirectedProof& proof, const PointAt& query, const PointAt& target,
                PerPoint* perPoint) {
    d.certificate = Certificate{};
    d.certificate.band = proof.band;
    if (!proof.proven) return;
    if (perPoint != nullptr && !perPoint->nearest.empty()) {
        for (const BandNearest& b : proof.settled) {
            perPoint->nearest[b.query] = uint32_t(b.target);
            if (!perPoint->distance.empty()) perPoint->distance[b.query] = b.distance;
        }
    }
    d.queryIndex = proof.query;
    d.targetIndex = proof.target;
    d.queryPoint = query(proof.query);
    d.targetPoint = target(proof.target);
    d.distance = proof.distance;
    d.certificate.confirmed = true;
    d.certificate.query = proof.query;
    d.certificate.nearest = proof.target;
    d.certificate.distance = proof.distance;
}

DirectedProof proveOnHost(const DirectionBand& band, const PointAt& query, const PointView& targets,
                          int threads) {
    const PointAt target = [&targets](uint64_t i) { return targets.at(i); };
    return proveDirection(band, query, target, hostBruteForce(query, targets, threads), kHostFirstBatch);
}

void proveFromViews(HausdorffResult& r, const PointView& a, const PointView& b, int threads) {
    if (!r.proofMaterial) return;
    auto one = [threads](Directed& d, PerPoint& pp, const DirectionBand& band, const PointView& q,
                         const PointView& t) {
        if (!band.present) return;
        const PointAt query = [&q](uint64_t i) { return q.at(i); };
        const PointAt target = [&t](uint64_t i) { return t.at(i); };
        applyProof(d, proveOnHost(band, query, t, threads), query, target, &pp);
    };
    one(r.aToB, r.aNearest, r.proofMaterial->aToB, a, b);
    if (!r.directedOnly) one(r.bToA, r.bNearest, r.proofMaterial->bToA, b, a);
}

}  // namespace rthdist::core
