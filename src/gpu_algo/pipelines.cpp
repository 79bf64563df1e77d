#include "gpu_algo/pipelines.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <exception>
#include <span>
#include <system_error>
#include <thread>
#include <vector>

#include "core/stopwatch.hpp"
#include "gpu/compute_pipeline.hpp"
#include "gpu/context.hpp"
#include "gpu/vk_struct.hpp"
#include "rthdist_shared.h"

// SPIR-V embedded at build time (cmake/Shaders.cmake).
#include "batch_nearest.comp.h"
#include "batch_witness.comp.h"
#include "cell_bounds.comp.h"
#include "cell_bounds_fix.comp.h"
#include "cell_build.comp.h"
#include "cell_heads.comp.h"
#include "cell_keys.comp.h"
#include "cells_total.comp.h"
#include "cert_scan.comp.h"
#include "cert_witness.comp.h"
#include "check_index.comp.h"
#include "check_queries.comp.h"
#include "coarsen.comp.h"
#include "compact.comp.h"
#include "cull.comp.h"
#include "grow_boxes.comp.h"
#include "ingest.comp.h"
#include "ingest_f64.comp.h"
#include "leaf_first.comp.h"
#include "leaf_groups.comp.h"
#include "leaf_keys.comp.h"
#include "leaf_scatter.comp.h"
#include "leaf_slots.comp.h"
#include "probe_levels.comp.h"
#include "refine.comp.h"
#include "refine_args.comp.h"
#include "resolve.comp.h"
#include "sample_gather.comp.h"
#include "scan_add.comp.h"
#include "scan_block.comp.h"
#include "scatter.comp.h"
#include "search.rgen.h"
#include "search.rint.h"
#include "search.rmiss.h"
#include "search_advance.comp.h"
#include "search_rq.comp.h"
#include "sweep_targets.comp.h"
#include "tail_scan.comp.h"
// The point-to-surface search (prepareSurfaceSearch).
#include "surface_search.rgen.h"
#include "surface_search.rint.h"
#include "surface_search_rq.comp.h"
#include "surface_tail.comp.h"

