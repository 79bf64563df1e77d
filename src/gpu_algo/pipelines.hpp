// The compute pipelines of the three stages and, for devices without ray
// queries, the ray-tracing pipeline with its shader binding table. All share
// one layout: push constants (every stage) and set 0 = the TLAS.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "gpu/buffer.hpp"
#include "gpu/unique_handle.hpp"

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
    kIngest,         // the caller's points into vec4 records, bounds, validation (ingest.comp)
    kRefineArgs,     // refine.comp's indirect dispatch size (refine_args.comp)
    kIngestF64,      // device input views read in double (ingest_f64.comp): only with shaderFloat64
    kSampleGather,   // the bit count's sample of a device-input set (sample_gather.comp)
    kBatchNearest,   // computeBatch's small pairs: exact scans (batch_nearest.comp)
    kBatchWitness,   // and their witnesses (batch_witness.comp)
    kSearchAdvance,  // between the radii of one submission (search_advance.comp)
    kProbeLevels,    // the bit count's probe (probe_levels.comp): only with shaderFloat64
    kTailScan,       // the candidate search's far tail: whole levels scanned (tail_scan.comp)
    kCertScan,       // the certificate's brute force over a direction's targets (cert_scan.comp)
    kCertWitness,    // and of the witness alone, with the final self-check (cert_witness.comp)
    kSweepTargets,   // the search's sweep: few open queries against every target (sweep_targets.comp)
    kLeafFirst,      // a split index's first leaf per grid cell (leaf_first.comp)
    kCellsTotal,     // the number of runs once their heads are scanned (cells_total.comp)
    kLeafGroups,     // a split index's leaf groups of crowded cells (leaf_groups.comp)
    // The point-to-surface search, ray-query path (surface_search_rq.comp):
    // created by prepareSurfaceSearch only.
    kSurfaceSearchRayQuery,
    // The point-to-surface search's tail, on both paths (surface_tail.comp):
    // created by prepareSurfaceSearch only.
    kSurfaceTail,
    kCount
};

class Pipelines {
public:
    // cache: a VkPipelineCache (gpu/pipeline_cache.hpp) or VK_NULL_HANDLE.
    // threads: host threads that create the pipelines at once (0: one per
    // hardware thread; at most kMaxCreateThreads).
    Pipelines(Context& ctx, bool rayQuery, VkPipelineCache cache, int threads = 0);
    static constexpr size_t kMaxCreateThreads = 16;
    ~Pipelines() = default;
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
    // The same with (width, height, depth) read by the device at `args` (a
    // VkTraceRaysIndirectCommandKHR): only where tracesIndirect().
    void cmdTraceRaysIndirect(VkCommandBuffer cmd, const void* push, uint32_t pushSize,
                              VkDeviceAddress args) const;
    [[nodiscard]] bool tracesIndirect() const;
    // How long the constructor took to create the pipelines (with the cache:
    // found there, else compiled).
    [[nodiscard]] double createMs() const { return m_createMs; }

    // The point-to-surface search's pipelines (design.md §11), created on
    // first use so that point calls never compile them: the ray-query kernel
    // (Kernel::kSurfaceSearchRayQuery), or the ray-tracing pipeline of
    // surface_search.rgen/rint and its shader binding table; and the tail's
    // kernel (Kernel::kSurfaceTail) on both.
    void prepareSurfaceSearch(VkPipelineCache cache);
    // One surface-search ray-generation invocation per index in [0, width).
    void cmdTraceSurfaceRays(VkCommandBuffer cmd, const void* push, uint32_t pushSize, uint32_t width) const;

    [[nodiscard]] VkPipelineStageFlags shaderStages() const { return m_shaderStages; }

private:
    // Construction steps: set 0 (the TLAS) and the shared layout; the compute
    // kernels; the ray-tracing pipeline and its shader binding table.
    void createLayout();
    void cmdBindRt(VkCommandBuffer cmd, const void* push, uint32_t pushSize) const;
    // The compute kernels made at construction (not the surface search's).
    [[nodiscard]] std::vector<Kernel> startupKernels() const;
    void createPipelines(VkPipelineCache cache, int threads);
    void createRtPipeline(VkPipelineCache cache);
    void createShaderBindingTable();
    // A ray-tracing pipeline of raygen | miss | procedural hit group, and
    // its shader binding table (regions: raygen, miss, hit).
    UniquePipeline createRtPipelineOf(VkPipelineCache cache, std::span<const uint32_t> rgen,
                                      std::span<const uint32_t> rmiss, std::span<const uint32_t> rint,
                                      const char* name);
    void createShaderBindingTableOf(VkPipeline pipeline, Buffer& sbt, VkStridedDeviceAddressRegionKHR& raygen,
                                    VkStridedDeviceAddressRegionKHR& miss,
                                    VkStridedDeviceAddressRegionKHR& hit);
    // Binds a compute kernel (and the TLAS for ray queries) and its push constants.
    void cmdBindCompute(VkCommandBuffer cmd, Kernel kernel, const void* push, uint32_t pushSize) const;

    Context& m_ctx;
    bool m_rayQuery;
    UniqueDescriptorSetLayout m_setLayout;
    UniquePipelineLayout m_layout;
    UniqueDescriptorPool m_pool;
    VkDescriptorSet m_set = VK_NULL_HANDLE;  // freed with m_pool
    std::array<UniquePipeline, size_t(Kernel::kCount)> m_compute;
    UniquePipeline m_rtPipeline;
    Buffer m_sbt;
    VkStridedDeviceAddressRegionKHR m_raygen{}, m_miss{}, m_hit{}, m_callable{};
    // The point-to-surface search's ray-tracing pipeline (prepareSurfaceSearch).
    UniquePipeline m_surfaceRt;
    Buffer m_surfaceSbt;
    VkStridedDeviceAddressRegionKHR m_surfaceRaygen{}, m_surfaceMiss{}, m_surfaceHit{};
    VkShaderStageFlags m_stages;  // that see set 0 and the push constants
    VkPipelineStageFlags m_shaderStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    double m_createMs = 0.0;
};

// Groups of 1-D dispatch for n items of RTHDIST_WG threads.
[[nodiscard]] uint32_t groupsFor(uint64_t n, uint32_t groupSize);

}  // namespace rthdist::gpu
