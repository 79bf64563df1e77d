#include "io/file_bytes.hpp"

#include <sys/stat.h>

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

}  // namespace

Result<std::string> readFileBytes(const std::string& path, InflatedBound gzipBound) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        return badInput(path, "open", std::strerror(errno));
    }
    if (S_ISDIR(st.st_mode)) return badInput(path, "open", "is a directory, not a file");
    if (!S_ISREG(st.st_mode)) return badInput(path, "open", "not a regular file");

    std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
    if (!file) return badInput(path, "open", std::strerror(errno));

    // The size from stat is a hint only: the file may change under us, so
    // read until EOF and keep what actually arrived.
    std::string bytes;
    bytes.resize(static_cast<size_t>(st.st_size));
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

}  // namespace rthdist::io
