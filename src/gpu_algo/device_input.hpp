// Device input (include/rthdist/vulkan_interop.hpp): point sets that lie in
// the embedder's VkBuffers, ingested into the index build's vec4 records on
// the device. Float views with origin 0 take ingest.comp, as packed host
// arrays do; double views (and float views that meet one) take the two
// passes of ingest_f64.comp: the box in double, then float(p - origin). The
// host reads back only the summaries and the bit count's sample.
#pragma once

#include <vulkan/vulkan.h>

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/input_frame.hpp"
#include "gpu_algo/index_build.hpp"
#include "gpu_algo/point_index.hpp"
#include "gpu_algo/set_points.hpp"
#include "gpu_algo/workspace.hpp"
#include "rthdist/point_view.hpp"

namespace rthdist::gpu_algo {

class DeviceIngest {
public:
    DeviceIngest(Workspace& workspace, IndexBuild& index) : m_ws(workspace), m_index(index) {}

    // Mode 0 of ingest_f64.comp over each view, in one submission: its box in
    // double and whether it is float-exact (what summarizeSet finds on the
    // host), or InputRejected naming the set (PointIndex::name of `names`)
    // and its first non-finite point. At most two views.
    [[nodiscard]] std::array<core::SetSummary, 2> summarize(std::span<const DeviceInput> views,
                                                            std::span<const std::string> names);

    // The records of each view into its set's points (ix.scratch->points),
    // shifted by `origin` (ingest_f64.comp mode 1 unless the view is float
    // and the origin 0: ingest.comp), in one submission; then each set's
    // bounds (of its float records) and grid, the bit count from a sample
    // of its records read back (core::chooseBitsFromSample) unless `bits` > 0.
    // Sets ix.n. The caller indexes them after (IndexBuild::buildIndexes,
    // ingested). `first`: this is the call's first submission (it then opens
    // with the barrier from the embedder's writes).
    void ingest(std::span<PointIndex* const> sets, std::span<const DeviceInput> views,
                const glm::dvec3& origin, int bits, bool first);

    // Records into the ingest's submission what the automatic bit count
    // (bits <= 0) needs from it: on a device without shaderFloat64, after a
    // barrier from the ingest, each set's sample (cmdGatherSample, kept for
    // chooseGrids); nothing otherwise.
    void cmdBitCountSamples(VkCommandBuffer cmd, std::span<PointIndex* const> sets, int bits);
    // Once that submission is done and the bounds are read: each set's grid
    // over its bounds with `bits`, or (bits <= 0) the automatic bit count,
    // the count chooseBits finds on the same points: where the device has
    // shaderFloat64 its probe is counted on the device in one more
    // submission (probe_levels.comp) and the host applies the rule to the
    // counts of each level (core::chooseBitsFromCounts); else the host counts
    // the gathered sample (core::chooseBitsFromSample).
    void chooseGrids(std::span<PointIndex* const> sets, int bits);

    // The first command of a call on device input: every earlier memory write
    // on the queue -> the shader and transfer reads of the call (the
    // synchronisation contract of vulkan_interop.hpp).
    static void cmdEmbedderWritesBarrier(VkCommandBuffer cmd);

private:
    void cmdConvert(VkCommandBuffer cmd, PointIndex& ix, const DeviceInput& view, const CounterBlock& blk,
                    const glm::dvec3& origin);
    // Gathers every sampleStride-th record of an ingested set (about 32k)
    // into `sample` (host-visible, 12 bytes per record, grown and kept), for
    // the bit count: one dispatch of sample_gather.comp. Returns the count.
    size_t cmdGatherSample(VkCommandBuffer cmd, PointIndex& ix, Buffer& sample);
    // The automatic bit count runs on the device (probe_levels.comp needs shaderFloat64).
    [[nodiscard]] bool probesOnDevice() const { return m_ws.ctx.shaderFloat64(); }
    // chooseGrids' two automatic forms: the probe on the device, the gathered samples on the host.
    void chooseGridsByProbe(std::span<PointIndex* const> sets);
    void chooseGridsFromSamples(std::span<PointIndex* const> sets);

    Workspace& m_ws;
    IndexBuild& m_index;
    std::array<Buffer, 2> m_samples;      // the sample of each set of a call (host-visible)
    std::array<size_t, 2> m_sampled{};    // ... and its count
    std::array<Buffer, 2> m_probeTables;  // each set's hash tables of probe cells (device)
};

}  // namespace rthdist::gpu_algo
