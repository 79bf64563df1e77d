// The deepmind convention of compareMasks (masks.hpp has its definition;
// surfels.hpp and surfel_area.hpp the surfels and their areas). Internal to
// rthdist_masks.
#pragma once

#include "masks/masks.hpp"

namespace rthdist::masks::detail {

// compareMasks for Convention::kDeepmind, once compareMasks has checked the
// grids and options.
[[nodiscard]] Result<MaskResult> compareDeepmind(Engine& engine, const Volume& a, LabelSelect selectA,
                                                 const Volume& b, LabelSelect selectB,
                                                 const MaskOptions& options);

}  // namespace rthdist::masks::detail
