#include "gpu/compute_pipeline.hpp"

#include "gpu/context.hpp"
#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

UniqueShaderModule createShaderModule(VkDevice device, std::span<const uint32_t> spirv) {
    VkShaderModuleCreateInfo ci =
        vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    ci.codeSize = spirv.size_bytes();
    ci.pCode = spirv.data();
    return RTHDIST_VK_CREATE(UniqueShaderModule, vkCreateShaderModule, device, ci);
}

UniquePipelineLayout createPipelineLayout(VkDevice device, std::span<const VkDescriptorSetLayout> setLayouts,
                                          VkShaderStageFlags pushStages, uint32_t pushBytes) {
    const VkPushConstantRange range{pushStages, 0, pushBytes};
    VkPipelineLayoutCreateInfo ci =
        vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    ci.setLayoutCount = uint32_t(setLayouts.size());
    ci.pSetLayouts = setLayouts.data();
    ci.pushConstantRangeCount = 1;
    ci.pPushConstantRanges = &range;
    return RTHDIST_VK_CREATE(UniquePipelineLayout, vkCreatePipelineLayout, device, ci);
}

UniquePipeline createComputePipeline(const Context& ctx, std::span<const uint32_t> spirv,
                                     VkPipelineLayout layout, VkPipelineCache cache,
                                     VkPipelineCreateFlags flags, const char* debugName) {
    const VkDevice d = ctx.device();
    const UniqueShaderModule module = createShaderModule(d, spirv);
    VkComputePipelineCreateInfo ci =
        vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    ci.flags = flags;
    ci.stage = vkStruct<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module.get();
    ci.stage.pName = "main";
    ci.layout = layout;
    VkPipeline pipeline;
    RTHDIST_VK_CHECK(vkCreateComputePipelines(d, cache, 1, &ci, nullptr, &pipeline));
    UniquePipeline owned(pipeline, d);
    ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline), debugName);
    return owned;
}

}  // namespace rthdist::gpu
