// The header of a NumPy .npy file, read exactly as NumPy's format
// specification (numpy.lib.format) says: the magic "\x93NUMPY", version 1.0,
// 2.0 or 3.0, the header length (2 bytes little-endian for 1.0, 4 for 2.0
// and 3.0), then a Python dict literal with exactly the keys 'descr',
// 'fortran_order' and 'shape' (each once): descr a string, fortran_order
// True or False, shape a tuple of non-negative integers. What NumPy's own
// reader would refuse is refused here, as is what it would accept but a
// label volume cannot be (another number of axes, a zero axis, a
// non-label dtype); every error names the file and the field.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "masks/label_types.hpp"
#include "rthdist/result.hpp"

namespace rthdist::masks::detail {

// The preamble: magic, version and header length (10 bytes for 1.0, 12 for 2.0/3.0).
inline constexpr size_t kNpyMinPreamble = 10;
inline constexpr size_t kNpyMaxPreamble = 12;
// NumPy refuses longer headers unless told otherwise (numpy.lib.format._MAX_HEADER_SIZE).
inline constexpr size_t kNpyMaxHeaderBytes = 10000;

struct NpyHeader {
    uint64_t dataAt = 0;              // the array's first byte in the file
    std::string descr;                // as written ("<u1")
    const LabelType* type = nullptr;  // its scalar type
    bool swap = false;                // big-endian multi-byte data
    bool fortran = false;
    std::array<int64_t, 3> dims{0, 0, 0};
    uint64_t voxels = 0;     // dims' product
    uint64_t dataBytes = 0;  // voxels * type->bytes
};

// The preamble's header length: `head` holds at least the first 12 bytes of
// the file or all of it; the total bytes of preamble + header.
[[nodiscard]] Result<uint64_t> npyHeaderEnd(std::string_view head, const std::string& path);

// The header in `bytes` (the file's first npyHeaderEnd bytes) of a file of
// `fileSize` bytes: the array must fit what follows the header.
[[nodiscard]] Result<NpyHeader> parseNpyHeader(std::string_view bytes, uint64_t fileSize,
                                               const std::string& path);

}  // namespace rthdist::masks::detail
