// rthdist masks — the conventions table: what each tool's Hausdorff distance
// on segmentation masks is made of, one row per convention (docs/masks.md has
// the table in prose, and the tools' sources each row was read from).
//
// Every rule of a convention is a field of its row, and the masks library
// reads the row instead of asking which convention it has: which points a
// mask gives, the metric, whether the connectivity option applies, the
// directed percentile, how the two directions combine, the float32
// tolerance, whether surface measures exist, and what the tool reports on an
// empty mask. Adding a convention is adding an enumerator and its row here
// (the static_assert below keeps them in step) and its test; a rule no row
// has yet (another percentile, another point set) also needs its code where
// that field is read.
//
// Contract: kConventionRules[size_t(c)] is convention c's row, for every c in
// kAllConventions (their order); names are distinct lower-case words.
// Constant data: thread-safe.
#pragma once

#include <array>
#include <cstddef>

namespace rthdist::masks {

enum class Convention { kRthdist, kMonai, kMedpy, kPlastimatch, kItk, kDeepmind };

// The points a mask gives.
enum class PointSet {
    kBoundary,    // voxel centres of the boundary: foreground voxels with a background (or
                  // outside) neighbour under the connectivity (mask XOR its erosion)
    kForeground,  // every foreground voxel; a voxel inside the other mask is at distance 0
    kSurfels,     // corners of the half-voxel-shifted grid with a 2x2x2 code other than 0
                  // and 255, each weighted by its marching-cubes area (DeepMind)
};

// Where distances are measured.
enum class Metric {
    kWorld,    // the voxel-to-world affine (a shear counts)
    kSpacing,  // the voxel spacing only (the affine's column norms), as the tools do
};

// A direction's HD-p from its distances.
enum class DirectedPercentile {
    kNone,           // not defined (HD only)
    kNearestRank,    // x_r, r = ceil(p n / 100) (rthdist/stats.hpp percentileNearestRank)
    kLinear,         // linear interpolation at rank p/100 (n - 1) (numpy.percentile)
    kTorchQuantile,  // kLinear, in torch.quantile's float32 rank and weight with
                     // MaskOptions::monaiFloat32 (else in double)
    kKthSmallest,    // the k-th smallest, k = floor(p/100 n - 1) clamped to [0, n - 1]
    kAreaWeighted,   // the first distance whose cumulative area / total >= p/100
};

// The two directions' HD-p made one number.
enum class Combination {
    kNone,    // no HD-p
    kMax,     // the larger of the two directed values
    kMean,    // their mean
    kPooled,  // kLinear over both directions' distances together
};

// What a tool reports on an empty mask, one direction: HD, mean, surface
// overlap, HD-p for p > 0 and for p = 0 ("nan", "inf", "0", "undefined": the
// tool defines none, "error": the tool raises).
struct EmptySideTexts {
    const char *hd, *mean, *overlap, *percentile, *percentileAt0;
};
// One case (both masks empty, or one): the combined numbers, the empty
// side's direction and the other side's (both empty: the same).
struct EmptyCaseTexts {
    const char *hd, *hdPercentile, *hdPercentileAt0, *assd, *msd, *surfaceDice;
    EmptySideTexts emptySide, otherSide;
};

struct ConventionRules {
    Convention convention;
    const char* name;  // as --convention and Python's convention= take it
    const char* rule;  // one line: point set, metric, percentile rule, combination
    PointSet points;
    Metric metric;
    bool connectivityOption;  // MaskOptions::connectivity applies (6 when 0); else always 6
    DirectedPercentile percentile;
    bool percentileAt0IsMax;  // HD-p at p = 0 is the directed maximum (MONAI's `if not percentile`)
    Combination combination;
    bool float32Tolerance;  // with MaskOptions::monaiFloat32: float(d) <= float(tolerance)
    bool surfaceMeasures;   // ASSD, surface overlaps and Dice defined (else NaN)
    EmptyCaseTexts bothEmpty, oneEmpty;
};

namespace conventions_detail {
inline constexpr const char* kU = "undefined";
inline constexpr EmptyCaseTexts kUndefined{
    kU, kU, kU, kU, kU, kU, {kU, kU, kU, kU, kU}, {kU, kU, kU, kU, kU}};
inline constexpr const char* kE = "error";
inline constexpr EmptyCaseTexts kError{kE, kE, kE, kE, kE, kE, {kE, kE, kE, kE, kE}, {kE, kE, kE, kE, kE}};
inline constexpr EmptySideTexts kNanSide{"nan", "nan", "nan", "nan", "nan"};
inline constexpr EmptyCaseTexts kAllNan{"nan", "nan", "nan", "nan", "nan", "nan", kNanSide, kNanSide};
}  // namespace conventions_detail

// The table. Empty-mask texts were read from the tools' code: MONAI d388d1c
// (get_surface_distance, _compute_percentile_hausdorff_distance,
// compute_average_surface_distance, compute_surface_dice), DeepMind
// surface-distance 1f805ce (compute_robust_hausdorff,
// compute_average_surface_distance, compute_surface_overlap_at_tolerance,
// compute_surface_dice_at_tolerance), MedPy (__surface_distances raises).
inline constexpr std::array kConventionRules{
    ConventionRules{Convention::kRthdist, "rthdist",
                    "boundary voxels (connectivity), world coordinates (affine); HD-p = max of the two "
                    "directed nearest-rank percentiles",
                    PointSet::kBoundary, Metric::kWorld, true, DirectedPercentile::kNearestRank, false,
                    Combination::kMax, false, true, conventions_detail::kUndefined,
                    conventions_detail::kUndefined},
    // MONAI: with one mask empty every distance of both directions is inf (one
    // per edge voxel of the other mask); torch.quantile interpolates inf - inf
    // (NaN) but p = 0 takes the maximum; surface Dice counts none of them.
    ConventionRules{Convention::kMonai, "monai",
                    "mask XOR erosion (6-connected), spacing; HD-p = max of the two directed linear "
                    "percentiles (torch.quantile)",
                    PointSet::kBoundary, Metric::kSpacing, false, DirectedPercentile::kTorchQuantile, true,
                    Combination::kMax, true, true, conventions_detail::kAllNan,
                    EmptyCaseTexts{"inf",
                                   "nan",
                                   "inf",
                                   "inf",
                                   "inf",
                                   "0",
                                   {"inf", "inf", "0", "nan", "inf"},
                                   {"inf", "inf", "0", "nan", "inf"}}},
    ConventionRules{Convention::kMedpy, "medpy",
                    "mask XOR erosion (connectivity), spacing; HD-p = linear percentile of both directions "
                    "pooled",
                    PointSet::kBoundary, Metric::kSpacing, true, DirectedPercentile::kLinear, false,
                    Combination::kPooled, false, true, conventions_detail::kError,
                    conventions_detail::kError},
    // plastimatch's statistics stay 0 on two empty masks; it has no surface Dice.
    ConventionRules{Convention::kPlastimatch, "plastimatch",
                    "boundary voxels (6-connected), spacing; HD-p = mean of the two directed k-th smallest, "
                    "k = floor(p/100 n - 1)",
                    PointSet::kBoundary, Metric::kSpacing, false, DirectedPercentile::kKthSmallest, false,
                    Combination::kMean, false, true,
                    EmptyCaseTexts{"0",
                                   "0",
                                   "0",
                                   "0",
                                   "0",
                                   conventions_detail::kU,
                                   {"0", "0", conventions_detail::kU, "0", "0"},
                                   {"0", "0", conventions_detail::kU, "0", "0"}},
                    conventions_detail::kUndefined},
    ConventionRules{Convention::kItk, "itk",
                    "all foreground voxels (inside the other = 0), spacing; HD only; average = mean of the "
                    "directed means",
                    PointSet::kForeground, Metric::kSpacing, false, DirectedPercentile::kNone, false,
                    Combination::kNone, false, false, conventions_detail::kUndefined,
                    conventions_detail::kUndefined},
    // DeepMind: a side without surfels averages nothing (0/0); its robust HD is inf.
    ConventionRules{
        Convention::kDeepmind, "deepmind",
        "surfels on the half-voxel-shifted grid with marching-cubes areas, spacing; HD-p = max of "
        "the two directed area-weighted percentiles (first cumulative area fraction >= p/100)",
        PointSet::kSurfels, Metric::kSpacing, false, DirectedPercentile::kAreaWeighted, false,
        Combination::kMax, false, true,
        EmptyCaseTexts{"inf",
                       "inf",
                       "inf",
                       "nan",
                       "nan",
                       "nan",
                       {"inf", "nan", "nan", "inf", "inf"},
                       {"inf", "nan", "nan", "inf", "inf"}},
        EmptyCaseTexts{"inf",
                       "inf",
                       "inf",
                       "inf",
                       "nan",
                       "0",
                       {"inf", "nan", "nan", "inf", "inf"},
                       {"inf", "inf", "0", "inf", "inf"}}},
};

// Every convention, in the table's order.
inline constexpr std::array<Convention, kConventionRules.size()> kAllConventions = [] {
    std::array<Convention, kConventionRules.size()> all{};
    for (size_t i = 0; i < all.size(); ++i) all[i] = kConventionRules[i].convention;
    return all;
}();

namespace conventions_detail {
constexpr bool rowsInOrder() {
    for (size_t i = 0; i < kConventionRules.size(); ++i)
        if (size_t(kConventionRules[i].convention) != i) return false;
    return true;
}
}  // namespace conventions_detail
static_assert(conventions_detail::rowsInOrder(), "kConventionRules[i] is Convention(i)'s row, one row each");

// Convention c's row (c from kAllConventions).
[[nodiscard]] constexpr const ConventionRules& conventionRules(Convention c) {
    return kConventionRules[size_t(c)];
}

}  // namespace rthdist::masks
