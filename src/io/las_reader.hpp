// LAS 1.0-1.4 (ASPRS "LAS Specification 1.4 - R15", 2019): the public header
// block, variable-length records (skipped: the points start at the header's
// offset to point data) and point data records of formats 0-10, whose first
// 12 bytes are X, Y, Z as int32 in units of the header's scale, plus its
// offset. Coordinates are X * scale + offset in double.
//
// Checked before anything is allocated: the signature, version 1.0-1.4, the
// header size against the version's and the file's, the offset to point
// data, the point format (0-10; the compression bits of LAZ are refused with
// lazError), the record length against the format's minimum, the point count
// (1.4: the 64-bit count; a legacy count that disagrees is an error) times
// the record length against the bytes after the offset, and non-zero finite
// scales and finite offsets. Then every point's coordinates must be finite.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "io/parallel_chunks.hpp"
#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// Smallest point record of each format 0-10 (the specification's sizes;
// records may be longer: extra bytes).
inline constexpr uint16_t kLasMinRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

// bytes: the whole (already gunzipped) file; path names it in error messages.
// classes: keep only points with one of these classification values (empty:
// all); classification is the low 5 bits of byte 15 in formats 0-5, byte 16
// in formats 6-10. Keeping no point is an error naming the classes.
// plan: threads and chunk size of the parallel conversion (the result does
// not depend on it).
[[nodiscard]] Result<PointCloud> readLas(std::string_view bytes, const std::string& path,
                                         const std::vector<int>& classes, const ChunkPlan& plan = {});

// The error for compressed LAS (a .laz file, or a LAS header whose point
// format carries LASzip's compression bits).
[[nodiscard]] Error lazError(const std::string& path, const std::string& where);

}  // namespace rthdist::io
