// rthdist — statistics of per-point nearest distances (Options::perPointDistances).
//
// Definitions (the README repeats them):
//   Directed distances: d_A = every a's exact NN distance to B (HausdorffResult::
//   aNearest), d_B = every b's to A (bNearest). Pooled: the multiset d_A ∪ d_B
//   (|A| + |B| values; each point counts once, so the larger set weighs more).
//   min, max, mean = sum/n, RMS = sqrt(sum of squares / n), in double.
//   Percentile, nearest-rank method: for n values sorted ascending x_1 <= ... <= x_n
//   and 0 < p <= 100, P_p = x_r with r = ceil(p * n / 100) (computed as
//   ceil((p * n) / 100) in double, clamped to [1, n]); P_0 = x_1. The result is
//   always one of the distances (no interpolation), P_100 = max, and
//   P_50 of {1,2,3,4} is 2.
//   Symmetric percentile (the default, "max"): max(P_p(d_A), P_p(d_B)); HD95 is
//   the symmetric 95th percentile, so HD100 = H(A,B). The "pooled" variant is
//   P_p of the pooled multiset (some tools, e.g. medical-imaging HD95 code,
//   compute that one); both are reported, choose by name with percentileVariant.
//   Histogram: `bins` equal bins over [lo, hi]; value v goes to bin
//   floor((v - lo) / (hi - lo) * bins), v == hi to the last bin; values
//   outside [lo, hi] are counted in below/above, not in a bin. Auto range
//   (the default): lo = 0, hi = the pooled maximum (hi = 1 when every distance
//   is 0). All three histograms share the range so they can be compared.
//   Normalized values: value / diagonal, where diagonal is the length of the
//   bounding-box diagonal of A ∪ B (symmetric in A and B, as H is). Metro and
//   MeshLab divide by the diagonal of the first mesh's box instead; diagonalA
//   is reported so that figure can be formed too.
//
// Contract: result.aNearest must hold |a| distances (and bNearest |b| unless
// result.directedOnly), histogramBins >= 1, every percentile in [0, 100] and
// a fixed range finite with rangeLo < rangeHi; otherwise kInvalidArgument.
// With directedOnly the B->A and pooled blocks are empty (count 0) and
// symmetric values equal A->B.
// Threading: pure function of its inputs; reentrant.
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist {

struct StatsOptions {
    std::vector<double> percentiles{50.0, 90.0, 95.0, 99.0};  // each in [0, 100]
    int histogramBins = 20;                                   // >= 1
    // Histogram range: both 0 (the default) = auto; anything else is a fixed
    // range [rangeLo, rangeHi], both finite with rangeLo < rangeHi, else
    // hausdorffStats returns kInvalidArgument naming the range (an infinite
    // bound would give infinite bins, NaN edges).
    double rangeLo = 0.0;
    double rangeHi = 0.0;
};

struct Histogram {
    double lo = 0.0, hi = 0.0;      // range; bin i covers [lo + i*w, lo + (i+1)*w)
    std::vector<uint64_t> counts;   // one per bin
    uint64_t below = 0, above = 0;  // values outside [lo, hi]
};

struct Percentile {
    double p = 0.0;      // in [0, 100]
    double value = 0.0;  // nearest-rank percentile
};

struct DistanceStats {
    uint64_t count = 0;
    double min = 0.0, max = 0.0, mean = 0.0, rms = 0.0;
    std::vector<Percentile> percentiles;  // in StatsOptions order
    Histogram histogram;
};

struct HausdorffStats {
    DistanceStats aToB, bToA, pooled;
    std::vector<Percentile> symmetric;  // max of the two directed percentiles
    double diagonal = 0.0;              // bbox diagonal of A ∪ B (the normalizer)
    double diagonalA = 0.0, diagonalB = 0.0;
};

// Nearest-rank percentile of ascending `sorted` (non-empty), p in [0, 100].
[[nodiscard]] RTHDIST_API double percentileNearestRank(std::span<const double> sorted, double p);

// Statistics of one set of distances (any order); empty -> count 0. The
// histogram's range: finite, histogramLo < histogramHi (not checked here;
// hausdorffStats checks StatsOptions' range before it calls this).
[[nodiscard]] RTHDIST_API DistanceStats distanceStats(std::span<const double> distances,
                                                      const StatsOptions& options, double histogramLo,
                                                      double histogramHi);

// a, b: the sets the result was computed on, as given (float or double
// views; their diagonals are taken in double from these values, so a double
// input's diagonal is its own, not its float copy's).
[[nodiscard]] RTHDIST_API Result<HausdorffStats> hausdorffStats(const HausdorffResult& result,
                                                                const PointView& a, const PointView& b,
                                                                const StatsOptions& options = {});

// Symmetric ("max") or pooled ("pooled") percentile p by variant name; false
// when the name is unknown or p was not among StatsOptions::percentiles.
[[nodiscard]] RTHDIST_API bool percentileVariant(const HausdorffStats& stats, const std::string& variant,
                                                 double p, double& out);

}  // namespace rthdist
