// One row of 8-bit labels packed into selection words (row_bits.hpp's
// layout: voxel x is bit x % 64 of word x / 64, bits past the row 0), with
// the count of selected voxels: the inner loop of the host extraction.
// Internal to rthdist_masks.
//
// packByteRow picks, once per process, an AVX2 + POPCNT version where the
// CPU has them (two 32-byte compares per word; measured 2x a thread's rate
// of the SSE2 word loop on the H100 machine's Xeon: docs/bench/masks), else
// packByteRowPortable. Both give the same words and count (a test compares
// them on every row length and label pattern).
// Threading: pure functions of their arguments.
#pragma once

#include <cstdint>

namespace rthdist::masks::detail {

// Which bytes are selected: `any` (label != 0), else label == key.
struct ByteSelect {
    bool any = true;
    uint8_t key = 0;
};

// Bits of the n <= 64 labels from `labels` (bit i: label i selected; 16
// labels per SSE2 compare where the target has it).
uint64_t byteWord(const uint8_t* labels, int64_t n, ByteSelect select);

// nx labels from `labels` into ceil(nx / 64) words; the selected count.
uint64_t packByteRow(const uint8_t* labels, int64_t nx, ByteSelect select, uint64_t* words);

// The same without AVX2 (SSE2 where the target has it).
uint64_t packByteRowPortable(const uint8_t* labels, int64_t nx, ByteSelect select, uint64_t* words);

// Whether packByteRow runs the AVX2 version on this CPU.
bool packByteRowUsesAvx2();

}  // namespace rthdist::masks::detail
