// Decompresses a gzip stream (one or more concatenated members) with zlib,
// bounded so that a small file cannot inflate into gigabytes.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "rthdist/result.hpp"

namespace rthdist::io {

// The first inflated bytes handed to a format's header check.
inline constexpr size_t kInflateHeadBytes = 64 * 1024;
// Whatever the header says, a stream may inflate to at most this many times
// its compressed size, or kMinInflateCap, whichever is larger: real point
// data compresses a few times, decompression bombs a thousand times.
inline constexpr uint64_t kMaxInflateRatio = 64;
inline constexpr uint64_t kMinInflateCap = uint64_t{256} << 20;
// What a header check returns when its header does not bound the size.
inline constexpr uint64_t kNoInflatedBound = std::numeric_limits<uint64_t>::max();
// Bytes allowed after what a header declares (padding, a final newline).
inline constexpr uint64_t kInflatedSlack = 64 * 1024;

// A format's header check: given the first inflated bytes (head; whole when
// that is all of the stream), the most bytes the whole stream may inflate
// to, kNoInflatedBound when the header does not say, or the header's error.
using InflatedBound = Result<uint64_t> (*)(std::string_view head, bool whole, const std::string& path);

// max(kMinInflateCap, kMaxInflateRatio * compressedSize).
[[nodiscard]] uint64_t inflateCap(uint64_t compressedSize);

// path only names the file in error messages. A stream that ends before its
// trailer, or has a bad CRC, is an error naming the compressed byte offset.
// bound (optional) checks the header before the rest is inflated and caps
// the output; maxBytes (default inflateCap) caps it whatever the header says.
[[nodiscard]] Result<std::string> gunzip(std::string_view compressed, const std::string& path,
                                         InflatedBound bound = nullptr,
                                         std::optional<uint64_t> maxBytes = std::nullopt);

}  // namespace rthdist::io
