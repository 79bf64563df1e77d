// A VkPipelineCache kept in a file between processes, so that a new process
// on the same device and driver does not compile rthdist's pipelines again
// (setup was 0.35-0.54 s on the H200 without it).
//
// File: <dir>/pipelines-<vendorID>-<deviceID>-<pipelineCacheUUID>.bin. Its
// header (VkPipelineCacheHeaderVersionOne) is checked against the device
// before the driver sees the data; a file that is short, larger than
// kMaxFileBytes, or written for another device or driver is ignored (and
// replaced on save). Writes go to a temporary file of an unpredictable name
// created exclusively (mkstemp, 0600) in the same directory and renamed over
// the old one, so concurrent processes never read half a file and a symlink
// planted under any name is never written through; the file is read only
// when it is a regular file of this user's, opened without following a
// symlink. A directory that another user can write (not sticky and ours) is
// neither read nor written ("ignored: ..."); a missing one is created 0700.
// Any I/O failure only means an empty cache: it is reported by loadStatus(),
// never as an error.
// Threading: one owner; Vulkan synchronizes the cache's use by pipeline
// creation internally.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>

#include "gpu/unique_handle.hpp"

namespace rthdist::gpu {

class PipelineCache {
public:
    static constexpr uint64_t kMaxFileBytes = uint64_t(64) << 20;

    // dir empty: an in-memory cache only (nothing read or written).
    PipelineCache(VkDevice device, VkPhysicalDevice physical, const std::string& dir);
    ~PipelineCache() = default;
    PipelineCache(const PipelineCache&) = delete;
    PipelineCache& operator=(const PipelineCache&) = delete;

    [[nodiscard]] VkPipelineCache handle() const { return m_cache.get(); }
    [[nodiscard]] const std::string& path() const { return m_path; }
    // "loaded", "none" (no file or no dir), or why a file was ignored.
    [[nodiscard]] const std::string& loadStatus() const { return m_status; }
    [[nodiscard]] bool loaded() const { return m_status == "loaded"; }

    // Writes the cache when it holds data the file did not have.
    void save();

private:
    VkDevice m_device;
    UniquePipelineCache m_cache;
    std::string m_path;
    std::string m_status = "none";
    size_t m_loadedBytes = 0;
};

}  // namespace rthdist::gpu