namespace rthdist::gpu {

namespace {

constexpr uint32_t kPushBytes = 128;

struct Spirv {
    std::span<const uint32_t> code;
    const char* name;
};

VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

// The kernels' SPIR-V, in Kernel order.
const std::array<Spirv, size_t(Kernel::kCount)> kComputeSpirv = {{
    {k_spv_cell_keys_comp, "cell_keys"},
    {k_spv_scan_block_comp, "scan_block"},
    {k_spv_scan_add_comp, "scan_add"},
    {k_spv_scatter_comp, "scatter"},
    {k_spv_cell_heads_comp, "cell_heads"},
    {k_spv_cell_build_comp, "cell_build"},
    {k_spv_cull_comp, "cull"},
    {k_spv_compact_comp, "compact"},
    {k_spv_grow_boxes_comp, "grow_boxes"},
    {k_spv_search_rq_comp, "search_rq"},
    {k_spv_refine_comp, "refine"},
    {k_spv_resolve_comp, "resolve"},
    {k_spv_coarsen_comp, "coarsen"},
    {k_spv_check_index_comp, "check_index"},
    {k_spv_check_queries_comp, "check_queries"},
    {k_spv_leaf_slots_comp, "leaf_slots"},
    {k_spv_leaf_keys_comp, "leaf_keys"},
    {k_spv_leaf_scatter_comp, "leaf_scatter"},
    {k_spv_cell_bounds_comp, "cell_bounds"},
    {k_spv_cell_bounds_fix_comp, "cell_bounds_fix"},
    {k_spv_ingest_comp, "ingest"},
    {k_spv_refine_args_comp, "refine_args"},
    {k_spv_ingest_f64_comp, "ingest_f64"},
    {k_spv_sample_gather_comp, "sample_gather"},
    {k_spv_batch_nearest_comp, "batch_nearest"},
    {k_spv_batch_witness_comp, "batch_witness"},
    {k_spv_search_advance_comp, "search_advance"},
    {k_spv_probe_levels_comp, "probe_levels"},
    {k_spv_tail_scan_comp, "tail_scan"},
    {k_spv_cert_scan_comp, "cert_scan"},
    {k_spv_cert_witness_comp, "cert_witness"},
    {k_spv_sweep_targets_comp, "sweep_targets"},
    {k_spv_leaf_first_comp, "leaf_first"},
    {k_spv_cells_total_comp, "cells_total"},
    {k_spv_leaf_groups_comp, "leaf_groups"},
    {k_spv_surface_search_rq_comp, "surface_search_rq"},
    {k_spv_surface_tail_comp, "surface_tail"},
}};

}  // namespace

uint32_t groupsFor(uint64_t n, uint32_t groupSize) { return uint32_t((n + groupSize - 1) / groupSize); }

Pipelines::Pipelines(Context& ctx, bool rayQuery, VkPipelineCache cache, int threads)
    : m_ctx(ctx), m_rayQuery(rayQuery), m_stages(VK_SHADER_STAGE_COMPUTE_BIT) {
    if (!rayQuery) {
        m_stages |= VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR |
                    VK_SHADER_STAGE_MISS_BIT_KHR;
        m_shaderStages |= VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR;
    }
    // Each step's handles are owned as soon as they exist: a throw in a later
    // step releases them.
    createLayout();
    const auto t0 = core::Clock::now();
    createPipelines(cache, threads);
    m_createMs = core::msSince(t0);
    if (!rayQuery) createShaderBindingTable();
}

void Pipelines::createLayout() {
    const VkDevice d = m_ctx.device();
    VkDescriptorSetLayoutBinding b{};
    b.binding = 0;
    b.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    b.descriptorCount = 1;
    b.stageFlags = m_stages;
    VkDescriptorSetLayoutCreateInfo sl =
        vkStruct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    sl.bindingCount = 1;
    sl.pBindings = &b;
    m_setLayout = RTHDIST_VK_CREATE(UniqueDescriptorSetLayout, vkCreateDescriptorSetLayout, d, sl);
    m_layout = createPipelineLayout(d, {m_setLayout.ptr(), 1}, m_stages, kPushBytes);

    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1};
    VkDescriptorPoolCreateInfo dp =
        vkStruct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    dp.maxSets = 1;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &ps;
    m_pool = RTHDIST_VK_CREATE(UniqueDescriptorPool, vkCreateDescriptorPool, d, dp);
    VkDescriptorSetAllocateInfo da =
        vkStruct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    da.descriptorPool = m_pool.get();
    da.descriptorSetCount = 1;
    da.pSetLayouts = m_setLayout.ptr();
    RTHDIST_VK_CHECK(vkAllocateDescriptorSets(d, &da, &m_set));
}

std::vector<Kernel> Pipelines::startupKernels() const {
    std::vector<Kernel> kernels;
    for (size_t k = 0; k < size_t(Kernel::kCount); ++k) {
        if (Kernel(k) == Kernel::kSearchRayQuery && !m_rayQuery) continue;
        if (Kernel(k) == Kernel::kSurfaceSearchRayQuery || Kernel(k) == Kernel::kSurfaceTail)
            continue;  // prepareSurfaceSearch
        // Float64 SPIR-V is valid only on a device with shaderFloat64 enabled.
        if ((Kernel(k) == Kernel::kIngestF64 || Kernel(k) == Kernel::kProbeLevels) && !m_ctx.shaderFloat64())
            continue;
        kernels.push_back(Kernel(k));
    }
    return kernels;
}

// The driver makes each pipeline on its own (compiled, or found in the
// cache, which Vulkan synchronizes): they are made on up to `threads` host
// threads at once, the ray-tracing pipeline (the largest) taken first. The
// first failure is thrown once every thread has stopped.
void Pipelines::createPipelines(VkPipelineCache cache, int threads) {
    const std::vector<Kernel> kernels = startupKernels();
    const size_t items = kernels.size() + (m_rayQuery ? 0 : 1);
    const size_t hardware = std::max(1u, std::thread::hardware_concurrency());
    const size_t workers = std::min({items, threads > 0 ? size_t(threads) : hardware, kMaxCreateThreads});
    std::atomic<size_t> next{0};
    std::vector<std::exception_ptr> failures(workers);
    const auto work = [&](size_t worker) {
        try {
            for (size_t item = next++; item < items; item = next++) {
                if (!m_rayQuery && item == 0) {
                    createRtPipeline(cache);
                    continue;
                }
                const Kernel k = kernels[item - (m_rayQuery ? 0 : 1)];
                m_compute[size_t(k)] = createComputePipeline(
                    m_ctx, kComputeSpirv[size_t(k)].code, m_layout.get(), cache,
                    VK_PIPELINE_CREATE_DISPATCH_BASE_BIT, kComputeSpirv[size_t(k)].name);
            }
        } catch (...) {
            failures[worker] = std::current_exception();
            next = items;  // the others stop after their current pipeline
        }
    };
    std::vector<std::thread> helpers;
    try {
        for (size_t w = 1; w < workers; ++w) helpers.emplace_back(work, w);
    } catch (const std::system_error&) {  // no thread to be had: fewer helpers
    }
    work(0);
    for (std::thread& t : helpers) t.join();
    for (const std::exception_ptr& f : failures)
        if (f) std::rethrow_exception(f);
}

