#include "gpu/buffer.hpp"

#include <string>

#include "gpu/context.hpp"

namespace rthdist::gpu {

Buffer::Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind) {
    m_device = ctx.device();
    m_size = size == 0 ? 16 : size;
    requireWithin(m_size, ctx.limits().maxBufferBytes, "a buffer", "maxBufferSize");
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = m_size;
    bi.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    RTHDIST_VK_CHECK(vkCreateBuffer(m_device, &bi, nullptr, &m_buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(m_device, m_buffer, &req);
    const VkMemoryPropertyFlags hostFlags =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkMemoryPropertyFlags wanted =
        kind == MemoryKind::kDevice ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT : hostFlags;
    uint32_t type =
        kind == MemoryKind::kReadback
            ? ctx.memoryTypeIndex(req.memoryTypeBits, hostFlags | VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
            : ~0u;
    if (type == ~0u) type = ctx.memoryTypeIndex(req.memoryTypeBits, wanted);
    if (type == ~0u) {
        reset();
        throwVulkanError(VK_ERROR_FEATURE_NOT_PRESENT, "memoryTypeIndex (no suitable memory type)", __FILE__,
                         __LINE__);
    }
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    VkResult r = vkAllocateMemory(m_device, &ai, nullptr, &m_memory);
    if (r < 0) {
        reset();
        const DeviceLimits& l = ctx.limits();
        const std::string what = "vkAllocateMemory of " + std::to_string(req.size) +
                                 " bytes (the device's maxMemoryAllocationSize is " +
                                 std::to_string(l.maxAllocationBytes) + ", its largest device heap " +
                                 std::to_string(l.deviceHeapBytes) + " bytes)";
        throwVulkanError(r, what.c_str(), __FILE__, __LINE__);
    }
    RTHDIST_VK_CHECK(vkBindBufferMemory(m_device, m_buffer, m_memory, 0));
    if (kind != MemoryKind::kDevice)
        RTHDIST_VK_CHECK(vkMapMemory(m_device, m_memory, 0, VK_WHOLE_SIZE, 0, &m_mapped));
    VkBufferDeviceAddressInfo dai{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    dai.buffer = m_buffer;
    m_address = vkGetBufferDeviceAddress(m_device, &dai);
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
    if (this != &o) {
        reset();
        m_device = o.m_device;
        m_buffer = o.m_buffer;
        m_memory = o.m_memory;
        m_address = o.m_address;
        m_size = o.m_size;
        m_mapped = o.m_mapped;
        o.m_buffer = VK_NULL_HANDLE;
        o.m_memory = VK_NULL_HANDLE;
        o.m_mapped = nullptr;
        o.m_address = 0;
        o.m_size = 0;
    }
    return *this;
}

void Buffer::reset() {
    if (m_buffer) vkDestroyBuffer(m_device, m_buffer, nullptr);
    if (m_memory) vkFreeMemory(m_device, m_memory, nullptr);
    m_buffer = VK_NULL_HANDLE;
    m_memory = VK_NULL_HANDLE;
    m_mapped = nullptr;
    m_address = 0;
    m_size = 0;
}

}  // namespace rthdist::gpu
