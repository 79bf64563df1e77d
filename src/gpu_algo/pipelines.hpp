// The compute pipelines of the three stages and, for devices without ray
// queries, the ray-tracing pipeline with its shader binding table. All share
// one layout: push constants (every stage) and set 0 = the TLAS.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>

#include "gpu/buffer.hpp"

namespace rthdist::gpu {

class Context;

enum class Kernel : uint32_t {
    kCellKeys,
    kScanBlock,
    kScanAdd,
    kScatter,
    kCellHeads,
    kCellBuild,
    kCull,
    kCompact,
    kGrowBoxes,
    kSearchRayQuery,  // only on the ray-query backend
    kRefine,
    kResolve,
    kCoarsen,
    kCheckIndex,    // self-check of an index (check_index.comp)
    kCheckQueries,  // self-check of a direction (check_queries.comp)
    kLeafSlots,     // leaf split of crowded cells (leaf_*.comp)
    kLeafKeys,
    kLeafScatter,
    kCellBounds,  // parallel tight boxes of large cells (cell_bounds*.comp)
    kCellBoundsFix,
    kIngest,      // the caller's points into vec4 records, bounds, validation (ingest.comp)
    kRefineArgs,  // refine.comp's indirect dispatch size (refine_args.comp)
    kCount
};

class Pipelines {
public:
    // cache: a VkPipelineCache (gpu/pipeline_cache.hpp) or VK_NULL_HANDLE.
    Pipelines(Context& ctx, bool rayQuery, VkPipelineCache cache);
    ~Pipelines();
    Pipelines(const Pipelines&) = delete;
    Pipelines& operator=(const Pipelines&) = delete;

    // Points set 0 binding 0 at this TLAS.
    void bindTlas(VkAccelerationStructureKHR tlas);

    void cmdDispatch(VkCommandBuffer cmd, Kernel kernel, const void* push, uint32_t pushSize,
                     uint32_t groups) const;
    // A dispatch whose group counts the device wrote at `args` (a
    // VkDispatchIndirectCommand; at most the device's group limits).
    void cmdDispatchIndirect(VkCommandBuffer cmd, Kernel kernel, const void* push, uint32_t pushSize,
                             VkBuffer args, VkDeviceSize offset) const;
    // Ray-tracing pipeline: one ray-generation invocation per index in [0, width).
    void cmdTraceRays(VkCommandBuffer cmd, const void* push, uint32_t pushSize, uint32_t width) const;

    [[nodiscard]] VkPipelineStageFlags shaderStages() const { return m_shaderStages; }

private:
    VkShaderModule createModule(const uint32_t* code, size_t bytes);
    // Binds a compute kernel (and the TLAS for ray queries) and its push constants.
    void cmdBindCompute(VkCommandBuffer cmd, Kernel kernel, const void* push, uint32_t pushSize) const;

    Context& m_ctx;
    bool m_rayQuery;
    VkDescriptorSetLayout m_setLayout = VK_NULL_HANDLE;
    VkPipelineLayout m_layout = VK_NULL_HANDLE;
    VkDescriptorPool m_pool = VK_NULL_HANDLE;
    VkDescriptorSet m_set = VK_NULL_HANDLE;
    std::array<VkPipeline, size_t(Kernel::kCount)> m_compute{};
    VkPipeline m_rtPipeline = VK_NULL_HANDLE;
    Buffer m_sbt;
    VkStridedDeviceAddressRegionKHR m_raygen{}, m_miss{}, m_hit{}, m_callable{};
    VkPipelineStageFlags m_shaderStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
};

// Groups of 1-D dispatch for n items of RTHDIST_WG threads.
[[nodiscard]] uint32_t groupsFor(uint64_t n, uint32_t groupSize);

}  // namespace rthdist::gpu
