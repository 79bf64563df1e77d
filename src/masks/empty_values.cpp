// What each convention's tool reports for a row with an empty mask
// (masks.hpp emptyValues), one row of a table per convention, read from the
// tools' code at the commits of ../shared/MASKS.md: MONAI d388d1c
// (get_surface_distance, _compute_percentile_hausdorff_distance,
// compute_average_surface_distance, compute_surface_dice), DeepMind
// surface-distance 1f805ce (compute_robust_hausdorff,
// compute_average_surface_distance, compute_surface_overlap_at_tolerance,
// compute_surface_dice_at_tolerance), MedPy (__surface_distances raises).
#include <array>

#include "masks/masks.hpp"

namespace rthdist::masks {
namespace {

// One direction's texts: HD, mean, surface overlap, HD-p for p > 0 and for p = 0.
struct SideTexts {
    const char *hd, *mean, *overlap, *percentile, *percentileAt0;
};

// One case (both empty, or one): the combined numbers, then the empty
// side's direction and the other side's (both empty: the same).
struct CaseTexts {
    const char *hd, *hdPercentile, *hdPercentileAt0, *assd, *msd, *surfaceDice;
    SideTexts emptySide, otherSide;
};

struct EmptyRow {
    Convention convention;
    CaseTexts both, one;
};

constexpr const char* kU = "undefined";
constexpr CaseTexts kUndefined{kU, kU, kU, kU, kU, kU, {kU, kU, kU, kU, kU}, {kU, kU, kU, kU, kU}};
constexpr const char* kE = "error";
constexpr CaseTexts kError{kE, kE, kE, kE, kE, kE, {kE, kE, kE, kE, kE}, {kE, kE, kE, kE, kE}};

// MONAI: with one mask empty every distance of both directions is inf (one
// per edge voxel of the other mask); torch.quantile interpolates inf - inf
// (NaN) but p = 0 takes the maximum; surface Dice counts none of them.
constexpr SideTexts kMonaiOneSide{"inf", "inf", "0", "nan", "inf"};
// DeepMind: a side without surfels averages nothing (0/0); its robust HD is inf.
constexpr SideTexts kDeepmindNoSurfels{"inf", "nan", "nan", "inf", "inf"};

constexpr std::array<EmptyRow, kAllConventions.size()> kEmptyRows{{
    {Convention::kRthdist, kUndefined, kUndefined},
    {Convention::kMonai,
     {"nan",
      "nan",
      "nan",
      "nan",
      "nan",
      "nan",
      {"nan", "nan", "nan", "nan", "nan"},
      {"nan", "nan", "nan", "nan", "nan"}},
     {"inf", "nan", "inf", "inf", "inf", "0", kMonaiOneSide, kMonaiOneSide}},
    {Convention::kMedpy, kError, kError},
    // plastimatch's statistics stay 0; it has no surface Dice.
    {Convention::kPlastimatch,
     {"0", "0", "0", "0", "0", kU, {"0", "0", kU, "0", "0"}, {"0", "0", kU, "0", "0"}},
     kUndefined},
    {Convention::kItk, kUndefined, kUndefined},
    {Convention::kDeepmind,
     {"inf", "inf", "inf", "nan", "nan", "nan", kDeepmindNoSurfels, kDeepmindNoSurfels},
     {"inf", "inf", "inf", "inf", "nan", "0", kDeepmindNoSurfels, {"inf", "inf", "0", "inf", "inf"}}},
}};

constexpr bool rowsInOrder() {
    for (size_t i = 0; i < kEmptyRows.size(); ++i)
        if (kEmptyRows[i].convention != kAllConventions[i]) return false;
    return true;
}
static_assert(rowsInOrder(), "kEmptyRows[i] is Convention(i)'s");

EmptyDirected directedTexts(const SideTexts& t, const std::vector<double>& percentiles) {
    EmptyDirected d{t.hd, t.mean, t.overlap, {}};
    for (double p : percentiles) d.percentiles.emplace_back(p == 0.0 ? t.percentileAt0 : t.percentile);
    return d;
}

}  // namespace

EmptyValues emptyValues(Convention c, EmptyStatus s, const std::vector<double>& percentiles) {
    EmptyValues v;
    if (s == EmptyStatus::kNone || size_t(c) >= kEmptyRows.size()) return v;
    const CaseTexts& t =
        s == EmptyStatus::kBothEmpty ? kEmptyRows[size_t(c)].both : kEmptyRows[size_t(c)].one;
    v.hd = t.hd;
    v.assd = t.assd;
    v.msd = t.msd;
    v.surfaceDice = t.surfaceDice;
    for (double p : percentiles) v.hdPercentile.emplace_back(p == 0.0 ? t.hdPercentileAt0 : t.hdPercentile);
    const bool aEmpty = s != EmptyStatus::kBEmpty;  // both, or A
    v.aToB = directedTexts(aEmpty ? t.emptySide : t.otherSide, percentiles);
    v.bToA = directedTexts(aEmpty && s != EmptyStatus::kBothEmpty ? t.otherSide : t.emptySide, percentiles);
    return v;
}

}  // namespace rthdist::masks
