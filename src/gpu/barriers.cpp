#include "gpu/barriers.hpp"

#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

void cmdBarrier2(VkCommandBuffer cmd, VkPipelineStageFlags2 src, VkAccessFlags2 srcAccess,
                 VkPipelineStageFlags2 dst, VkAccessFlags2 dstAccess) {
    VkMemoryBarrier2 mb = vkStruct<VkMemoryBarrier2>(VK_STRUCTURE_TYPE_MEMORY_BARRIER_2);
    mb.srcStageMask = src;
    mb.srcAccessMask = srcAccess;
    mb.dstStageMask = dst;
    mb.dstAccessMask = dstAccess;
    VkDependencyInfo dep = vkStruct<VkDependencyInfo>(VK_STRUCTURE_TYPE_DEPENDENCY_INFO);
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &mb;
    vkCmdPipelineBarrier2(cmd, &dep);
}

void cmdBarrier(VkCommandBuffer cmd, VkPipelineStageFlags src, VkAccessFlags srcAccess,
                VkPipelineStageFlags dst, VkAccessFlags dstAccess) {
    cmdBarrier2(cmd, src, srcAccess, dst, dstAccess);
}

void cmdShaderBarrier(VkCommandBuffer cmd, VkPipelineStageFlags shaderStages) {
    const VkPipelineStageFlags2 stages =
        VkPipelineStageFlags2(shaderStages) | VK_PIPELINE_STAGE_2_TRANSFER_BIT;
    cmdBarrier2(cmd, stages, VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT, stages,
                VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_TRANSFER_READ_BIT |
                    VK_ACCESS_2_TRANSFER_WRITE_BIT);
}

void cmdHostReadBarrier(VkCommandBuffer cmd) {
    cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

}  // namespace rthdist::gpu
