#include "gpu/pipeline_cache.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "gpu/vk_check.hpp"
#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

namespace {

std::string hex(const uint8_t* bytes, size_t n) {
    std::string s;
    char buf[3];
    for (size_t i = 0; i < n; ++i) {
        std::snprintf(buf, sizeof(buf), "%02x", bytes[i]);
        s += buf;
    }
    return s;
}

// Why `data` cannot seed a cache of this device, or "" when it can.
std::string headerMismatch(const std::vector<char>& data, const VkPhysicalDeviceProperties& props) {
    VkPipelineCacheHeaderVersionOne h{};
    if (data.size() < sizeof(h)) return "shorter than its header";
    std::memcpy(&h, data.data(), sizeof(h));
    if (h.headerSize < sizeof(h) || h.headerSize > data.size()) return "bad header size";
    if (h.headerVersion != VK_PIPELINE_CACHE_HEADER_VERSION_ONE) return "unknown header version";
    if (h.vendorID != props.vendorID || h.deviceID != props.deviceID) return "written for another device";
    if (std::memcmp(h.pipelineCacheUUID, props.pipelineCacheUUID, VK_UUID_SIZE) != 0)
        return "written by another driver";
    return "";
}

// Why `dir` must not hold the cache, or "" when it may: a directory that
// another user can write (its owner when that is not us, its group or
// others) unless it is sticky and ours (there nobody else can replace or
// remove our files). A missing directory is fine (save() creates it, 0700).
std::string unsafeDirectory(const std::string& dir) {
    struct stat st {};
    if (::stat(dir.c_str(), &st) != 0) return "";
    if (!S_ISDIR(st.st_mode)) return dir + " is not a directory";
    const bool ours = st.st_uid == ::geteuid();
    const bool othersWrite =
        (!ours && (st.st_mode & S_IWUSR) != 0) || (st.st_mode & (S_IWGRP | S_IWOTH)) != 0;
    if (othersWrite && !(ours && (st.st_mode & S_ISVTX) != 0))
        return dir +
               " can be written by other users and is not a sticky directory of this user's "
               "(chmod go-w it, or set RTHDIST_CACHE_DIR)";
    return "";
}

// The file's bytes: a regular file of this user's, opened without following
// a symlink (one planted in a shared directory is ignored, not read).
std::vector<char> readFile(const std::string& path, std::string& status) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        if (errno != ENOENT) status = errno == ELOOP ? "ignored: a symbolic link" : "ignored: unreadable";
        return {};  // no file yet: status stays "none"
    }
    std::vector<char> data;
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid()) {
        status = "ignored: not a regular file of this user's";
    } else if (uint64_t(st.st_size) > PipelineCache::kMaxFileBytes) {
        status = "ignored: larger than 64 MiB";
    } else {
        data.resize(size_t(st.st_size));
        size_t done = 0;
        while (done < data.size()) {
            const ssize_t n = ::read(fd, data.data() + done, data.size() - done);
            if (n <= 0) break;
            done += size_t(n);
        }
        if (done != data.size()) {
            status = "ignored: unreadable";
            data.clear();
        }
    }
    ::close(fd);
    return data;
}

}  // namespace

PipelineCache::PipelineCache(VkDevice device, VkPhysicalDevice physical, const std::string& dir)
    : m_device(device) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical, &props);
    std::vector<char> data;
    if (!dir.empty()) {
        m_path = dir + "/pipelines-" + std::to_string(props.vendorID) + "-" + std::to_string(props.deviceID) +
                 "-" + hex(props.pipelineCacheUUID, VK_UUID_SIZE) + ".bin";
        if (const std::string why = unsafeDirectory(dir); !why.empty()) {
            m_status = "ignored: " + why;
            m_path.clear();  // neither read nor written
        } else {
            data = readFile(m_path, m_status);
        }
        if (!data.empty()) {
            const std::string why = headerMismatch(data, props);
            if (why.empty()) {
                m_status = "loaded";
            } else {
                m_status = "ignored: " + why;
                data.clear();
            }
        }
    }
    VkPipelineCacheCreateInfo ci =
        vkStruct<VkPipelineCacheCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO);
    ci.initialDataSize = data.size();
    ci.pInitialData = data.empty() ? nullptr : data.data();
    m_cache = RTHDIST_VK_CREATE(UniquePipelineCache, vkCreatePipelineCache, device, ci);
    m_loadedBytes = data.size();
}

void PipelineCache::save() {
    if (m_path.empty()) return;
    size_t size = 0;
    if (vkGetPipelineCacheData(m_device, m_cache.get(), &size, nullptr) != VK_SUCCESS || size == 0) return;
    if (m_status == "loaded" && size <= m_loadedBytes) return;  // nothing new
    std::vector<char> data(size);
    if (vkGetPipelineCacheData(m_device, m_cache.get(), &size, data.data()) != VK_SUCCESS) return;
    // The directory: created 0700 where missing, and checked again (it may
    // have changed since the constructor).
    const std::filesystem::path dir = std::filesystem::path(m_path).parent_path();
    std::error_code ec;
    std::filesystem::create_directories(dir.parent_path(), ec);
    if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) return;
    if (!unsafeDirectory(dir.string()).empty()) return;
    // A temporary file of an unpredictable name, created here (O_EXCL, 0600:
    // mkstemp), renamed over the old file: a symlink planted under any name
    // is never opened for writing, and a reader sees the old file or the new.
    std::string tmp = m_path + ".tmp-XXXXXX";
    const int fd = ::mkstemp(tmp.data());
    if (fd < 0) return;
    size_t done = 0;
    while (done < size) {
        const ssize_t n = ::write(fd, data.data() + done, size - done);
        if (n <= 0) break;
        done += size_t(n);
    }
    if (::close(fd) != 0 || done != size || ::rename(tmp.c_str(), m_path.c_str()) != 0) ::unlink(tmp.c_str());
}

}  // namespace rthdist::gpu
