// A volume file opened for reading: regular files only, checked before a
// byte is read and without blocking (a FIFO, a device such as /dev/zero, a
// directory or a socket is refused by its type), read in exact pieces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "rthdist/result.hpp"

namespace rthdist::masks::detail {

class VolumeFile {
public:
    // kBadInput naming the path: missing, unreadable, or not a regular file.
    [[nodiscard]] static Result<VolumeFile> open(const std::string& path);

    VolumeFile(VolumeFile&& other) noexcept;
    VolumeFile& operator=(VolumeFile&& other) noexcept;
    VolumeFile(const VolumeFile&) = delete;
    VolumeFile& operator=(const VolumeFile&) = delete;
    ~VolumeFile();

    [[nodiscard]] int fd() const { return m_fd; }
    [[nodiscard]] uint64_t size() const { return m_size; }  // at open
    [[nodiscard]] const std::string& path() const { return m_path; }

    // Up to n bytes from the current position: fewer only at the end of the file.
    [[nodiscard]] Result<size_t> readSome(void* out, size_t n);
    // Exactly n bytes, else kBadInput "<path>: <what> is truncated ...".
    [[nodiscard]] std::optional<Error> readExact(void* out, size_t n, const std::string& what);

private:
    VolumeFile(int fd, uint64_t size, std::string path) : m_fd(fd), m_size(size), m_path(std::move(path)) {}
    int m_fd = -1;
    uint64_t m_size = 0;
    std::string m_path;
};

}  // namespace rthdist::masks::detail
