#include "api/certify.hpp"

#include <string>

#include "core/certificate.hpp"
#include "core/input_frame.hpp"
#include "core/search_mutant.hpp"
#include "cpu/cpu_hausdorff.hpp"

namespace rthdist::api {
namespace {

// The witness alone: its nearest target in double over every target.
bool witnessHolds(Directed& d, const PointView& q, const PointView& t, int threads) {
    const core::PointAt query = [&q](uint64_t i) { return q.at(i); };
    core::BandNearest nearest{d.queryIndex};
    if (!core::hostBruteForce(query, t, threads)(std::span(&nearest, 1))) return false;
    if (!(nearest.distance == d.distance)) return false;
    d.certificate = Certificate{};
    d.certificate.confirmed = true;
    d.certificate.query = d.queryIndex;
    d.certificate.nearest = nearest.target;
    d.certificate.distance = nearest.distance;
    return true;
}

// h(q, t) on the CPU backend, proven from q and t; kInternal when it is not.
std::optional<Error> recompute(Directed& d, PerPoint& perPoint, const PointView& q, const PointView& t,
                               const glm::dvec3& origin, int threads, const char* name) {
    const core::SearchMutantPause sound;  // tests' mutant (core/search_mutant.hpp) off
    const core::FloatSet fq(q, origin, threads), ft(t, origin, threads);
    Options options;
    options.directedOnly = true;
    options.threads = threads;
    options.perPointDistances = !perPoint.nearest.empty();
    Result<HausdorffResult> r = cpu::cpuHausdorff(fq.span(), ft.span(), options);
    if (!r)
        return Error{ErrorCode::kInternal, std::string("the certificate of ") + name +
                                               " did not hold and its recomputation on the CPU backend "
                                               "failed: " +
                                               r.error().message};
    core::restoreOriginal(*r, q, t, threads);  // the proof and per-point distances from q and t
    if (!r->aToB.certificate.confirmed)
        return Error{ErrorCode::kInternal, std::string("the certificate of ") + name +
                                               " did not hold, nor did it for its recomputation on the "
                                               "CPU backend"};
    const Counters counters = d.counters;
    d = r->aToB;
    d.counters = counters;
    d.certificate.recomputed = true;
    if (options.perPointDistances) {
        if (perPoint.distance.empty()) r->aNearest.distance.clear();  // nearest only, as asked
        perPoint = std::move(r->aNearest);
    }
    return std::nullopt;
}

}  // namespace

std::optional<Error> settleCertificates(HausdorffResult& r, const PointView& a, const PointView& b,
                                        int threads, bool canRecompute) {
    auto settle = [&](Directed& d, PerPoint& perPoint, const core::DirectionBand* band, const PointView& q,
                      const PointView& t, const char* name) -> std::optional<Error> {
        if (d.certificate.confirmed) return std::nullopt;
        const bool hasBand = band != nullptr && band->present;
        if (!hasBand && canRecompute && witnessHolds(d, q, t, threads)) return std::nullopt;
        if (!canRecompute)
            return Error{ErrorCode::kInternal,
                         std::string("the certificate of ") + name + " did not hold" +
                             (hasBand && !band->failure.empty() ? ": " + band->failure : std::string())};
        const std::string why = hasBand && !band->failure.empty() ? band->failure
                                : hasBand ? "its proof from the caller's coordinates failed"
                                          : "the witness query has a nearer target";
        auto err = recompute(d, perPoint, q, t, r.origin, threads, name);
        if (!err) d.certificate.failure = why;
        return err;
    };
    const detail::ProofMaterial* m = r.proofMaterial.get();
    if (auto err = settle(r.aToB, r.aNearest, m ? &m->aToB : nullptr, a, b, "h(A,B)")) return err;
    r.hausdorff = r.aToB.distance;
    if (!r.directedOnly) {
        if (auto err = settle(r.bToA, r.bNearest, m ? &m->bToA : nullptr, b, a, "h(B,A)")) return err;
        r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
    }
    r.proofMaterial.reset();
    return std::nullopt;
}

}  // namespace rthdist::api
