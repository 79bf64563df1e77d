#include "gpu/host_import.hpp"

#include <cstdint>

#include "gpu/context.hpp"
#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

std::optional<HostImport> HostImport::create(Context& ctx, const void* data, size_t bytes) {
    if (!ctx.hostImport() || data == nullptr || bytes == 0) return std::nullopt;
    const VkDevice d = ctx.device();
    const VkDeviceSize align = ctx.importAlignment();
    const auto begin = reinterpret_cast<uintptr_t>(data);
    const uintptr_t base = begin - begin % align;
    const VkDeviceSize size = ((begin + bytes - base + align - 1) / align) * align;
    void* basePtr = reinterpret_cast<void*>(base);

    VkMemoryHostPointerPropertiesEXT props =
        vkStruct<VkMemoryHostPointerPropertiesEXT>(VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT);
    if (ctx.getHostPointerProperties()(d, VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT, basePtr,
                                       &props) != VK_SUCCESS ||
        props.memoryTypeBits == 0)
        return std::nullopt;

    HostImport im;
    im.m_offset = VkDeviceSize(begin - base);
    VkExternalMemoryBufferCreateInfo ext =
        vkStruct<VkExternalMemoryBufferCreateInfo>(VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO);
    ext.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    VkBufferCreateInfo bi = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, &ext);
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer;
    if (vkCreateBuffer(d, &bi, nullptr, &buffer) != VK_SUCCESS) return std::nullopt;
    im.m_buffer = UniqueBuffer(buffer, d);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(d, buffer, &req);
    const uint32_t type = ctx.memoryTypeIndex(req.memoryTypeBits & props.memoryTypeBits, 0);
    if (type == ~0u) return std::nullopt;

    VkImportMemoryHostPointerInfoEXT import =
        vkStruct<VkImportMemoryHostPointerInfoEXT>(VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT);
    import.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    import.pHostPointer = basePtr;
    VkMemoryAllocateInfo ai = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &import);
    ai.allocationSize = size;
    ai.memoryTypeIndex = type;
    VkDeviceMemory memory;
    if (vkAllocateMemory(d, &ai, nullptr, &memory) != VK_SUCCESS) return std::nullopt;
    im.m_memory = UniqueMemory(memory, d);
    if (vkBindBufferMemory(d, buffer, memory, 0) != VK_SUCCESS) return std::nullopt;
    return im;
}

}  // namespace rthdist::gpu
