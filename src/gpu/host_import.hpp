// A buffer over the caller's own host memory (VK_EXT_external_memory_host):
// the device reads an array where it lies, so a host array reaches the
// device without a host copy (the transfer then runs at link speed straight
// from the caller's pages).
//
// The pages that hold [data, data + bytes) are imported (the range widened
// to the device's import alignment, whole pages that already hold the
// array). The caller's memory must stay allocated and unchanged while the
// import lives; rthdist imports for the duration of one call and releases
// the import before the call returns. An import the driver refuses (memory
// it cannot pin, an alignment past the page size) is not an error: create()
// returns nothing and the caller copies instead. Used only when
// Tuning::hostImport (RTHDIST_HOST_IMPORT=1; gpu/context.cpp says why).
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <optional>

#include "gpu/unique_handle.hpp"

namespace rthdist::gpu {

class Context;

class HostImport {
public:
    [[nodiscard]] static std::optional<HostImport> create(Context& ctx, const void* data, size_t bytes);
    HostImport(HostImport&&) noexcept = default;
    HostImport& operator=(HostImport&&) noexcept = default;
    HostImport(const HostImport&) = delete;
    HostImport& operator=(const HostImport&) = delete;
    ~HostImport() = default;

    [[nodiscard]] VkBuffer handle() const { return m_buffer.get(); }
    // Where `data` lies in the buffer.
    [[nodiscard]] VkDeviceSize offset() const { return m_offset; }

private:
    HostImport() = default;

    UniqueMemory m_memory;  // declared first: released after the buffer bound to it
    UniqueBuffer m_buffer;
    VkDeviceSize m_offset = 0;
};

}  // namespace rthdist::gpu
