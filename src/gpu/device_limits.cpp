#include "gpu/device_limits.hpp"

#include <algorithm>

#include "gpu/device_requirements.hpp"
#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

namespace {

void readHeaps(VkPhysicalDevice pd, DeviceLimits& out) {
    VkPhysicalDeviceMemoryBudgetPropertiesEXT budget = vkStruct<VkPhysicalDeviceMemoryBudgetPropertiesEXT>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT);
    const bool hasBudget = deviceHasExtension(pd, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    VkPhysicalDeviceMemoryProperties2 mem2 = vkStruct<VkPhysicalDeviceMemoryProperties2>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2, hasBudget ? &budget : nullptr);
    vkGetPhysicalDeviceMemoryProperties2(pd, &mem2);
    const VkPhysicalDeviceMemoryProperties& mem = mem2.memoryProperties;
    uint64_t device = 0, host = 0, deviceBudget = 0;
    for (uint32_t h = 0; h < mem.memoryHeapCount; ++h) {
        if (!(mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) || mem.memoryHeaps[h].size < device)
            continue;
        device = mem.memoryHeaps[h].size;
        deviceBudget =
            hasBudget && budget.heapBudget[h] > 0 ? std::min(budget.heapBudget[h], device) : device;
    }
    for (uint32_t t = 0; t < mem.memoryTypeCount; ++t)
        if (mem.memoryTypes[t].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
            host = std::max<uint64_t>(host, mem.memoryHeaps[mem.memoryTypes[t].heapIndex].size);
    if (device > 0) out.deviceHeapBytes = device;
    if (deviceBudget > 0) out.deviceBudgetBytes = deviceBudget;
    if (host > 0) out.hostHeapBytes = host;
}

}  // namespace

DeviceLimits readDeviceLimits(VkPhysicalDevice pd) {
    DeviceLimits out;
    const bool hasRtPipeline = deviceHasExtension(pd, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
    const bool hasAccel = deviceHasExtension(pd, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
    const bool hasMaintenance4 = deviceHasExtension(pd, VK_KHR_MAINTENANCE_4_EXTENSION_NAME);
    VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt =
        vkStruct<VkPhysicalDeviceRayTracingPipelinePropertiesKHR>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR);
    VkPhysicalDeviceAccelerationStructurePropertiesKHR as =
        vkStruct<VkPhysicalDeviceAccelerationStructurePropertiesKHR>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR);
    VkPhysicalDeviceMaintenance4PropertiesKHR m4 = vkStruct<VkPhysicalDeviceMaintenance4PropertiesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES_KHR);
    VkPhysicalDeviceMaintenance3Properties m3 = vkStruct<VkPhysicalDeviceMaintenance3Properties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES);
    // Only structures of extensions the device has go into the chain.
    void* chain = nullptr;
    if (hasRtPipeline) {
        rt.pNext = chain;
        chain = &rt;
    }
    if (hasAccel) {
        as.pNext = chain;
        chain = &as;
    }
    if (hasMaintenance4) {
        m4.pNext = chain;
        chain = &m4;
    }
    m3.pNext = chain;
    VkPhysicalDeviceProperties2 p2 =
        vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &m3);
    vkGetPhysicalDeviceProperties2(pd, &p2);
    const VkPhysicalDeviceLimits& l = p2.properties.limits;
    out.maxAllocationBytes = m3.maxMemoryAllocationSize;
    if (hasMaintenance4) out.maxBufferBytes = m4.maxBufferSize;
    out.maxGroupsX = l.maxComputeWorkGroupCount[0];
    if (hasRtPipeline) {
        const uint64_t width = uint64_t(l.maxComputeWorkGroupCount[0]) * l.maxComputeWorkGroupSize[0];
        out.maxRayDispatch = std::min<uint64_t>(rt.maxRayDispatchInvocationCount, width);
    }
    if (hasAccel) out.maxPrimitives = as.maxPrimitiveCount;
    readHeaps(pd, out);
    return out;
}

void requireWithin(uint64_t value, uint64_t limit, const char* what, const char* limitName) {
    if (value <= limit) return;
    throw LimitError(std::string(what) + " needs " + std::to_string(value) + ", more than the device's " +
                     limitName + " (" + std::to_string(limit) + ")");
}

std::vector<std::pair<std::string, uint64_t>> DeviceLimits::named() const {
    return {{"max_buffer_bytes", maxBufferBytes},   {"max_allocation_bytes", maxAllocationBytes},
            {"device_heap_bytes", deviceHeapBytes}, {"host_heap_bytes", hostHeapBytes},
            {"max_work_groups_x", maxGroupsX},      {"max_ray_dispatch", maxRayDispatch},
            {"max_blas_primitives", maxPrimitives}};
}

}  // namespace rthdist::gpu
