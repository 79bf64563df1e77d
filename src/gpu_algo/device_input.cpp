#include "gpu_algo/device_input.hpp"

#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "core/index_space.hpp"
#include "gpu/barriers.hpp"

namespace rthdist::gpu_algo {

static_assert(RTHDIST_CTR_INGEST + sizeof(sh::IngestSummary) <= RTHDIST_CTR_INGEST64 &&
              RTHDIST_CTR_INGEST64 % 8 == 0 &&
              RTHDIST_CTR_INGEST64 + sizeof(sh::IngestSummary64) <= kCounterBlockBytes);

namespace {

// The double of orderedBits64 (ingest_f64.comp).
double fromOrderedBits64(uint64_t u) {
    constexpr uint64_t kSign = uint64_t(1) << 63;
    return std::bit_cast<double>((u & kSign) != 0 ? u & ~kSign : ~u);
}

sh::IngestSummary64& summary64(const CounterBlock& blk) {
    return *reinterpret_cast<sh::IngestSummary64*>(blk.host + RTHDIST_CTR_INGEST64);
}

void requireFloat64(const gpu::Context& ctx) {
    if (!ctx.shaderFloat64())
        throw InputRejected{
            Error{ErrorCode::kNoDevice,
                  "double device views (or a float view beside one) are read in double on the "
                  "device: enable the feature shaderFloat64 on the VkDevice "
                  "(VulkanDeviceSetup::features2) and set VulkanDevice::shaderFloat64"}};
}

}  // namespace

void DeviceIngest::cmdEmbedderWritesBarrier(VkCommandBuffer cmd) {
    gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT);
}

std::array<core::SetSummary, 2> DeviceIngest::summarize(std::span<const DeviceInput> views,
                                                        std::span<const std::string> names) {
    requireFloat64(m_ws.ctx);
    const auto t0 = Clock::now();
    VkCommandBuffer cmd = m_ws.ctx.begin();
    cmdEmbedderWritesBarrier(cmd);
    for (size_t k = 0; k < views.size(); ++k) {
        const gpu::ScopedLabel label(m_ws.ctx, cmd, "device input box");
        sh::IngestSummary64& s = summary64(m_ws.blocks[k]);
        for (int a = 0; a < 3; ++a) {
            s.lo[a] = ~uint64_t(0);
            s.hi[a] = 0;
        }
        s.firstBad = 0xffffffffu;
        s.notFloat = 0;
        const sh::IngestDevicePush p{views[k].address,
                                     0,
                                     m_ws.blocks[k].addr(RTHDIST_CTR_INGEST64),
                                     {0, 0, 0},
                                     views[k].n,
                                     views[k].stride,
                                     views[k].scalar == Scalar::kFloat64 ? 1u : 0u,
                                     0u};
        m_ws.dispatch(cmd, Kernel::kIngestF64, p, views[k].n);
    }
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
    m_ws.timings->index += msSince(t0);
    std::array<core::SetSummary, 2> out{};
    for (size_t k = 0; k < views.size(); ++k) {
        const sh::IngestSummary64& s = summary64(m_ws.blocks[k]);
        if (s.firstBad != 0xffffffffu)
            throw InputRejected{Error{ErrorCode::kInvalidArgument, "point set " + names[k] + ": point " +
                                                                       std::to_string(s.firstBad) +
                                                                       " has a NaN or infinite coordinate"}};
        for (int a = 0; a < 3; ++a) {
            out[k].box.lo[a] = fromOrderedBits64(s.lo[a]);
            out[k].box.hi[a] = fromOrderedBits64(s.hi[a]);
        }
        out[k].floatExact = s.notFloat == 0;
    }
    return out;
}

void DeviceIngest::cmdConvert(VkCommandBuffer cmd, PointIndex& ix, const DeviceInput& view,
                              const CounterBlock& blk, const glm::dvec3& origin) {
    if (view.scalar == Scalar::kFloat32 && origin == glm::dvec3(0.0)) {
        m_index.cmdIngest(cmd, ix, blk, view.address, view.stride);  // as packed host arrays
        return;
    }
    requireFloat64(m_ws.ctx);
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "device input ingest");
    sh::IngestSummary& s = blk.ingest();
    for (int a = 0; a < 3; ++a) {
        s.lo[a] = 0xffffffffu;
        s.hi[a] = 0u;
    }
    s.firstBad = 0xffffffffu;  // found by the summary pass already
    const Buffer& points = m_ws.grow(ix.scratch->points, VkDeviceSize(ix.n) * 16, ix.name + ".points");
    const sh::IngestDevicePush p{view.address,
                                 points.address(),
                                 blk.addr(RTHDIST_CTR_INGEST),
                                 {std::bit_cast<uint64_t>(origin.x), std::bit_cast<uint64_t>(origin.y),
                                  std::bit_cast<uint64_t>(origin.z)},
                                 ix.n,
                                 view.stride,
                                 view.scalar == Scalar::kFloat64 ? 1u : 0u,
                                 1u};
    m_ws.dispatch(cmd, Kernel::kIngestF64, p, ix.n);
}

size_t DeviceIngest::cmdGatherSample(VkCommandBuffer cmd, PointIndex& ix, Buffer& sample) {
    const size_t stride = core::sampleStride(ix.n);
    const size_t count = (size_t(ix.n) + stride - 1) / stride;
    m_ws.grow(sample, VkDeviceSize(count) * 12, ix.name + ".sample", MemoryKind::kReadback);
    const Buffer& points = m_ws.grow(ix.scratch->points, VkDeviceSize(ix.n) * 16, ix.name + ".points");
    const sh::SampleGatherPush p{points.address(), sample.address(), uint32_t(count), uint32_t(stride)};
    m_ws.dispatch(cmd, Kernel::kSampleGather, p, count);
    return count;
}

