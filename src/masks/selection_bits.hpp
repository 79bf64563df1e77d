// A mask's selection kept as one bit per voxel: what a prepared reference
// keeps of its label volume for itk, whose directions need, for every voxel
// of a prediction, whether the reference holds it (a eighth of the bytes of
// the smallest label array, a 64th of an int32 one). Internal to
// rthdist_masks.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "masks/boundary.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {

class SelectionBits {
public:
    SelectionBits() = default;
    // The voxels of `v` that `select` picks.
    SelectionBits(const Volume& v, LabelSelect select, int threads);

    [[nodiscard]] bool operator()(uint64_t voxel) const { return (m_words[voxel >> 6] >> (voxel & 63)) & 1u; }
    [[nodiscard]] uint64_t bytes() const { return m_words.capacity() * sizeof(uint64_t); }

    // Ascending voxels selected here and not in (b, sb): differenceVoxels(this, b).
    [[nodiscard]] std::vector<uint64_t> minus(const Volume& b, LabelSelect sb, int threads) const;
    // Ascending voxels selected in (b, sb) and not here: differenceVoxels(b, this).
    [[nodiscard]] std::vector<uint64_t> missingFrom(const Volume& b, LabelSelect sb, int threads) const;
    // The first voxel selected both here and in (b, sb): firstCommonVoxel.
    [[nodiscard]] std::optional<uint64_t> firstCommon(const Volume& b, LabelSelect sb) const;

private:
    Dims m_dims{0, 0, 0};
    std::vector<uint64_t> m_words;  // voxel i is bit i % 64 of word i / 64
};

}  // namespace rthdist::masks::detail
