// The proof that a directed value is exact in double (issue 32), shared by
// every backend; docs/design.md ("The certificate") has the argument:
//
// The float search ends with every query settled (the self-check) and holding
// a best pair whose target is a real point (every stage lowers a query's best
// only with real targets). Let f(q) be that pair's float distance in the
// search frame, hf the largest f of an exact (not dead) query, and e the
// rounding slack below: the float distance of any pair differs from the
// exact distance of the same input points (times the frame's power-of-two
// scale s) by at most e. Then
//   - a query with f(q) < hf - 2e (outside the band) has a real target at
//     exact distance below (hf - e) / s: it cannot be the maximum once one is
//     proven at or above (hf - e) / s;
//   - each band query has an upper bound U(q), the exact distance to its
//     best target. In order of falling U, a band query whose U exceeds the
//     largest exact nearest distance L found so far gets its nearest target by
//     a brute force in double over the WHOLE target set (the device: every
//     target within U s + 3e in float, then double; the host: every target);
//     the others cannot exceed L;
//   - if L >= (hf - e) / s, L is h exactly in double (ties aside) and its pair
//     is the witness. Otherwise the search reported a maximum that no query
//     reaches in double, i.e. it missed a nearer target of that query: the
//     proof fails and the engine recomputes the direction (api/engine.cpp).
#pragma once

#include <glm/vec3.hpp>

#include <cmath>

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "rthdist/rthdist.hpp"