void DeviceIngest::ingest(std::span<PointIndex* const> sets, std::span<const DeviceInput> views,
                          const glm::dvec3& origin, int bits, bool first) {
    const auto t0 = Clock::now();
    VkCommandBuffer cmd = m_ws.ctx.begin();
    if (first) cmdEmbedderWritesBarrier(cmd);
    for (size_t k = 0; k < sets.size(); ++k) {
        sets[k]->n = views[k].n;
        sets[k]->source = nullptr;
        cmdConvert(cmd, *sets[k], views[k], m_ws.blocks[k], origin);
    }
    cmdBitCountSamples(cmd, sets, bits);
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
    for (size_t k = 0; k < sets.size(); ++k) m_index.finishIngest(*sets[k], m_ws.blocks[k]);
    chooseGrids(sets, bits);
    m_ws.timings->index += msSince(t0);
}

void DeviceIngest::cmdBitCountSamples(VkCommandBuffer cmd, std::span<PointIndex* const> sets, int bits) {
    if (bits > 0 || probesOnDevice()) return;
    m_ws.barrier(cmd);
    for (size_t k = 0; k < sets.size(); ++k) m_sampled[k] = cmdGatherSample(cmd, *sets[k], m_samples[k]);
}

void DeviceIngest::chooseGrids(std::span<PointIndex* const> sets, int bits) {
    if (bits <= 0 && probesOnDevice()) return chooseGridsByProbe(sets);
    if (bits <= 0) return chooseGridsFromSamples(sets);
    for (PointIndex* ix : sets) ix->grid = core::makeGrid(ix->bounds, bits);
}

void DeviceIngest::chooseGridsByProbe(std::span<PointIndex* const> sets) {
    constexpr VkDeviceSize kTableBytes = (VkDeviceSize(RTHDIST_PROBE_LEVELS) << RTHDIST_PROBE_SLOT_BITS) * 4;
    static_assert(RTHDIST_PROBE_LEVELS == core::kMaxBits && RTHDIST_PROBE_SLOT_BITS == 17);
    std::array<core::BitProbe, 2> probes;
    std::array<bool, 2> probed{};
    std::array<uint32_t, 2> sampled{};
    for (size_t k = 0; k < sets.size(); ++k)
        probed[k] = core::bitProbeOf(sets[k]->bounds, sets[k]->n, probes[k]);
    if (probed[0] || probed[1]) {
        VkCommandBuffer cmd = m_ws.ctx.begin();
        for (size_t k = 0; k < sets.size(); ++k) {
            if (!probed[k]) continue;
            Buffer& tables = m_ws.grow(m_probeTables[k], kTableBytes, sets[k]->name + ".probe");
            vkCmdFillBuffer(cmd, tables.handle(), 0, kTableBytes, 0u);
            std::memset(m_ws.blocks[k].host + RTHDIST_CTR_PROBE, 0, (RTHDIST_PROBE_LEVELS + 1) * 4);
        }
        m_ws.barrier(cmd);
        for (size_t k = 0; k < sets.size(); ++k) {
            if (!probed[k]) continue;
            const PointIndex& ix = *sets[k];
            const size_t stride = core::sampleStride(ix.n);
            sampled[k] = uint32_t((size_t(ix.n) + stride - 1) / stride);
            const core::BitProbe& p = probes[k];
            const sh::ProbeLevelsPush push{
                m_ws.grow(ix.scratch->points, VkDeviceSize(ix.n) * 16, ix.name + ".points").address(),
                m_probeTables[k].address(),
                m_ws.blocks[k].addr(RTHDIST_CTR_PROBE),
                {std::bit_cast<uint64_t>(p.origin.x), std::bit_cast<uint64_t>(p.origin.y),
                 std::bit_cast<uint64_t>(p.origin.z)},
                std::bit_cast<uint64_t>(p.perLength),
                sampled[k],
                uint32_t(stride)};
            m_ws.dispatch(cmd, Kernel::kProbeLevels, push, sampled[k]);
        }
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
    }
    for (size_t k = 0; k < sets.size(); ++k) {
        PointIndex& ix = *sets[k];
        int chosen = core::kMinBits;
        if (probed[k]) {
            const auto* counts = reinterpret_cast<const uint32_t*>(m_ws.blocks[k].host + RTHDIST_CTR_PROBE);
            core::LevelCounts distinct{};
            for (int level = 1; level <= core::kMaxBits; ++level) distinct[size_t(level)] = counts[level];
            chosen = core::chooseBitsFromCounts(distinct, sampled[k], ix.n);
        }
        ix.grid = core::makeGrid(ix.bounds, clampedBits(chosen, ix.n));
    }
}

void DeviceIngest::chooseGridsFromSamples(std::span<PointIndex* const> sets) {
    for (size_t k = 0; k < sets.size(); ++k) {
        PointIndex& ix = *sets[k];
        std::vector<glm::vec3> sample(m_sampled[k]);
        std::memcpy(sample.data(), m_samples[k].mapped(), m_sampled[k] * 12);
        ix.grid =
            core::makeGrid(ix.bounds, clampedBits(core::chooseBitsFromSample(sample, ix.n, ix.bounds), ix.n));
    }
}

}  // namespace rthdist::gpu_algo
