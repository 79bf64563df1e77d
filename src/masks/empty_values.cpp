// What each convention's tool reports for a row with an empty mask
// (rthdist/masks.hpp emptyValues): the texts of the convention's row
// (rthdist/mask_conventions.hpp, bothEmpty and oneEmpty) spread over the
// numbers of a MaskResult.
#include <vector>

#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

EmptyDirected directedTexts(const EmptySideTexts& t, const std::vector<double>& percentiles) {
    EmptyDirected d{t.hd, t.mean, t.overlap, {}};
    for (double p : percentiles) d.percentiles.emplace_back(p == 0.0 ? t.percentileAt0 : t.percentile);
    return d;
}

}  // namespace

EmptyValues emptyValues(Convention c, EmptyStatus s, const std::vector<double>& percentiles) {
    EmptyValues v;
    if (s == EmptyStatus::kNone || size_t(c) >= kConventionRules.size()) return v;
    const ConventionRules& row = conventionRules(c);
    const EmptyCaseTexts& t = s == EmptyStatus::kBothEmpty ? row.bothEmpty : row.oneEmpty;
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
