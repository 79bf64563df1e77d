// One bit per voxel (selection_bits.hpp). Work is split by z-slice (by
// words to build), each slice's list joined in slice order, so every list
// is ascending and deterministic, as boundary.cpp's.
#include "masks/selection_bits.hpp"

#include <algorithm>
#include <bit>

#include "core/parallel.hpp"
#include "masks/selected.hpp"
#include "masks/slice_lists.hpp"

namespace rthdist::masks::detail {
namespace {

constexpr size_t kWordsPerChunk = size_t(1) << 12;

}  // namespace

SelectionBits::SelectionBits(const Volume& v, LabelSelect select, int threads)
    : m_dims(v.dims), m_words((v.voxelCount() + 63) / 64, 0) {
    const uint64_t n = v.voxelCount();
    withLabels(v, [&](const auto* labels) {
        const Selected sel(labels, select);
        core::parallelChunks(m_words.size(), kWordsPerChunk, threads, [&](size_t wb, size_t we, int) {
            for (size_t w = wb; w < we; ++w)
                m_words[w] = sel.word(int64_t(w * 64), int64_t(std::min<uint64_t>(64, n - w * 64)));
        });
    });
}

std::vector<uint64_t> SelectionBits::minus(const Volume& b, LabelSelect sb, int threads) const {
    const uint64_t slice = uint64_t(m_dims[0] * m_dims[1]);
    return withLabels(b, [&](const auto* labels) {
        const Selected inB(labels, sb);
        return perSlice(m_dims[2], threads, [&](int64_t z, std::vector<uint64_t>& out) {
            const uint64_t begin = uint64_t(z) * slice, end = begin + slice;
            for (uint64_t w = begin / 64; w * 64 < end; ++w) {
                uint64_t word = m_words[w];
                while (word != 0) {
                    const uint64_t i = w * 64 + uint64_t(std::countr_zero(word));
                    word &= word - 1;
                    if (i >= begin && i < end && !inB(int64_t(i))) out.push_back(i);
                }
            }
        });
    });
}

std::vector<uint64_t> SelectionBits::missingFrom(const Volume& b, LabelSelect sb, int threads) const {
    const int64_t nx = m_dims[0], ny = m_dims[1];
    return withLabels(b, [&](const auto* labels) {
        const Selected inB(labels, sb);
        return perSlice(m_dims[2], threads, [&](int64_t z, std::vector<uint64_t>& out) {
            for (int64_t y = 0; y < ny; ++y) {
                const int64_t row = (y + ny * z) * nx;
                if (inB.countRow(row, row + nx) == 0) continue;
                for (int64_t x = row; x < row + nx; ++x)
                    if (inB(x) && !(*this)(uint64_t(x))) out.push_back(uint64_t(x));
            }
        });
    });
}

std::optional<uint64_t> SelectionBits::firstCommon(const Volume& b, LabelSelect sb) const {
    return withLabels(b, [&](const auto* labels) -> std::optional<uint64_t> {
        const Selected inB(labels, sb);
        for (size_t w = 0; w < m_words.size(); ++w) {
            for (uint64_t word = m_words[w]; word != 0; word &= word - 1) {
                const uint64_t i = w * 64 + uint64_t(std::countr_zero(word));
                if (inB(int64_t(i))) return i;
            }
        }
        return std::nullopt;
    });
}

}  // namespace rthdist::masks::detail
