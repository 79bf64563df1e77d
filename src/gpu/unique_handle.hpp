// One move-only owner for every Vulkan handle rthdist creates (house style 4:
// nothing leaks on an exception path, no deinit() a destructor could do).
//
// Unique<Handle, Deleter> holds one handle and the deleter that destroys it
// (the deleter carries what the destroy call needs: the device, a loaded
// entry point). A member that is a Unique is destroyed when a constructor
// throws after it was assigned, so an object built step by step releases
// whatever it had created so far.
//
// Creation: RTHDIST_VK_CREATE for the vkCreateXxx(device, &info, nullptr,
// &handle) calls; otherwise create into a local handle, check it, then hand
// it over with nothing that can throw in between (Vulkan leaves the output
// undefined on failure, so an owner is never handed a handle of a failed
// call):
//
//     m_layout = RTHDIST_VK_CREATE(UniquePipelineLayout, vkCreatePipelineLayout, device, info);
//
//     VkPipeline raw;
//     RTHDIST_VK_CHECK(vkCreateComputePipelines(device, cache, 1, &info, nullptr, &raw));
//     m_pipeline = UniquePipeline(raw, device);
//
// Threading: like the handle it owns (Vulkan's external synchronization rules).
#pragma once

#include <vulkan/vulkan.h>

#include <utility>

#include "gpu/vk_check.hpp"

namespace rthdist::gpu {

template <typename Handle, typename Deleter>
class Unique {
public:
    using HandleType = Handle;
    using DeleterType = Deleter;

    Unique() = default;
    Unique(Handle handle, Deleter deleter) noexcept : m_handle(handle), m_deleter(std::move(deleter)) {}
    Unique(Unique&& o) noexcept
        : m_handle(std::exchange(o.m_handle, Handle{})), m_deleter(std::move(o.m_deleter)) {}
    Unique& operator=(Unique&& o) noexcept {
        if (this != &o) {
            reset();
            m_handle = std::exchange(o.m_handle, Handle{});
            m_deleter = std::move(o.m_deleter);
        }
        return *this;
    }
    Unique(const Unique&) = delete;
    Unique& operator=(const Unique&) = delete;
    ~Unique() { reset(); }

    // Destroys the handle now (no-op when empty).
    void reset() noexcept {
        if (m_handle != Handle{}) m_deleter(std::exchange(m_handle, Handle{}));
    }
    // Gives the handle up without destroying it.
    [[nodiscard]] Handle release() noexcept { return std::exchange(m_handle, Handle{}); }
    [[nodiscard]] Handle get() const noexcept { return m_handle; }
    // Address of the handle, for Vulkan calls that take an array of them.
    [[nodiscard]] const Handle* ptr() const noexcept { return &m_handle; }
    [[nodiscard]] const Deleter& deleter() const noexcept { return m_deleter; }
    [[nodiscard]] explicit operator bool() const noexcept { return m_handle != Handle{}; }

private:
    Handle m_handle{};
    Deleter m_deleter{};
};

// Objects created from a VkDevice and destroyed by vkDestroyXxx(device,
// handle, nullptr) (vkFreeMemory has the same shape).
template <typename Handle, void (*Destroy)(VkDevice, Handle, const VkAllocationCallbacks*)>
struct DeviceChildDeleter {
    VkDevice device = VK_NULL_HANDLE;
    DeviceChildDeleter() = default;
    DeviceChildDeleter(VkDevice d) : device(d) {}  // NOLINT: implicit, so owners take the device
    void operator()(Handle h) const noexcept { Destroy(device, h, nullptr); }
};

template <typename Handle, void (*Destroy)(VkDevice, Handle, const VkAllocationCallbacks*)>
using UniqueDeviceChild = Unique<Handle, DeviceChildDeleter<Handle, Destroy>>;

using UniqueBuffer = UniqueDeviceChild<VkBuffer, vkDestroyBuffer>;
using UniqueMemory = UniqueDeviceChild<VkDeviceMemory, vkFreeMemory>;
using UniqueShaderModule = UniqueDeviceChild<VkShaderModule, vkDestroyShaderModule>;
using UniquePipeline = UniqueDeviceChild<VkPipeline, vkDestroyPipeline>;
using UniquePipelineLayout = UniqueDeviceChild<VkPipelineLayout, vkDestroyPipelineLayout>;
using UniquePipelineCache = UniqueDeviceChild<VkPipelineCache, vkDestroyPipelineCache>;
using UniqueDescriptorSetLayout = UniqueDeviceChild<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = UniqueDeviceChild<VkDescriptorPool, vkDestroyDescriptorPool>;
using UniqueCommandPool = UniqueDeviceChild<VkCommandPool, vkDestroyCommandPool>;
using UniqueFence = UniqueDeviceChild<VkFence, vkDestroyFence>;
using UniqueQueryPool = UniqueDeviceChild<VkQueryPool, vkDestroyQueryPool>;

// Objects whose destroy entry point is loaded at run time (the loader does
// not export it): the deleter carries it with the parent object.
template <typename Parent, typename Handle, typename DestroyFn>
struct LoadedDeleter {
    Parent parent{};
    DestroyFn destroy = nullptr;
    void operator()(Handle h) const noexcept { destroy(parent, h, nullptr); }
};
// Acceleration structures (gpu::RtFunctions::destroyAccel).
using UniqueAccel =
    Unique<VkAccelerationStructureKHR,
           LoadedDeleter<VkDevice, VkAccelerationStructureKHR, PFN_vkDestroyAccelerationStructureKHR>>;
// The validation layer's messenger (VK_EXT_debug_utils).
using UniqueMessenger =
    Unique<VkDebugUtilsMessengerEXT,
           LoadedDeleter<VkInstance, VkDebugUtilsMessengerEXT, PFN_vkDestroyDebugUtilsMessengerEXT>>;

// The root, the device (the instance is the process's:
// gpu/process_instance.hpp). Context waits for the device to be idle
// before anything goes, and declares them first so they go last.
template <typename Handle, void (*Destroy)(Handle, const VkAllocationCallbacks*)>
struct RootDeleter {
    void operator()(Handle h) const noexcept { Destroy(h, nullptr); }
};
using UniqueDevice = Unique<VkDevice, RootDeleter<VkDevice, vkDestroyDevice>>;

// Calls create(device, &info, nullptr, &handle) (a vkCreateXxx of the
// device) and returns the handle owned; a failure throws VulkanError and
// nothing is owned. Through RTHDIST_VK_CREATE, which names the call.
template <typename Owner, typename Create, typename Info>
[[nodiscard]] Owner createOwned(Create create, VkDevice device, const Info& info, const char* expr,
                                const char* file, int line) {
    typename Owner::HandleType handle{};
    const VkResult result = create(device, &info, nullptr, &handle);
    if (result < 0) throwVulkanError(result, expr, file, line);
    return Owner(handle, device);
}

}  // namespace rthdist::gpu

// m_fence = RTHDIST_VK_CREATE(UniqueFence, vkCreateFence, device, fenceInfo);
#define RTHDIST_VK_CREATE(Owner, create, device, info) \
    ::rthdist::gpu::createOwned<Owner>(create, device, info, #create, __FILE__, __LINE__)
