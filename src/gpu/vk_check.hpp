// Vulkan failures (VkResult < 0) are exceptional inside the library: they throw
// VulkanError with the result, the expression, file and line; the public API
// catches at its boundary and turns them into an Error.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace rthdist::gpu {

class VulkanError : public std::runtime_error {
public:
    VulkanError(VkResult result, const std::string& what) : std::runtime_error(what), m_result(result) {}
    [[nodiscard]] VkResult result() const { return m_result; }
    // The device or the host ran out of memory (kOutOfMemory at the API).
    [[nodiscard]] bool outOfMemory() const {
        return m_result == VK_ERROR_OUT_OF_DEVICE_MEMORY || m_result == VK_ERROR_OUT_OF_HOST_MEMORY;
    }

private:
    VkResult m_result;
};

[[noreturn]] void throwVulkanError(VkResult result, const char* expr, const char* file, int line);
const char* vkResultName(VkResult result);

}  // namespace rthdist::gpu

#define RTHDIST_VK_CHECK(expr)                                                               \
    do {                                                                                     \
        VkResult rthdist_vk_result_ = (expr);                                                \
        if (rthdist_vk_result_ < 0)                                                          \
            ::rthdist::gpu::throwVulkanError(rthdist_vk_result_, #expr, __FILE__, __LINE__); \
    } while (0)
