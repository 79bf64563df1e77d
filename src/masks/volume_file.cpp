// VolumeFile (volume_file.hpp): stat, open without blocking, fstat again.
#include "masks/volume_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "masks/label_types.hpp"

namespace rthdist::masks::detail {
namespace {

const char* kindOf(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

Error notRegular(const std::string& path, mode_t mode) {
    return badInput(path, std::string("is ") + kindOf(mode) + ", not a regular file (nothing was read)");
}

}  // namespace

Result<VolumeFile> VolumeFile::open(const std::string& path) {
    struct stat before {};
    if (::stat(path.c_str(), &before) != 0)
        return badInput(path, std::string("cannot open the file: ") + std::strerror(errno));
    if (!S_ISREG(before.st_mode)) return notRegular(path, before.st_mode);
    // O_NONBLOCK: a FIFO put in its place since the stat opens at once (and is refused below).
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return badInput(path, std::string("cannot open the file: ") + std::strerror(errno));
    VolumeFile file(fd, 0, path);
    struct stat st {};
    if (::fstat(fd, &st) != 0)
        return badInput(path, std::string("cannot stat the file: ") + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) return notRegular(path, st.st_mode);
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0)
        return badInput(path, std::string("cannot read the file: ") + std::strerror(errno));
    file.m_size = uint64_t(st.st_size);
    return file;
}

VolumeFile::VolumeFile(VolumeFile&& other) noexcept
    : m_fd(std::exchange(other.m_fd, -1)), m_size(other.m_size), m_path(std::move(other.m_path)) {}

VolumeFile& VolumeFile::operator=(VolumeFile&& other) noexcept {
    if (this != &other) {
        if (m_fd >= 0) ::close(m_fd);
        m_fd = std::exchange(other.m_fd, -1);
        m_size = other.m_size;
        m_path = std::move(other.m_path);
    }
    return *this;
}

VolumeFile::~VolumeFile() {
    if (m_fd >= 0) ::close(m_fd);
}

Result<size_t> VolumeFile::readSome(void* out, size_t n) {
    size_t got = 0;
    char* p = static_cast<char*>(out);
    while (got < n) {
        const ssize_t r = ::read(m_fd, p + got, std::min<size_t>(n - got, size_t(1) << 30));
        if (r < 0) {
            if (errno == EINTR) continue;
            return badInput(m_path, std::string("read error: ") + std::strerror(errno));
        }
        if (r == 0) break;
        got += size_t(r);
    }
    return got;
}

std::optional<Error> VolumeFile::readExact(void* out, size_t n, const std::string& what) {
    const Result<size_t> got = readSome(out, n);
    if (!got) return got.error();
    if (*got != n)
        return badInput(m_path, what + " is truncated (" + std::to_string(*got) + " of " + std::to_string(n) +
                                    " bytes; the file ends early)");
    return std::nullopt;
}

}  // namespace rthdist::masks::detail
