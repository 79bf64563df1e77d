#include "io/file_bytes.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "io/io_error.hpp"

namespace rthdist::io {
namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

bool endsWithGz(const std::string& path) {
    if (path.size() < 3) return false;
    const std::string tail = path.substr(path.size() - 3);
    return tail == ".gz" || tail == ".GZ" || tail == ".Gz" || tail == ".gZ";
}

// What every access refuses before opening: a missing path, a directory,
// anything but a regular file (a FIFO would block the open). The size is a
// hint: the file may change before it is read.
Result<size_t> regularFileSize(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return badInput(path, "open", std::strerror(errno));
    if (S_ISDIR(st.st_mode)) return badInput(path, "open", "is a directory, not a file");
    if (!S_ISREG(st.st_mode)) return badInput(path, "open", "not a regular file");
    return static_cast<size_t>(st.st_size);
}

// The mapping of a regular file; an empty MappedFile (and errno) when the
// file is empty or the system refuses to map it.
Result<MappedFile> mapFile(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return badInput(path, "open", std::strerror(errno));
    struct stat st {};
    MappedFile map;
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) map = MappedFile(fd, static_cast<size_t>(st.st_size));
    ::close(fd);
    return map;
}

}  // namespace

Result<std::string> readFileBytes(const std::string& path, InflatedBound gzipBound) {
    const auto size = regularFileSize(path);
    if (!size) return size.error();

    std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
    if (!file) return badInput(path, "open", std::strerror(errno));

    // The size from stat is a hint only: the file may change under us, so
    // read until EOF and keep what actually arrived.
    std::string bytes;
    bytes.resize(*size);
    size_t got = std::fread(bytes.data(), 1, bytes.size(), file.get());
    if (std::ferror(file.get())) return badInput(path, offsetWhere(got), "read error");
    if (got == bytes.size()) {
        char more[4096];
        size_t n = 0;
        while ((n = std::fread(more, 1, sizeof more, file.get())) > 0) bytes.append(more, n);
        if (std::ferror(file.get())) return badInput(path, offsetWhere(bytes.size()), "read error");
    } else {
        bytes.resize(got);
    }

    if (endsWithGz(path) && !bytes.empty()) return gunzip(bytes, path, gzipBound);
    return bytes;
}

Result<FileBytes> openFileBytes(const std::string& path, InflatedBound gzipBound, FileAccess access) {
    if (access == FileAccess::kMap && !endsWithGz(path)) {
        if (const auto size = regularFileSize(path); !size) return size.error();
        auto map = mapFile(path);
        if (!map) return map.error();
        if (map->valid()) return FileBytes(std::move(map).value());
        // Empty, or not mappable (a file system without mmap): read it.
    }
    auto bytes = readFileBytes(path, gzipBound);
    if (!bytes) return bytes.error();
    return FileBytes(std::move(bytes).value());
}

}  // namespace rthdist::io
