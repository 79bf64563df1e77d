#include "gpu_algo/workspace.hpp"

#include <algorithm>

namespace rthdist::gpu_algo {

void throwIfCancelled(const CallOptions& options) {
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) throw CallCancelled{};
}

void reportProgress(const CallOptions& options, const char* stage, double fraction) {
    if (options.progress) options.progress(stage, std::clamp(fraction, 0.0, 1.0));
    throwIfCancelled(options);
}

Workspace::Workspace(gpu::Context& c, const std::string& cacheDir)
    : ctx(c),
      pipelineCache(c.device(), c.physicalDevice(), cacheDir),
      pipelines(c, c.backend() == Backend::kRayQuery, pipelineCache.handle()),
      accel(c),
      rayQuery(c.backend() == Backend::kRayQuery) {
    pipelineCache.save();
    hostSmall = Buffer(ctx, kCounterBlockBytes * blocks.size(), gpu::kStorageUsage, MemoryKind::kHost);
    for (size_t k = 0; k < blocks.size(); ++k)
        blocks[k] = CounterBlock{static_cast<char*>(hostSmall.mapped()) + k * kCounterBlockBytes,
                                 hostSmall.address() + k * kCounterBlockBytes, k * kCounterBlockBytes};
}

Buffer& Workspace::buf(const std::string& name, VkDeviceSize bytes, MemoryKind kind) {
    return bufIn(pool, name, bytes, kind, true);
}

Buffer& Workspace::setBuf(PointIndex& ix, const std::string& suffix, VkDeviceSize bytes) {
    return bufIn(*ix.store, ix.name + suffix, bytes, MemoryKind::kDevice, !ix.owned);
}

Buffer& Workspace::bufIn(std::map<std::string, Buffer>& store, const std::string& name, VkDeviceSize bytes,
                         MemoryKind kind, bool slack) {
    Buffer& b = store[name];
    if (!b || b.size() < bytes) {
        b.reset();
        const VkDeviceSize room =
            !slack ? bytes
                   : std::min<VkDeviceSize>(bytes + std::min(bytes / 4, kMaxSlack),
                                            std::max<VkDeviceSize>(bytes, ctx.limits().maxBufferBytes));
        b = Buffer(ctx, std::max<VkDeviceSize>(room, 256),
                   gpu::kStorageUsage | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                   kind);
        ctx.setDebugName(VK_OBJECT_TYPE_BUFFER, uint64_t(b.handle()), name.c_str());
    }
    return b;
}

void Workspace::cmdScan(VkCommandBuffer cmd, VkDeviceAddress data, uint32_t n, const std::string& tag,
                        size_t level) {
    const uint32_t blocks = gpu::groupsFor(n, RTHDIST_SCAN_BLOCK);
    const VkDeviceAddress sums = buf(tag + std::to_string(level), VkDeviceSize(blocks) * 4).address();
    sh::ScanPush p{data, sums, n};
    pipelines.cmdDispatch(cmd, Kernel::kScanBlock, &p, sizeof(p), blocks);
    if (blocks > 1) {
        barrier(cmd);
        cmdScan(cmd, sums, blocks, tag, level + 1);
        barrier(cmd);
        pipelines.cmdDispatch(cmd, Kernel::kScanAdd, &p, sizeof(p), blocks);
    }
}

}  // namespace rthdist::gpu_algo