namespace rthdist::core {

// e / m: the slack of the float search relative to m, the largest |coordinate|
// of both sets in the search frame (after the origin and the scale). Each
// coordinate is rounded by at most 2^-24 m, so a pair's distance moves by at
// most 2 sqrt(3) 2^-24 m; the float differences, squares and sum add at most
// 2 sqrt(3) 2^-24 m + 1.5 * 2^-24 * 2 sqrt(3) m. The sum is below 12.2 * 2^-24 m;
// 16 * 2^-24 leaves room for the double recomputation and the float square
// roots of the band's thresholds (their margins are 2^-20 relative too).
inline constexpr double kSlackPerMagnitude = 0x1.0p-20;

[[nodiscard]] inline double searchSlack(double magnitude) { return kSlackPerMagnitude * magnitude; }

// The band's squared threshold (search units) for a float maximum hf2
// (squared): queries at or above it are settled again in double. Rounded down
// by a relative 2^-20, so the device's float evaluation of the same formula
// (shaders/check_queries.comp) is never above the real value.
[[nodiscard]] double bandThreshold2(double hf2, double slack);

// A query of the band: input indices of the query and of its best target.
struct BandQuery {
    uint64_t query = 0;
    uint64_t best = 0;
};

// One band query's nearest target in double so far.
struct BandNearest {
    uint64_t query = 0;
    uint64_t target = std::numeric_limits<uint64_t>::max();
    double distance = std::numeric_limits<double>::infinity();
    // Takes target t at exact distance d if nearer (ties: the smaller index).
    void offer(uint64_t t, double d) {
        if (d < distance || (d == distance && t < target)) {
            distance = d;
            target = t;
        }
    }
};

// What a backend leaves for the proof of one direction.
struct DirectionBand {
    bool present = false;  // the backend collected a band (else only the witness is checked)
    std::string failure;   // the band could not be collected (e.g. past its capacity)
    std::vector<BandQuery> queries;
    // Device brute forces already run: the candidate targets of a query (every
    // target within its bound), which a proof from other coordinates reuses.
    std::vector<std::pair<uint64_t, std::vector<uint64_t>>> candidates;
    double hf = 0.0;       // the float maximum (its square root), search units
    double slack = 0.0;    // e, search units
    double scale = 1.0;    // s: search units per input unit
    uint64_t witness = 0;  // the search's own witness query (input index)
};

// Coordinates of a set's points by input index, in double.
using PointAt = std::function<glm::dvec3(uint64_t)>;
// Fills each entry's nearest target in double over the whole target set
// (entries' `query` set, the rest as constructed); false when it cannot.
using BruteForce = std::function<bool(std::span<BandNearest>)>;

// The distance both backends and the oracle report: sqrt(dx^2 + dy^2 + dz^2) in double.
[[nodiscard]] inline double exactDistance(const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 d = a - b;
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

// What the certificate of one direction found.
struct DirectedProof {
    bool proven = false;               // the argument above holds: `distance` is h, exact in double
    uint64_t query = 0;                // the winning query (ties: the smaller index)
    uint64_t target = 0;               // its nearest target in double (ties: the smaller index)
    double distance = 0.0;             // their distance, in the input's units
    uint64_t band = 0;                 // queries of the band
    uint64_t bruteForced = 0;          // band queries whose nearest target was searched in double
    std::vector<BandNearest> settled;  // those queries and their exact nearest targets
    std::string failure;               // why not proven (empty when proven)
};

// Queries handed to one brute force at most (one pass over the targets).
inline constexpr size_t kBruteForceBatch = 64;
// The first batch of a host brute force (proveDirection's firstBatch): the
// CPU backend's band on a torus of 3M x 4M points held 97 and 936 queries,
// of which a first batch of 64 sent 45 and 64 through 4M targets each, 1 s
// of its 2.4 s on 2 cores, where one query each was needed.
inline constexpr size_t kHostFirstBatch = 1;

// The proof of one direction from its band (see the top of this file). Band
// queries with device candidates take their nearest from them; the others
// go to `bruteForce` in order of falling U, `firstBatch` queries at once
// first, then twice as many each time up to kBruteForceBatch. The proof
// stops at the first query whose U cannot exceed the largest exact distance
// so far, which is usually the second: a host brute force (one pass over
// every target per batch) starts at 1 (kHostFirstBatch); a device one, where
// a pass is a submission, at kBruteForceBatch.
[[nodiscard]] DirectedProof proveDirection(const DirectionBand& band, const PointAt& query,
                                           const PointAt& target, const BruteForce& bruteForce,
                                           size_t firstBatch = kBruteForceBatch);

// A host brute force over `targets` (n points, coordinates by `target`) on
// `threads` threads (EngineOptions::threads), for proveDirection.
[[nodiscard]] BruteForce hostBruteForce(const PointAt& query, const PointAt& target, uint64_t n, int threads);
// The same answer over the points of a view, read where they lie: each
// pair's squared distance is compared with the chunk's nearest so far and
// its square root taken only when it is smaller (the root is monotone and a
// chunk is scanned in rising index order, so a pair skipped could neither be
// nearer nor win a tie). ~1 ns a target and query on one core where the
// PointAt form costs several: at 1B targets a pass is what the proof costs.
[[nodiscard]] BruteForce hostBruteForce(const PointAt& query, const PointView& targets, int threads);

// proveDirection with the host's brute force over the view's targets on
// `threads` threads, its batches from kHostFirstBatch: what every proof on
// the host runs (the CPU backend's, proveFromViews).
[[nodiscard]] DirectedProof proveOnHost(const DirectionBand& band, const PointAt& query,
                                        const PointView& targets, int threads);

// Each direction of `r` whose backend left a band (r.proofMaterial) proven
// again from the caller's coordinates `a` and `b` (the band's indices are
// theirs): the witness, value and certificate from that proof, or the
// certificate unconfirmed (Engine recomputes it). Host brute forces run on
// `threads` threads.
void proveFromViews(HausdorffResult& r, const PointView& a, const PointView& b, int threads);

// Sets d's witness, value and certificate from a proof that holds (points
// from `query` and `target`); an unproven one leaves d's witness and value,
// its certificate unconfirmed. A per-point array (`perPoint`, if not empty)
// takes the settled queries' exact nearest targets, so that its maximum is
// the witness.
void applyProof(Directed& d, const DirectedProof& proof, const PointAt& query, const PointAt& target,
                PerPoint* perPoint = nullptr);

}  // namespace rthdist::core

namespace rthdist::detail {

// HausdorffResult::proofMaterial: each direction's band, left by the backend
// for a proof from the caller's own coordinates (the Engine's frame).
struct ProofMaterial {
    core::DirectionBand aToB, bToA;
};

}  // namespace rthdist::detail
