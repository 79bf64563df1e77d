// What a device must offer for a Context, as data (vk-bootstrap's
// PhysicalDeviceSelector): a core version, device extensions and named
// features, plus a compute queue with timestamps (always). Probing names
// every unmet entry, and device creation enables exactly the listed
// extensions and features.
//
// Two families: computeRequirements() for work that only dispatches compute
// shaders over device addresses (the splat renderer: any Vulkan 1.3 compute
// device with 64-bit buffer atomics), and backendRequirements() for the
// ray-tracing backends (that, plus acceleration structures and the backend's
// extension).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rthdist/options.hpp"
#include "rthdist/vulkan_interop.hpp"

namespace rthdist::gpu {

enum class DeviceFeature : uint32_t {
    kShaderInt64,               // VkPhysicalDeviceFeatures
    kBufferDeviceAddress,       // Vulkan 1.2
    kShaderBufferInt64Atomics,  // Vulkan 1.2
    kScalarBlockLayout,         // Vulkan 1.2
    kSynchronization2,          // Vulkan 1.3 (gpu/barriers.hpp records vkCmdPipelineBarrier2)
    kAccelerationStructure,     // VK_KHR_acceleration_structure
    kRayQuery,                  // VK_KHR_ray_query
    kRayTracingPipeline,        // VK_KHR_ray_tracing_pipeline
    kShaderFloat64,             // VkPhysicalDeviceFeatures: double views of device input (ingest_f64.comp)
    kTraceRaysIndirect,         // VK_KHR_ray_tracing_pipeline: traces sized by the device
    kCount
};

// The feature's name in the Vulkan structures ("rayQuery").
[[nodiscard]] const char* featureName(DeviceFeature feature);

struct DeviceRequirements {
    // What a Context created with these reports as its backend (kRayQuery,
    // kRtPipeline; kAuto for a compute-only context, which has no ray tracing).
    Backend backend = Backend::kAuto;
    uint32_t apiVersion = VK_API_VERSION_1_3;
    std::vector<const char*> extensions;
    std::vector<DeviceFeature> features;

    [[nodiscard]] bool needs(DeviceFeature feature) const;
    [[nodiscard]] bool needs(const char* extension) const;
};

// Compute shaders over buffer device addresses with 64-bit integers and
// atomics, scalar block layout and synchronization2 barriers.
[[nodiscard]] DeviceRequirements computeRequirements();
// computeRequirements() plus acceleration structures and, for kRayQuery,
// VK_KHR_ray_query or, for kRtPipeline, VK_KHR_ray_tracing_pipeline.
[[nodiscard]] DeviceRequirements backendRequirements(Backend backend);

// Why `pd` cannot meet `req`, one entry per unmet requirement ("Vulkan 1.3
// (device offers 1.2)", "extension VK_KHR_ray_query", "feature rayQuery",
// "a compute queue with timestamps"); empty when it can.
[[nodiscard]] std::vector<std::string> unmetRequirements(VkPhysicalDevice pd, const DeviceRequirements& req);
// Whether the device has this one feature (an optional one: shaderFloat64,
// rayTracingPipelineTraceRaysIndirect).
[[nodiscard]] bool deviceHasFeature(VkPhysicalDevice pd, DeviceFeature feature);

// Sets the flag of every feature of `req` in the embedder's feature
// structures (rthdist/vulkan_interop.hpp), and lists the extensions and the
// features' names there.
void describeForEmbedder(const DeviceRequirements& req, VulkanDeviceSetup& setup);

// Whether `pd` offers the device extension `name`.
[[nodiscard]] bool deviceHasExtension(VkPhysicalDevice pd, const char* name);

// The index of the first queue family with compute and timestamps, or ~0u.
[[nodiscard]] uint32_t computeQueueFamily(VkPhysicalDevice pd);

// Creates a device of `pd` with exactly the extensions and features of `req`
// (plus `extraExtensions`, optional ones the caller found) and one queue of
// `queueFamily`. Only the feature structures that hold a listed feature are
// chained (one of an extension that is not enabled would be invalid there).
[[nodiscard]] VkResult createDeviceFor(VkPhysicalDevice pd, const DeviceRequirements& req,
                                       std::span<const char* const> extraExtensions, uint32_t queueFamily,
                                       VkDevice* device);

}  // namespace rthdist::gpu
