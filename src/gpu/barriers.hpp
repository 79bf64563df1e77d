// Pipeline barriers, recorded with synchronization2 (vkCmdPipelineBarrier2,
// Vulkan 1.3 core; every Context enables the feature, gpu/context.hpp).
// Global memory barriers only: rthdist's buffers are used by one queue, so
// no buffer or image barrier (ownership, layout) is ever needed.
#pragma once

#include <vulkan/vulkan.h>

namespace rthdist::gpu {

// Global memory barrier between two groups of pipeline stages.
void cmdBarrier2(VkCommandBuffer cmd, VkPipelineStageFlags2 src, VkAccessFlags2 srcAccess,
                 VkPipelineStageFlags2 dst, VkAccessFlags2 dstAccess);
// The same with the legacy flag types: their bits are the low bits of the
// synchronization2 ones, so the barrier is recorded as cmdBarrier2.
void cmdBarrier(VkCommandBuffer cmd, VkPipelineStageFlags src, VkAccessFlags srcAccess,
                VkPipelineStageFlags dst, VkAccessFlags dstAccess);
// Shader and transfer writes -> shader and transfer reads/writes, over the
// given shader stages (compute, plus ray tracing where the device has it).
void cmdShaderBarrier(VkCommandBuffer cmd, VkPipelineStageFlags shaderStages);
// Every device write so far -> host reads: recorded before a submission whose
// results the host reads once its fence has signalled (Context::submitAndWait
// records it on every submission).
void cmdHostReadBarrier(VkCommandBuffer cmd);

}  // namespace rthdist::gpu
