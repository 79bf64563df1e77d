// A mask's selection packed one bit per voxel, row by row: what the host
// extraction (boundary.cpp) tests neighbours on. The label volume is read
// once, by rows on every thread (64 labels to a word; 8-bit labels through
// byte_rows.hpp, 32 per AVX2 compare where the CPU has it), then a row's boundary is word
// arithmetic on it and on its up to eight neighbour rows, and an empty row
// costs a test of its words. (Packing and testing slab by slab instead, with
// three slices in cache, measured slower on the H100 machine's 16 cores:
// docs/bench/masks.) Internal to rthdist_masks.
//
// Layout: row (y, z) is the words [((z * ny) + y) * W, + W), W = ceil(nx /
// 64); voxel x of the row is bit x % 64 of word x / 64; the bits past nx are
// zero (outside the volume counts as background).
// Memory: ny * nz * W words (a 512 x 512 x 300 volume: 9.8 MB), from
// core::UninitVector (kept for the next extraction of the same size).
// Threading: built on `threads` threads; const methods may be called from
// any number of threads.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "core/uninit_vector.hpp"
#include "masks/boundary.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {

class RowBits {
public:
    // The voxels of `v` that `select` picks.
    RowBits(const Volume& v, LabelSelect select, int threads);

    [[nodiscard]] uint64_t selectedCount() const { return m_count; }

    // Appends the boundary voxels of row (y, z) under connectivity 6, 18 or
    // 26 (boundary.hpp's definition) to `out` as linear indices, ascending.
    void appendBoundaryOfRow(int64_t y, int64_t z, int connectivity, std::vector<uint64_t>& out) const;

    // fn(y) for every row y of slice z that holds a selected voxel, in
    // ascending y (the others hold no boundary voxel): the boundary pass
    // reads only those rows and their neighbours (a mask's slices are mostly
    // background: the organ pair's 153,600 rows per volume cost 0.6-0.9 ms
    // to visit on the H100 machine).
    template <class Fn>
    void forRowsInUse(int64_t z, Fn&& fn) const {
        const int64_t ny = m_dims[1];
        const int64_t first = z * ny, end = first + ny;
        for (int64_t r = first; r < end;) {
            const int64_t word = r / 64, bit = r % 64;
            uint64_t bits = m_rowsInUse[size_t(word)] >> bit;
            if (end - r < 64 - bit) bits &= (uint64_t(1) << (end - r)) - 1;
            for (; bits != 0; bits &= bits - 1) fn(r + std::countr_zero(bits) - first);
            r += 64 - bit;
        }
    }

private:
    [[nodiscard]] const uint64_t* row(int64_t y, int64_t z) const {
        return m_words.data() + size_t((z * m_dims[1] + y) * m_rowWords);
    }

    Dims m_dims{0, 0, 0};
    int64_t m_rowWords = 0;
    core::UninitVector<uint64_t> m_words;
    core::UninitVector<uint64_t> m_rowsInUse;  // bit r: row r (z * ny + y) holds a selected voxel
    uint64_t m_count = 0;
};

}  // namespace rthdist::masks::detail