void Pipelines::createRtPipeline(VkPipelineCache cache) {
    m_rtPipeline = createRtPipelineOf(cache, k_spv_search_rgen, k_spv_search_rmiss, k_spv_search_rint,
                                      "search_rt_pipeline");
}

UniquePipeline Pipelines::createRtPipelineOf(VkPipelineCache cache, std::span<const uint32_t> rgen,
                                             std::span<const uint32_t> rmiss, std::span<const uint32_t> rint,
                                             const char* name) {
    const VkDevice d = m_ctx.device();
    const UniqueShaderModule mods[3] = {createShaderModule(d, rgen), createShaderModule(d, rmiss),
                                        createShaderModule(d, rint)};
    const VkShaderStageFlagBits kinds[3] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                            VK_SHADER_STAGE_INTERSECTION_BIT_KHR};
    VkPipelineShaderStageCreateInfo st[3]{};
    VkRayTracingShaderGroupCreateInfoKHR g[3]{};
    for (int i = 0; i < 3; ++i) {
        st[i] = gpu::vkStruct<VkPipelineShaderStageCreateInfo>(
            VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
        st[i].stage = kinds[i];
        st[i].module = mods[i].get();
        st[i].pName = "main";
        g[i] = gpu::vkStruct<VkRayTracingShaderGroupCreateInfoKHR>(
            VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR);
        g[i].generalShader = g[i].closestHitShader = g[i].anyHitShader = g[i].intersectionShader =
            VK_SHADER_UNUSED_KHR;
    }
    g[0].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    g[0].generalShader = 0;
    g[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    g[1].generalShader = 1;
    g[2].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
    g[2].intersectionShader = 2;
    VkRayTracingPipelineCreateInfoKHR rci =
        vkStruct<VkRayTracingPipelineCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR);
    rci.stageCount = 3;
    rci.pStages = st;
    rci.groupCount = 3;
    rci.pGroups = g;
    rci.maxPipelineRayRecursionDepth = 1;
    rci.layout = m_layout.get();
    VkPipeline pipeline;
    RTHDIST_VK_CHECK(m_ctx.rt().createRtPipelines(d, VK_NULL_HANDLE, cache, 1, &rci, nullptr, &pipeline));
    m_ctx.setDebugName(VK_OBJECT_TYPE_PIPELINE, uint64_t(pipeline), name);
    return UniquePipeline(pipeline, d);
}

// Shader binding table: raygen | miss | hit, each region aligned to the base
// alignment; the buffer's address is rounded up, so over-allocate.
void Pipelines::createShaderBindingTable() {
    createShaderBindingTableOf(m_rtPipeline.get(), m_sbt, m_raygen, m_miss, m_hit);
}

void Pipelines::createShaderBindingTableOf(VkPipeline pipeline, Buffer& sbt,
                                           VkStridedDeviceAddressRegionKHR& raygen,
                                           VkStridedDeviceAddressRegionKHR& miss,
                                           VkStridedDeviceAddressRegionKHR& hit) {
    const auto& props = m_ctx.rtProps();
    const uint32_t handleSize = props.shaderGroupHandleSize;
    const VkDeviceSize stride = alignUp(handleSize, props.shaderGroupHandleAlignment);
    const VkDeviceSize base = props.shaderGroupBaseAlignment;
    const VkDeviceSize region = alignUp(stride, base);
    std::vector<uint8_t> handles(3 * handleSize);
    RTHDIST_VK_CHECK(
        m_ctx.rt().getGroupHandles(m_ctx.device(), pipeline, 0, 3, handles.size(), handles.data()));
    sbt = Buffer(m_ctx, 3 * region + base,
                 VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                 MemoryKind::kHost);
    const VkDeviceAddress start = alignUp(sbt.address(), base);
    auto* bytes = static_cast<uint8_t*>(sbt.mapped()) + (start - sbt.address());
    for (int i = 0; i < 3; ++i) std::memcpy(bytes + i * region, handles.data() + i * handleSize, handleSize);
    raygen = {start, stride, stride};
    miss = {start + region, stride, stride};
    hit = {start + 2 * region, stride, stride};
}

