#include "gpu/host_import.hpp"

#include <cstdint>

#include "gpu/context.hpp"

namespace rthdist::gpu {

std::optional<HostImport> HostImport::create(Context& ctx, const void* data, size_t bytes) {
    if (!ctx.hostImport() || data == nullptr || bytes == 0) return std::nullopt;
    const VkDeviceSize align = ctx.importAlignment();
    const auto begin = reinterpret_cast<uintptr_t>(data);
    const uintptr_t base = begin - begin % align;
    const VkDeviceSize size = ((begin + bytes - base + align - 1) / align) * align;
    void* basePtr = reinterpret_cast<void*>(base);

    VkMemoryHostPointerPropertiesEXT props{VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT};
    if (ctx.getHostPointerProperties()(ctx.device(), VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT,
                                       basePtr, &props) != VK_SUCCESS ||
        props.memoryTypeBits == 0)
        return std::nullopt;

    HostImport im;
    im.m_device = ctx.device();
    im.m_offset = VkDeviceSize(begin - base);
    VkExternalMemoryBufferCreateInfo ext{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
    ext.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, &ext};
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (vkCreateBuffer(im.m_device, &bi, nullptr, &im.m_buffer) != VK_SUCCESS) return std::nullopt;
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(im.m_device, im.m_buffer, &req);
    const uint32_t types = req.memoryTypeBits & props.memoryTypeBits;
    uint32_t type = 0;
    while (type < 32 && (types & (1u << type)) == 0) ++type;
    if (type == 32) return std::nullopt;

    VkImportMemoryHostPointerInfoEXT import{VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT};
    import.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    import.pHostPointer = basePtr;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &import};
    ai.allocationSize = size;
    ai.memoryTypeIndex = type;
    if (vkAllocateMemory(im.m_device, &ai, nullptr, &im.m_memory) != VK_SUCCESS) return std::nullopt;
    if (vkBindBufferMemory(im.m_device, im.m_buffer, im.m_memory, 0) != VK_SUCCESS) return std::nullopt;
    return im;
}

HostImport& HostImport::operator=(HostImport&& o) noexcept {
    if (this != &o) {
        reset();
        m_device = o.m_device;
        m_buffer = o.m_buffer;
        m_memory = o.m_memory;
        m_offset = o.m_offset;
        o.m_buffer = VK_NULL_HANDLE;
        o.m_memory = VK_NULL_HANDLE;
    }
    return *this;
}

void HostImport::reset() {
    if (m_buffer) vkDestroyBuffer(m_device, m_buffer, nullptr);
    if (m_memory) vkFreeMemory(m_device, m_memory, nullptr);
    m_buffer = VK_NULL_HANDLE;
    m_memory = VK_NULL_HANDLE;
}

}  // namespace rthdist::gpu
