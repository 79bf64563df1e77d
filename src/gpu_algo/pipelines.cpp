#include "gpu_algo/pipelines.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "gpu/context.hpp"
#include "rthdist_shared.h"

// SPIR-V embedded at build time (cmake/Shaders.cmake).
#include "cell_bounds.comp.h"
#include "cell_bounds_fix.comp.h"
#include "cell_build.comp.h"
#include "cell_heads.comp.h"
#include "cell_keys.comp.h"
#include "check_index.comp.h"
#include "check_queries.comp.h"
#include "coarsen.comp.h"
#include "compact.comp.h"
#include "cull.comp.h"
#include "grow_boxes.comp.h"
#include "ingest.comp.h"
#include "leaf_keys.comp.h"
#include "leaf_scatter.comp.h"
#include "leaf_slots.comp.h"
#include "refine.comp.h"
#include "refine_args.comp.h"
#include "resolve.comp.h"
#include "scan_add.comp.h"
#include "scan_block.comp.h"
#include "scatter.comp.h"
#include "search.rgen.h"
#include "search.rint.h"
#include "search.rmiss.h"
#include "search_rq.comp.h"

namespace rthdist::gpu {

namespace {

constexpr uint32_t kPushBytes = 128;

struct Spirv {
    const uint32_t* code;
    size_t bytes;
    const char* name;
};

template <size_t N>
Spirv spirv(const uint32_t (&a)[N], const char* name) {
    return {a, N * sizeof(uint32_t), name};
}

VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

}  // namespace

uint32_t groupsFor(uint64_t n, uint32_t groupSize) { return uint32_t((n + groupSize - 1) / groupSize); }

VkShaderModule Pipelines::createModule(const uint32_t* code, size_t bytes) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = code;
    VkShaderModule m;
    RTHDIST_VK_CHECK(vkCreateShaderModule(m_ctx.device(), &ci, nullptr, &m));
    return m;
}

