// Packed rows and their boundary words (row_bits.hpp).
#include "masks/row_bits.hpp"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <type_traits>

#include "core/parallel.hpp"
#include "masks/byte_rows.hpp"
#include "masks/selected.hpp"

namespace rthdist::masks::detail {
namespace {

constexpr size_t kRowsPerChunk = 256;

// One row of labels starting at voxel `at` into `words` (nx voxels).
template <class T>
void packRow(const Selected<T>& sel, int64_t at, int64_t nx, uint64_t* words) {
    for (int64_t x = 0; x < nx; x += 64) *words++ = sel.word(at + x, std::min<int64_t>(64, nx - x));
}

// Word w of "selected with both x neighbours selected" for a packed row of W words.
uint64_t withXNeighbours(const uint64_t* r, int64_t w, int64_t W) {
    const uint64_t left = (r[w] << 1) | (w > 0 ? r[w - 1] >> 63 : 0);       // bit x: x - 1 selected
    const uint64_t right = (r[w] >> 1) | (w + 1 < W ? r[w + 1] << 63 : 0);  // bit x: x + 1 selected
    return r[w] & left & right;
}

}  // namespace

RowBits::RowBits(const Volume& v, LabelSelect select, int threads)
    : m_dims(v.dims), m_rowWords((v.dims[0] + 63) / 64) {
    const int64_t nx = m_dims[0];
    const size_t rows = size_t(m_dims[1] * m_dims[2]);
    m_words.resize(rows * size_t(m_rowWords));
    // A chunk's rows are whole words of m_rowsInUse (kRowsPerChunk % 64 == 0):
    // each word has one writer.
    static_assert(kRowsPerChunk % 64 == 0);
    m_rowsInUse.resize((rows + 63) / 64);
    std::vector<uint64_t> chunkCounts((rows + kRowsPerChunk - 1) / kRowsPerChunk, 0);
    withLabels(v, [&](const auto* labels) {
        const Selected sel(labels, select);
        using Label = std::remove_cv_t<std::remove_pointer_t<decltype(labels)>>;
        core::parallelChunks(rows, kRowsPerChunk, threads, [&](size_t b, size_t e, int) {
            uint64_t count = 0;
            uint64_t inUse[kRowsPerChunk / 64] = {};  // written to m_rowsInUse once, below
            for (size_t r = b; r < e; ++r) {
                uint64_t* words = m_words.data() + r * size_t(m_rowWords);
                uint64_t inRow = 0;
                if constexpr (std::is_same_v<Label, uint8_t>) {
                    // 8-bit labels: byte_rows.hpp (AVX2 where the CPU has it).
                    if (!sel.none)
                        inRow =
                            packByteRow(labels + int64_t(r) * nx, nx, ByteSelect{sel.any, sel.value}, words);
                    else
                        std::fill(words, words + m_rowWords, uint64_t(0));
                } else {
                    packRow(sel, int64_t(r) * nx, nx, words);
                    // Most words of a mask volume are empty; std::popcount is a
                    // library call on the baseline x86-64 target (no POPCNT).
                    for (int64_t w = 0; w < m_rowWords; ++w)
                        if (words[w] != 0) inRow += uint64_t(std::popcount(words[w]));
                }
                if (inRow != 0) inUse[(r - b) / 64] |= uint64_t(1) << (r % 64);
                count += inRow;
            }
            for (size_t w = b / 64; w < (e + 63) / 64; ++w) m_rowsInUse[w] = inUse[w - b / 64];
            chunkCounts[b / kRowsPerChunk] = count;
        });
    });
    for (uint64_t c : chunkCounts) m_count += c;
}

void RowBits::appendBoundaryOfRow(int64_t y, int64_t z, int connectivity, std::vector<uint64_t>& out) const {
    const int64_t W = m_rowWords, ny = m_dims[1], nz = m_dims[2];
    const uint64_t* centre = row(y, z);
    if (std::all_of(centre, centre + W, [](uint64_t w) { return w == 0; })) return;
    // The neighbour rows (dy, dz) of the connectivity (|dy| + |dz| <= maxL1)
    // and whether their x neighbours count too (|dy| + |dz| + 1 <= maxL1).
    // A row outside the volume is background: every selected voxel of this
    // row is then a boundary voxel.
    const int maxL1 = connectivity == 6 ? 1 : connectivity == 18 ? 2 : 3;
    const uint64_t* rows[8];
    bool shifted[8];
    int count = 0;
    bool outside = false;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
            const int l1 = std::abs(dy) + std::abs(dz);
            if (l1 == 0 || l1 > maxL1) continue;
            const int64_t ny2 = y + dy, nz2 = z + dz;
            if (ny2 < 0 || nz2 < 0 || ny2 >= ny || nz2 >= nz) {
                outside = true;
                continue;
            }
            rows[count] = row(ny2, nz2);
            shifted[count++] = l1 + 1 <= maxL1;
        }
    const uint64_t first = uint64_t((z * ny + y) * m_dims[0]);
    for (int64_t w = 0; w < W; ++w) {
        uint64_t interior = 0;
        if (!outside) {
            interior = withXNeighbours(centre, w, W);
            for (int k = 0; k < count && interior != 0; ++k)
                interior &= shifted[k] ? withXNeighbours(rows[k], w, W) : rows[k][w];
        }
        for (uint64_t b = centre[w] & ~interior; b != 0; b &= b - 1)
            out.push_back(first + uint64_t(w) * 64 + uint64_t(std::countr_zero(b)));
    }
}

}  // namespace rthdist::masks::detail
