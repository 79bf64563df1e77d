#include "gpu/pipeline_cache.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <unistd.h>

#include "gpu/vk_check.hpp"

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

std::vector<char> readFile(const std::string& path, std::string& status) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) return {};  // no file yet: status stays "none"
    if (size > PipelineCache::kMaxFileBytes) {
        status = "ignored: larger than 64 MiB";
        return {};
    }
    std::vector<char> data(size);
    std::ifstream in(path, std::ios::binary);
    if (!in.read(data.data(), std::streamsize(size))) {
        status = "ignored: unreadable";
        return {};
    }
    return data;
}

}  // namespace

std::string defaultPipelineCacheDir() {
    if (const char* d = std::getenv("RTHDIST_CACHE_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/rthdist";
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/rthdist";
    return "";
}

PipelineCache::PipelineCache(VkDevice device, VkPhysicalDevice physical, const std::string& dir)
    : m_device(device) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physical, &props);
    std::vector<char> data;
    if (!dir.empty()) {
        m_path = dir + "/pipelines-" + std::to_string(props.vendorID) + "-" + std::to_string(props.deviceID) +
                 "-" + hex(props.pipelineCacheUUID, VK_UUID_SIZE) + ".bin";
        data = readFile(m_path, m_status);
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
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
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
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(m_path).parent_path(), ec);
    const std::string tmp = m_path + ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out.write(data.data(), std::streamsize(size))) {
            std::filesystem::remove(tmp, ec);
            return;
        }
    }
    std::filesystem::rename(tmp, m_path, ec);
    if (ec) std::filesystem::remove(tmp, ec);
}

}  // namespace rthdist::gpu
