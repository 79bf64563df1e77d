// Shader modules, pipeline layouts and compute pipelines from SPIR-V embedded
// at build time (cmake/Shaders.cmake's k_spv_* arrays): the one way rthdist
// makes them, for the engine's kernels (gpu/pipelines.hpp) and the renderer
// (render/splat_renderer.cpp). Each returns an owner (gpu/unique_handle.hpp)
// and throws VulkanError when the driver refuses.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>

#include "gpu/unique_handle.hpp"

namespace rthdist::gpu {

class Context;

[[nodiscard]] UniqueShaderModule createShaderModule(VkDevice device, std::span<const uint32_t> spirv);

// A layout of `setLayouts` and one push-constant range [0, pushBytes) seen by
// `pushStages`.
[[nodiscard]] UniquePipelineLayout createPipelineLayout(VkDevice device,
                                                        std::span<const VkDescriptorSetLayout> setLayouts,
                                                        VkShaderStageFlags pushStages, uint32_t pushBytes);

// A compute pipeline of `spirv`'s "main" over `layout`. cache: a
// VkPipelineCache or VK_NULL_HANDLE; flags: e.g. VK_PIPELINE_CREATE_DISPATCH_BASE_BIT
// for vkCmdDispatchBase; debugName: its name in validation messages and captures.
[[nodiscard]] UniquePipeline createComputePipeline(const Context& ctx, std::span<const uint32_t> spirv,
                                                   VkPipelineLayout layout, VkPipelineCache cache,
                                                   VkPipelineCreateFlags flags, const char* debugName);

}  // namespace rthdist::gpu
