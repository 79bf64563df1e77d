#include "cli/output_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>

namespace rthdist::cli {
namespace {

// ".XXXXXX.tmp": what createTempFile appends to the final file's name.
constexpr char kTempSuffix[] = ".tmp";
constexpr size_t kTempExtra = 7 + sizeof kTempSuffix - 1;
constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

// The temporary file a signal must remove. Written before the flag is set,
// read only by the handler while it is set (async-signal-safe: unlink, raise).
char g_pendingTemp[PATH_MAX];
volatile sig_atomic_t g_hasPendingTemp = 0;

extern "C" void removePendingTempAndDie(int sig) {
    if (g_hasPendingTemp) unlink(g_pendingTemp);
    // SA_RESETHAND restored the default action: raising again ends the process
    // with this signal once the handler returns, as if it had not been caught.
    raise(sig);
}

// While alive, SIGINT/SIGTERM/SIGHUP remove the armed path before the process
// dies. A signal the caller ignores (nohup) stays ignored.
class PendingTemp {
public:
    PendingTemp() {
        struct sigaction ours {};
        ours.sa_handler = removePendingTempAndDie;
        ours.sa_flags = SA_RESETHAND;
        sigemptyset(&ours.sa_mask);
        for (size_t i = 0; i < std::size(kCleanupSignals); ++i) {
            sigaction(kCleanupSignals[i], nullptr, &m_previous[i]);
            if (m_previous[i].sa_handler != SIG_IGN) sigaction(kCleanupSignals[i], &ours, nullptr);
        }
    }
    // From now on a signal removes `path` (which may not exist yet).
    void arm(const std::string& path) {
        g_hasPendingTemp = 0;
        std::memcpy(g_pendingTemp, path.c_str(), path.size() + 1);  // path.size() < PATH_MAX: checked
        g_hasPendingTemp = 1;
    }
    void disarm() { g_hasPendingTemp = 0; }
    ~PendingTemp() {
        g_hasPendingTemp = 0;
        for (size_t i = 0; i < std::size(kCleanupSignals); ++i) {
            sigaction(kCleanupSignals[i], &m_previous[i], nullptr);
        }
    }
    PendingTemp(const PendingTemp&) = delete;
    PendingTemp& operator=(const PendingTemp&) = delete;

private:
    struct sigaction m_previous[std::size(kCleanupSignals)]{};
};

Error outputError(const std::string& path, int errorNumber, const std::string& step) {
    return Error{ErrorCode::kInternal,
                 "cannot write output '" + path + "': " + std::strerror(errorNumber) + " (" + step + ")"};
}

// write(2) until everything is written; false with errno set otherwise.
bool writeAll(int fd, std::string_view bytes) {
    while (!bytes.empty()) {
        const ssize_t n = ::write(fd, bytes.data(), std::min<size_t>(bytes.size(), size_t(1) << 30));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return false;
        if (n == 0) {
            errno = EIO;
            return false;
        }
        bytes.remove_prefix(size_t(n));
    }
    return true;
}

// The mode a file created by fopen would get (existing files keep theirs).
mode_t freshFileMode() {
    const mode_t mask = umask(0);
    umask(mask);
    return 0666 & ~mask;
}

// A device, FIFO or other non-regular file that exists: written in place.
Result<bool> writeInPlace(const std::string& path, const std::string& target, std::string_view bytes) {
    const int fd = ::open(target.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) return outputError(path, errno, "opening it");
    if (!writeAll(fd, bytes)) {
        const int e = errno;
        ::close(fd);
        return outputError(path, e, "writing");
    }
    if (::close(fd) != 0) return outputError(path, errno, "closing it");
    return true;
}

// Replaces the "XXXXXX" before ".tmp" in `temp` with random characters and
// creates that file exclusively, arming `pending` with each name before it is
// created (mkstemps would leave a window between creating and arming). Returns
// the descriptor, or -1 with errno set.
int createTempFile(std::string& temp, PendingTemp& pending) {
    static constexpr char kLetters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    const size_t at = temp.size() - (sizeof kTempSuffix - 1) - 6;
    std::random_device seed;
    std::mt19937 random(seed());
    std::uniform_int_distribution<int> letter(0, int(sizeof kLetters) - 2);
    for (int attempt = 0; attempt < 100; ++attempt) {
        for (size_t i = 0; i < 6; ++i) temp[at + i] = kLetters[letter(random)];
        pending.arm(temp);
        const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        if (fd >= 0) return fd;
        const int e = errno;
        pending.disarm();
        if (e != EEXIST) {
            errno = e;
            return -1;
        }
    }
    errno = EEXIST;
    return -1;
}

}  // namespace

Result<bool> writeOutputFile(const std::string& path, std::string_view bytes) {
    // Follow an existing symbolic link: replace the file it names, keep the link.
    std::string target = path;
    struct stat st {};
    if (::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) {
        std::unique_ptr<char, decltype(&std::free)> resolved(::realpath(path.c_str(), nullptr), &std::free);
        if (resolved) {
            target = resolved.get();
        } else {
            // A dangling link: the file it names is created (not the link
            // replaced), following a chain of links as the kernel would.
            for (int hop = 0; hop < 40 && ::lstat(target.c_str(), &st) == 0 && S_ISLNK(st.st_mode); ++hop) {
                std::string to(size_t(PATH_MAX), '\0');
                const ssize_t n = ::readlink(target.c_str(), to.data(), to.size() - 1);
                if (n <= 0) break;
                to.resize(size_t(n));
                const size_t slash = target.find_last_of('/');
                target =
                    to.front() == '/' || slash == std::string::npos ? to : target.substr(0, slash + 1) + to;
            }
        }
    }
    const bool exists = ::stat(target.c_str(), &st) == 0;
    if (exists && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) return writeInPlace(path, target, bytes);
    const mode_t mode = exists && S_ISREG(st.st_mode) ? (st.st_mode & 07777) : freshFileMode();

    const size_t slash = target.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : target.substr(0, slash);
    std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
    // The temporary name must fit NAME_MAX even when the final one barely does.
    if (base.size() + kTempExtra > NAME_MAX) base.resize(NAME_MAX - kTempExtra);
    std::string temp =
        (slash == std::string::npos ? "" : target.substr(0, slash + 1)) + base + ".XXXXXX" + kTempSuffix;
    if (temp.size() >= PATH_MAX) return outputError(path, ENAMETOOLONG, "naming the temporary file");

    // The handlers go in and the name is armed before the file exists, so a
    // signal at any moment finds the temporary file it must remove.
    PendingTemp pending;
    const int fd = createTempFile(temp, pending);
    if (fd < 0) return outputError(path, errno, "creating a temporary file in '" + dir + "'");
    auto fail = [&](int e, const char* step) {
        ::unlink(temp.c_str());
        return outputError(path, e, step);
    };
    if (::fchmod(fd, mode) != 0 || !writeAll(fd, bytes) || ::fsync(fd) != 0) {
        const int e = errno;
        ::close(fd);
        return fail(e, "writing the temporary file");
    }
    if (::close(fd) != 0) return fail(errno, "closing the temporary file");
    if (::rename(temp.c_str(), target.c_str()) != 0) return fail(errno, "renaming the temporary file");
    pending.disarm();

    // Make the rename itself durable. The new file is already in place, so a
    // failure here is not reported: the output exists and is complete.
    const int dirFd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dirFd >= 0) {
        (void)::fsync(dirFd);
        ::close(dirFd);
    }
    return true;
}

}  // namespace rthdist::cli