Pipelines::Pipelines(Context& ctx, bool rayQuery, VkPipelineCache cache) : m_ctx(ctx), m_rayQuery(rayQuery) {
    VkDevice d = ctx.device();
    VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT;
    if (!rayQuery) {
        stages |= VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR |
                  VK_SHADER_STAGE_MISS_BIT_KHR;
        m_shaderStages |= VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR;
    }
    VkDescriptorSetLayoutBinding b{};
    b.binding = 0;
    b.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    b.descriptorCount = 1;
    b.stageFlags = stages;
    VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    sl.bindingCount = 1;
    sl.pBindings = &b;
    RTHDIST_VK_CHECK(vkCreateDescriptorSetLayout(d, &sl, nullptr, &m_setLayout));
    VkPushConstantRange range{stages, 0, kPushBytes};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &m_setLayout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    RTHDIST_VK_CHECK(vkCreatePipelineLayout(d, &pl, nullptr, &m_layout));
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &ps;
    RTHDIST_VK_CHECK(vkCreateDescriptorPool(d, &dp, nullptr, &m_pool));
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = m_pool;
    da.descriptorSetCount = 1;
    da.pSetLayouts = &m_setLayout;
    RTHDIST_VK_CHECK(vkAllocateDescriptorSets(d, &da, &m_set));

    const Spirv compute[size_t(Kernel::kCount)] = {
        spirv(k_spv_cell_keys_comp, "cell_keys"),
        spirv(k_spv_scan_block_comp, "scan_block"),
        spirv(k_spv_scan_add_comp, "scan_add"),
        spirv(k_spv_scatter_comp, "scatter"),
        spirv(k_spv_cell_heads_comp, "cell_heads"),
        spirv(k_spv_cell_build_comp, "cell_build"),
        spirv(k_spv_cull_comp, "cull"),
        spirv(k_spv_compact_comp, "compact"),
        spirv(k_spv_grow_boxes_comp, "grow_boxes"),
        spirv(k_spv_search_rq_comp, "search_rq"),
        spirv(k_spv_refine_comp, "refine"),
        spirv(k_spv_resolve_comp, "resolve"),
        spirv(k_spv_coarsen_comp, "coarsen"),
        spirv(k_spv_check_index_comp, "check_index"),
        spirv(k_spv_check_queries_comp, "check_queries"),
        spirv(k_spv_leaf_slots_comp, "leaf_slots"),
        spirv(k_spv_leaf_keys_comp, "leaf_keys"),
        spirv(k_spv_leaf_scatter_comp, "leaf_scatter"),
        spirv(k_spv_cell_bounds_comp, "cell_bounds"),
        spirv(k_spv_cell_bounds_fix_comp, "cell_bounds_fix"),
        spirv(k_spv_ingest_comp, "ingest"),
        spirv(k_spv_refine_args_comp, "refine_args"),
    };
    for (size_t k = 0; k < size_t(Kernel::kCount); ++k) {
        if (Kernel(k) == Kernel::kSearchRayQuery && !rayQuery) continue;
        VkShaderModule m = createModule(compute[k].code, compute[k].bytes);
        VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
        ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        ci.stage.module = m;
        ci.stage.pName = "main";
        ci.layout = m_layout;
        ci.flags = VK_PIPELINE_CREATE_DISPATCH_BASE_BIT;
        VkResult r = vkCreateComputePipelines(d, cache, 1, &ci, nullptr, &m_compute[k]);
        vkDestroyShaderModule(d, m, nullptr);
        RTHDIST_VK_CHECK(r);
        ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE, uint64_t(m_compute[k]), compute[k].name);
    }
    if (rayQuery) return;

    VkShaderModule rgen = createModule(k_spv_search_rgen, sizeof(k_spv_search_rgen));
    VkShaderModule rmiss = createModule(k_spv_search_rmiss, sizeof(k_spv_search_rmiss));
    VkShaderModule rint = createModule(k_spv_search_rint, sizeof(k_spv_search_rint));
    VkPipelineShaderStageCreateInfo st[3]{};
    const VkShaderStageFlagBits kinds[3] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                            VK_SHADER_STAGE_INTERSECTION_BIT_KHR};
    const VkShaderModule mods[3] = {rgen, rmiss, rint};
    for (int i = 0; i < 3; ++i) {
        st[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        st[i].stage = kinds[i];
        st[i].module = mods[i];
        st[i].pName = "main";
    }
    VkRayTracingShaderGroupCreateInfoKHR g[3]{};
    for (int i = 0; i < 3; ++i) {
        g[i] = {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
        g[i].generalShader = g[i].closestHitShader = g[i].anyHitShader = g[i].intersectionShader =
            VK_SHADER_UNUSED_KHR;
    }
    g[0].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    g[0].generalShader = 0;
    g[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    g[1].generalShader = 1;
    g[2].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
    g[2].intersectionShader = 2;
    VkRayTracingPipelineCreateInfoKHR rci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
    rci.stageCount = 3;
    rci.pStages = st;
    rci.groupCount = 3;
    rci.pGroups = g;
    rci.maxPipelineRayRecursionDepth = 1;
    rci.layout = m_layout;
    VkResult r = ctx.rt().createRtPipelines(d, VK_NULL_HANDLE, cache, 1, &rci, nullptr, &m_rtPipeline);
    for (VkShaderModule m : mods) vkDestroyShaderModule(d, m, nullptr);
    RTHDIST_VK_CHECK(r);
    ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE, uint64_t(m_rtPipeline), "search_rt_pipeline");

    // Shader binding table: raygen | miss | hit, each region aligned to the
    // base alignment; the buffer's address is rounded up, so over-allocate.
    const auto& props = ctx.rtProps();
    const uint32_t handleSize = props.shaderGroupHandleSize;
    const VkDeviceSize stride = alignUp(handleSize, props.shaderGroupHandleAlignment);
    const VkDeviceSize base = props.shaderGroupBaseAlignment;
    const VkDeviceSize region = alignUp(stride, base);
    std::vector<uint8_t> handles(3 * handleSize);
    RTHDIST_VK_CHECK(ctx.rt().getGroupHandles(d, m_rtPipeline, 0, 3, handles.size(), handles.data()));
    m_sbt = Buffer(ctx, 3 * region + base,
                   VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                   MemoryKind::kHost);
    const VkDeviceAddress start = alignUp(m_sbt.address(), base);
    auto* bytes = static_cast<uint8_t*>(m_sbt.mapped()) + (start - m_sbt.address());
    for (int i = 0; i < 3; ++i) std::memcpy(bytes + i * region, handles.data() + i * handleSize, handleSize);
    m_raygen = {start, stride, stride};
    m_miss = {start + region, stride, stride};
    m_hit = {start + 2 * region, stride, stride};
}

Pipelines::~Pipelines() {
    VkDevice d = m_ctx.device();
    for (VkPipeline p : m_compute)
        if (p) vkDestroyPipeline(d, p, nullptr);
    if (m_rtPipeline) vkDestroyPipeline(d, m_rtPipeline, nullptr);
    if (m_pool) vkDestroyDescriptorPool(d, m_pool, nullptr);
    if (m_layout) vkDestroyPipelineLayout(d, m_layout, nullptr);
    if (m_setLayout) vkDestroyDescriptorSetLayout(d, m_setLayout, nullptr);
}

void Pipelines::bindTlas(VkAccelerationStructureKHR tlas) {
    VkWriteDescriptorSetAccelerationStructureKHR as{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    as.accelerationStructureCount = 1;
    as.pAccelerationStructures = &tlas;
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &as};
    w.dstSet = m_set;
    w.dstBinding = 0;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    vkUpdateDescriptorSets(m_ctx.device(), 1, &w, 0, nullptr);
}

void Pipelines::cmdBindCompute(VkCommandBuffer cmd, Kernel kernel, const void* push,
                               uint32_t pushSize) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_compute[size_t(kernel)]);
    if (kernel == Kernel::kSearchRayQuery)
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout, 0, 1, &m_set, 0, nullptr);
    vkCmdPushConstants(cmd, m_layout,
                       m_rayQuery ? VK_SHADER_STAGE_COMPUTE_BIT
                                  : (VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_RAYGEN_BIT_KHR |
                                     VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR),
                       0, pushSize, push);
}

