#include "gpu_algo/workspace.hpp"

#include <algorithm>
#include <cstdio>

namespace rthdist::gpu_algo {

void throwIfCancelled(const CallOptions& options) {
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) throw CallCancelled{};
}

void reportProgress(const CallOptions& options, const char* stage, double fraction) {
    if (options.progress) options.progress(stage, std::clamp(fraction, 0.0, 1.0));
    throwIfCancelled(options);
}

Workspace::Workspace(gpu::Context& c, const std::string& cacheDir, int hostThreads, const Tuning& tuned)
    : ctx(c),
      tuning(tuned),
      pipelineCache(c.device(), c.physicalDevice(), cacheDir),
      pipelines(c, c.backend() == Backend::kRayQuery, pipelineCache.handle(), hostThreads),
      accel(c),
      rayQuery(c.backend() == Backend::kRayQuery),
      threads(hostThreads) {
    const auto saveStart = core::Clock::now();
    pipelineCache.save();
    if (ctx.tracingSubmits())
        std::fprintf(stderr,
                     "rthdist setup: pipeline cache %s, pipelines made in %.1f ms, cache saved in %.1f ms\n",
                     pipelineCache.loadStatus().c_str(), pipelines.createMs(), core::msSince(saveStart));
    hostSmall = Buffer(ctx, kCounterBlockBytes * blocks.size(), gpu::kStorageUsage, MemoryKind::kHost);
    for (size_t k = 0; k < blocks.size(); ++k)
        blocks[k] = CounterBlock{static_cast<char*>(hostSmall.mapped()) + k * kCounterBlockBytes,
                                 hostSmall.address() + k * kCounterBlockBytes, k * kCounterBlockBytes};
}

void Workspace::recycle(Buffer& b) {
    // A buffer smaller than any request that adopts stays in its slot for
    // the slot's next use: in `spare` no request could take it, and every
    // call of a small pair would add its builds' scratch there for good.
    if (b && b.size() >= adoptMinBytes) spare.push_back(std::move(b));  // the move leaves b empty
}

void Workspace::recycleBuild(BuildScratch& build) {
    for (Buffer* b : {&build.points, &build.keys, &build.flags, &build.boundsU}) recycle(*b);
}

void Workspace::recycleBuildScratch() {
    for (BuildScratch& s : scratch.builds) recycleBuild(s);
    for (LeafScratch& leaf : scratch.leaves)
        for (Buffer* b : {&leaf.slotKeys, &leaf.outSlotKeys, &leaf.flags, &leaf.slotDense, &leaf.boundsU})
            recycle(*b);
}

Buffer& Workspace::grow(Buffer& b, VkDeviceSize bytes, const std::string& name, MemoryKind kind, bool slack) {
    if (!b || b.size() < bytes) {
        b.reset();
        if (slack && bytes >= adoptMinBytes) {  // exact sizes (a prepared set's): its own
            auto best = spare.end();
            for (auto it = spare.begin(); it != spare.end(); ++it)
                if (it->kind() == kind && it->size() >= bytes && it->size() / 2 <= bytes &&
                    (best == spare.end() || it->size() < best->size()))
                    best = it;
            if (best != spare.end()) {
                b = std::move(*best);
                spare.erase(best);
                ++adopted;
                ctx.setDebugName(VK_OBJECT_TYPE_BUFFER, uint64_t(b.handle()), name.c_str());
                if (ctx.tracingSubmits())
                    std::fprintf(stderr, "rthdist buffer %s: %.1f MiB (%s) adopted, a spent one\n",
                                 name.c_str(), double(b.size()) / double(1 << 20),
                                 kind == MemoryKind::kDevice ? "device" : "host");
                return b;
            }
        }
        const auto t0 = Clock::now();
        const VkDeviceSize room =
            !slack ? bytes
                   : std::min<VkDeviceSize>(bytes + std::min(bytes / 4, kMaxSlack),
                                            std::max<VkDeviceSize>(bytes, ctx.limits().maxBufferBytes));
        b = Buffer(ctx, std::max<VkDeviceSize>(room, 256),
                   gpu::kStorageUsage | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                   kind);
        ctx.setDebugName(VK_OBJECT_TYPE_BUFFER, uint64_t(b.handle()), name.c_str());
        if (ctx.tracingSubmits())
            std::fprintf(stderr, "rthdist buffer %s: %.1f MiB (%s) in %.3f ms\n", name.c_str(),
                         double(b.size()) / double(1 << 20), kind == MemoryKind::kDevice ? "device" : "host",
                         msSince(t0));
    }
    return b;
}

void Workspace::cmdScan(VkCommandBuffer cmd, VkDeviceAddress data, uint32_t n, ScanScratch& sums,
                        const char* name, size_t level) {
    const uint32_t blocks = gpu::groupsFor(n, RTHDIST_SCAN_BLOCK);
    if (sums.size() <= level) sums.resize(level + 1);
    const VkDeviceAddress sumsAt =
        grow(sums[level], VkDeviceSize(blocks) * 4, std::string(name) + std::to_string(level)).address();
    sh::ScanPush p{data, sumsAt, n};
    pipelines.cmdDispatch(cmd, Kernel::kScanBlock, &p, sizeof(p), blocks);
    if (blocks > 1) {
        barrier(cmd);
        cmdScan(cmd, sumsAt, blocks, sums, name, level + 1);
        barrier(cmd);
        pipelines.cmdDispatch(cmd, Kernel::kScanAdd, &p, sizeof(p), blocks);
    }
}

}  // namespace rthdist::gpu_algo
