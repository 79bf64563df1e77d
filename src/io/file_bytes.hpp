// A whole file's bytes: mapped in place (regular files) or read into memory
// (".gz" files, gunzipped on the way, and where mapping is refused).
#pragma once

#include <string>
#include <string_view>

#include "io/gzip_inflate.hpp"
#include "io/mapped_file.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// Fails (kBadInput, message names the path) for a missing file, a directory,
// an unreadable file, a corrupt or truncated gzip stream and one that
// inflates beyond its cap (gzip_inflate.hpp; gzipBound: the format's header
// check). An empty file is returned as an empty string; the caller decides
// whether that is an error.
[[nodiscard]] Result<std::string> readFileBytes(const std::string& path, InflatedBound gzipBound = nullptr);

// kMap: map a regular file read-only (mapped_file.hpp), read it when the
// system refuses the mapping; kRead: always read (readFileBytes). A ".gz"
// file is always read and gunzipped.
enum class FileAccess { kMap, kRead };

// The bytes of one file, owned: a mapping or a buffer.
class FileBytes {
public:
    explicit FileBytes(std::string bytes) : m_owned(std::move(bytes)) {}
    explicit FileBytes(MappedFile map) : m_map(std::move(map)) {}

    [[nodiscard]] std::string_view view() const { return m_map.valid() ? m_map.bytes() : m_owned; }
    [[nodiscard]] bool mapped() const { return m_map.valid(); }

private:
    std::string m_owned;
    MappedFile m_map;
};

// The same checks and errors as readFileBytes, whichever the access.
[[nodiscard]] Result<FileBytes> openFileBytes(const std::string& path, InflatedBound gzipBound = nullptr,
                                              FileAccess access = FileAccess::kMap);

}  // namespace rthdist::io
