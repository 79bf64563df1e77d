// Move-only owner of a VkBuffer with its own memory and device address.
// Device buffers live in DEVICE_LOCAL memory; host buffers are HOST_VISIBLE |
// HOST_COHERENT and stay mapped (staging and small read-backs).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/barriers.hpp"  // cmdBarrier and cmdShaderBarrier, declared here before
#include "gpu/unique_handle.hpp"

namespace rthdist::gpu {

class Context;

// kDevice: device-local. kHost: host-visible and coherent, for data the host
// writes and the device reads (staging, counters). kReadback: host-visible,
// coherent and, where the device has it, cached: for data the device writes
// and the host reads in bulk (uncached reads run at a fraction of memory speed).
enum class MemoryKind { kDevice, kHost, kReadback };

class Buffer {
public:
    Buffer() = default;
    // size 0 allocates a 16-byte buffer so every buffer has an address.
    Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind);
    Buffer(Buffer&& o) noexcept { *this = static_cast<Buffer&&>(o); }
    Buffer& operator=(Buffer&& o) noexcept;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    ~Buffer() = default;

    // Releases the buffer and its memory now; the Buffer is empty after.
    void reset();
    [[nodiscard]] VkBuffer handle() const { return m_buffer.get(); }
    [[nodiscard]] VkDeviceAddress address() const { return m_address; }
    [[nodiscard]] VkDeviceSize size() const { return m_size; }
    [[nodiscard]] void* mapped() const { return m_mapped; }
    [[nodiscard]] MemoryKind kind() const { return m_kind; }
    [[nodiscard]] explicit operator bool() const { return bool(m_buffer); }

private:
    UniqueMemory m_memory;  // declared first: released after the buffer bound to it
    UniqueBuffer m_buffer;
    VkDeviceAddress m_address = 0;
    VkDeviceSize m_size = 0;
    void* m_mapped = nullptr;
    MemoryKind m_kind = MemoryKind::kDevice;
};

// Usage flags every storage buffer of rthdist gets.
inline constexpr VkBufferUsageFlags kStorageUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;

}  // namespace rthdist::gpu