void Pipelines::bindTlas(VkAccelerationStructureKHR tlas) {
    VkWriteDescriptorSetAccelerationStructureKHR as = vkStruct<VkWriteDescriptorSetAccelerationStructureKHR>(
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR);
    as.accelerationStructureCount = 1;
    as.pAccelerationStructures = &tlas;
    VkWriteDescriptorSet w = vkStruct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &as);
    w.dstSet = m_set;
    w.dstBinding = 0;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    vkUpdateDescriptorSets(m_ctx.device(), 1, &w, 0, nullptr);
}

void Pipelines::cmdBindCompute(VkCommandBuffer cmd, Kernel kernel, const void* push,
                               uint32_t pushSize) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_compute[size_t(kernel)].get());
    if (kernel == Kernel::kSearchRayQuery || kernel == Kernel::kSurfaceSearchRayQuery)
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.get(), 0, 1, &m_set, 0,
                                nullptr);
    vkCmdPushConstants(cmd, m_layout.get(), m_stages, 0, pushSize, push);
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

void Pipelines::cmdBindRt(VkCommandBuffer cmd, const void* push, uint32_t pushSize) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, m_rtPipeline.get());
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, m_layout.get(), 0, 1, &m_set, 0,
                            nullptr);
    vkCmdPushConstants(cmd, m_layout.get(), m_stages, 0, pushSize, push);
}

void Pipelines::cmdTraceRays(VkCommandBuffer cmd, const void* push, uint32_t pushSize, uint32_t width) const {
    if (width == 0) return;
    cmdBindRt(cmd, push, pushSize);
    m_ctx.rt().cmdTraceRays(cmd, &m_raygen, &m_miss, &m_hit, &m_callable, width, 1, 1);
}

bool Pipelines::tracesIndirect() const { return m_ctx.rt().cmdTraceRaysIndirect != nullptr; }

void Pipelines::cmdTraceRaysIndirect(VkCommandBuffer cmd, const void* push, uint32_t pushSize,
                                     VkDeviceAddress args) const {
    cmdBindRt(cmd, push, pushSize);
    m_ctx.rt().cmdTraceRaysIndirect(cmd, &m_raygen, &m_miss, &m_hit, &m_callable, args);
}

void Pipelines::prepareSurfaceSearch(VkPipelineCache cache) {
    const auto tail = size_t(Kernel::kSurfaceTail);
    if (!m_compute[tail])
        m_compute[tail] =
            createComputePipeline(m_ctx, kComputeSpirv[tail].code, m_layout.get(), cache,
                                  VK_PIPELINE_CREATE_DISPATCH_BASE_BIT, kComputeSpirv[tail].name);
    const auto k = size_t(Kernel::kSurfaceSearchRayQuery);
    if (m_rayQuery && !m_compute[k]) {
        m_compute[k] = createComputePipeline(m_ctx, kComputeSpirv[k].code, m_layout.get(), cache,
                                             VK_PIPELINE_CREATE_DISPATCH_BASE_BIT, kComputeSpirv[k].name);
    } else if (!m_rayQuery && !m_surfaceRt) {
        m_surfaceRt = createRtPipelineOf(cache, k_spv_surface_search_rgen, k_spv_search_rmiss,
                                         k_spv_surface_search_rint, "surface_search_rt_pipeline");
        createShaderBindingTableOf(m_surfaceRt.get(), m_surfaceSbt, m_surfaceRaygen, m_surfaceMiss,
                                   m_surfaceHit);
    }
}

void Pipelines::cmdTraceSurfaceRays(VkCommandBuffer cmd, const void* push, uint32_t pushSize,
                                    uint32_t width) const {
    if (width == 0) return;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, m_surfaceRt.get());
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, m_layout.get(), 0, 1, &m_set, 0,
                            nullptr);
    vkCmdPushConstants(cmd, m_layout.get(), m_stages, 0, pushSize, push);
    m_ctx.rt().cmdTraceRays(cmd, &m_surfaceRaygen, &m_surfaceMiss, &m_surfaceHit, &m_callable, width, 1, 1);
}

}  // namespace rthdist::gpu