void Pipelines::cmdDispatch(VkCommandBuffer cmd, Kernel kernel, const void* push, uint32_t pushSize,
                            uint32_t groups) const {
    if (groups == 0) return;
    cmdBindCompute(cmd, kernel, push, pushSize);
    // Large 1-D dispatches are split to respect maxComputeWorkGroupCount[0]
    // (the device's, or a smaller one a test set); shaders see
    // gl_WorkGroupID offsets through vkCmdDispatchBase.
    const uint32_t maxGroups = std::max<uint32_t>(1, m_ctx.limits().maxGroupsX);
    for (uint64_t first = 0; first < groups; first += maxGroups)
        vkCmdDispatchBase(cmd, uint32_t(first), 0, 0, uint32_t(std::min<uint64_t>(maxGroups, groups - first)),
                          1, 1);
}

void Pipelines::cmdDispatchIndirect(VkCommandBuffer cmd, Kernel kernel, const void* push, uint32_t pushSize,
                                    VkBuffer args, VkDeviceSize offset) const {
    cmdBindCompute(cmd, kernel, push, pushSize);
    vkCmdDispatchIndirect(cmd, args, offset);
}

void Pipelines::cmdTraceRays(VkCommandBuffer cmd, const void* push, uint32_t pushSize, uint32_t width) const {
    if (width == 0) return;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, m_rtPipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, m_layout, 0, 1, &m_set, 0, nullptr);
    vkCmdPushConstants(cmd, m_layout,
                       VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_RAYGEN_BIT_KHR |
                           VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR,
                       0, pushSize, push);
    m_ctx.rt().cmdTraceRays(cmd, &m_raygen, &m_miss, &m_hit, &m_callable, width, 1, 1);
}

}  // namespace rthdist::gpu
