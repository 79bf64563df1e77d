// The deepmind convention of compareMasks (masks.hpp has its definition;
// surfels.hpp and surfel_area.hpp the surfels and their areas). Internal to
// rthdist_masks.
#pragma once

#include "masks/directions.hpp"
#include "masks/surfels.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {

// compareMasks for a surfel convention (deepmind), once compareMasks has checked the
// grids and options.
[[nodiscard]] Result<MaskResult> compareDeepmind(Engine& engine, const Volume& a, LabelSelect selectA,
                                                 const Volume& b, LabelSelect selectB,
                                                 const MaskOptions& options);

// The comparison of two masks' surfels, A first: A's spacing gives the
// areas and, through VoxelMetric::corners(a), the float search frame of both
// directions (B's grid equals it: checkSameGrid); each distance is
// recomputed with its query side's spacing. `toA` searches B's query corners
// against A's surfels (a prepared reference's set); null: one-shot calls, as
// for A -> B. `extractMs`: the surfels' extraction so far; `start`: the
// comparison's start (MaskResult::totalMs).
[[nodiscard]] Result<MaskResult> compareSurfels(Engine& engine, const Volume& a, const Surfels& sa,
                                                const Volume& b, const Surfels& sb,
                                                const MaskOptions& options, const NearestCall* toA,
                                                double extractMs, Clock::time_point start);

}  // namespace rthdist::masks::detail
