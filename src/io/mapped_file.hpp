// A read-only memory mapping of a whole regular file (POSIX mmap), owned
// RAII: the loaders parse the page cache in place instead of copying the
// file into a buffer first.
//
// A mapping shows the file as it is at each access: a file truncated by
// another process while it is being parsed makes the access past its new
// end raise SIGBUS (true of every reader that maps files); the loaders take
// the size once, when the file is opened.
#pragma once

#include <cstddef>
#include <string_view>

namespace rthdist::io {

class MappedFile {
public:
    MappedFile() = default;
    // Maps size bytes of the open descriptor fd (which may be closed
    // afterwards); valid() is false when the system refuses (errno is set).
    MappedFile(int fd, size_t size);
    MappedFile(MappedFile&& other) noexcept;
    MappedFile& operator=(MappedFile&& other) noexcept;
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    ~MappedFile();

    [[nodiscard]] bool valid() const { return m_data != nullptr; }
    [[nodiscard]] std::string_view bytes() const { return {static_cast<const char*>(m_data), m_size}; }

private:
    void* m_data = nullptr;
    size_t m_size = 0;
};

}  // namespace rthdist::io
