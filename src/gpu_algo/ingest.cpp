#include "gpu_algo/index_build.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/parallel.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {
namespace {

// The float of orderedBits (common.glsl): the host's read of a reduced bound.
float fromOrderedBits(uint32_t u) {
    return std::bit_cast<float>((u & 0x80000000u) != 0u ? u & 0x7fffffffu : ~u);
}

}  // namespace

void IndexBuild::stageSource(PointIndex& ix, std::span<const glm::vec3> pts) {
    ix.n = uint32_t(pts.size());
    const size_t bytes = size_t(ix.n) * 12;
    if (std::optional<gpu::HostImport> im = gpu::HostImport::create(m_ws.ctx, pts.data(), bytes)) {
        m_ws.imports.push_back(std::move(*im));
        ix.source = &m_ws.imports.back();
        return;
    }
    ix.source = nullptr;
    Buffer& source = m_ws.grow(ix.scratch->source, bytes, ix.name + ".source", MemoryKind::kHost);
    auto* dst = static_cast<char*>(source.mapped());
    const char* src = reinterpret_cast<const char*>(pts.data());
    // Chunks of 2^14 points (192 KiB): the Dragon's 437,645 points on every
    // thread of a 16-core host (2^16 gave them 7, the res2 set's 100,250 two).
    constexpr size_t kCopyChunk = size_t(1) << 14;
    core::parallelChunks(ix.n, kCopyChunk, m_ws.threads, [&](size_t begin, size_t end, int) {
        std::memcpy(dst + begin * 12, src + begin * 12, (end - begin) * 12);
    });
}

void IndexBuild::cmdUploadSource(VkCommandBuffer cmd, const PointIndex& ix) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "upload");
    const VkDeviceSize bytes = VkDeviceSize(ix.n) * 12;
    const VkBuffer from =
        ix.source ? ix.source->handle()
                  : m_ws.grow(ix.scratch->source, bytes, ix.name + ".source", MemoryKind::kHost).handle();
    const VkBufferCopy region{ix.source ? ix.source->offset() : 0, 0, bytes};
    vkCmdCopyBuffer(cmd, from, m_ws.grow(ix.scratch->raw, bytes, ix.name + ".raw").handle(), 1, &region);
}

void IndexBuild::cmdIngest(VkCommandBuffer cmd, const PointIndex& ix, const CounterBlock& blk,
                           VkDeviceAddress source, uint32_t stride) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "ingest");
    auto& summary = blk.ingest();
    for (int k = 0; k < 3; ++k) {
        summary.lo[k] = 0xffffffffu;
        summary.hi[k] = 0u;
    }
    summary.firstBad = 0xffffffffu;
    if (source == 0) source = m_ws.grow(ix.scratch->raw, VkDeviceSize(ix.n) * 12, ix.name + ".raw").address();
    sh::IngestPush ip{source,
                      m_ws.grow(ix.scratch->points, VkDeviceSize(ix.n) * 16, ix.name + ".points").address(),
                      blk.addr(RTHDIST_CTR_INGEST), ix.n, stride};
    m_ws.dispatch(cmd, Kernel::kIngest, ip, ix.n);
}

void IndexBuild::finishIngest(PointIndex& ix, const CounterBlock& blk) {
    const auto& summary = blk.ingest();
    if (summary.firstBad != 0xffffffffu)
        throw InputRejected{Error{ErrorCode::kInvalidArgument, "point set " + ix.name + ": point " +
                                                                   std::to_string(summary.firstBad) +
                                                                   " has a NaN or infinite coordinate"}};
    for (int k = 0; k < 3; ++k) {
        ix.bounds.lo[k] = double(fromOrderedBits(summary.lo[k]));
        ix.bounds.hi[k] = double(fromOrderedBits(summary.hi[k]));
    }
}

}  // namespace rthdist::gpu_algo
