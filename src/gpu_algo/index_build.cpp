#include "gpu_algo/index_build.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <future>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/parallel.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/self_check.hpp"
#include "gpu_algo/space_order.hpp"

namespace rthdist::gpu_algo {

int clampedBits(int bits, uint32_t n) {
    while (bits > core::kMinBits && (uint64_t(1) << (3 * bits)) > 8 * uint64_t(n) + 4096) --bits;
    return bits;
}

namespace {

// Crowded sets of at most this many points together split side by side
// (IndexBuild::splitLeaves): the second set's leaf scratch and ping-pong
// buffers (~36 bytes a point) are held beside the first's.
constexpr uint64_t kSideBySideSplitPoints = uint64_t(1) << 24;

// Points [begin, end) as vec4 records (w = 0) at dst, their box into lo, hi
// (kept in registers: dst may alias them as far as the compiler knows).
void toRecords(std::span<const glm::vec3> pts, size_t begin, size_t end, float* dst, glm::vec3& lo,
               glm::vec3& hi) {
    glm::vec3 l = lo, h = hi;
    for (size_t i = begin; i < end; ++i) {
        const glm::vec3 p = pts[i];
        dst[4 * (i - begin) + 0] = p.x;
        dst[4 * (i - begin) + 1] = p.y;
        dst[4 * (i - begin) + 2] = p.z;
        dst[4 * (i - begin) + 3] = 0.0f;
        l = glm::min(l, p);
        h = glm::max(h, p);
    }
    lo = l;
    hi = h;
}

// Threads of a pass in spreadItem's order (common.glsl) over n items: n
// rounded up to whole warps of 32 (n < 2^31: no overflow).
uint64_t spreadThreads(uint32_t n) { return (uint64_t(n) + 31) / 32 * 32; }

}  // namespace

void IndexBuild::stageIndex(PointIndex& ix, std::span<const glm::vec3> pts, int bits) {
    ix.n = uint32_t(pts.size());
    if (pts.size() > m_ws.chunkedUploadPoints) {
        // The records go up in chunks (uploadChunked), whose pass over the
        // points takes their box; the grid follows it there.
        ix.hostSource = pts;
        ix.hostSourceBits = bits;
        return;
    }
    ix.hostSource = {};
    Buffer& staging =
        m_ws.grow(ix.scratch->staging, VkDeviceSize(ix.n) * 16, ix.name + ".staging", MemoryKind::kHost);
    auto* dst = static_cast<float*>(staging.mapped());
    const int threads = core::resolveThreads(m_ws.threads, ix.n / kHostChunk + 1);
    std::vector<glm::vec3> lo(size_t(threads), pts[0]), hi(size_t(threads), pts[0]);
    core::parallelChunks(ix.n, kHostChunk, threads, [&](size_t begin, size_t end, int t) {
        toRecords(pts, begin, end, dst + 4 * begin, lo[size_t(t)], hi[size_t(t)]);
    });
    setGrid(ix, pts, lo, hi, bits);
}

void IndexBuild::setGrid(PointIndex& ix, std::span<const glm::vec3> pts, std::span<glm::vec3> lo,
                         std::span<glm::vec3> hi, int bits) {
    for (size_t t = 1; t < lo.size(); ++t) {
        lo[0] = glm::min(lo[0], lo[t]);
        hi[0] = glm::max(hi[0], hi[t]);
    }
    ix.bounds.lo = glm::dvec3(lo[0]);
    ix.bounds.hi = glm::dvec3(hi[0]);
    if (bits <= 0) {
        bits = clampedBits(core::chooseBits(pts, ix.bounds), ix.n);
    }
    ix.grid = core::makeGrid(ix.bounds, bits);
    ix.spaceOrder = inSpaceOrder(pts, ix.grid, m_ws.spaceOrderMinPoints);
}

void IndexBuild::uploadChunked(PointIndex& ix) {
    // Two halves of one host buffer: the host copies the packed floats of
    // the next chunk into one (and takes their box) while the device copies
    // the other (double buffering). 12 bytes a point cross the bus, not 16:
    // the device turns each chunk into vec4 records (ingest.comp) from a
    // chunk-sized buffer of its own.
    const size_t chunkPoints = std::max<size_t>(1, m_ws.uploadChunkPoints / 2);
    const VkDeviceSize chunkBytes = VkDeviceSize(chunkPoints) * 12;
    Buffer& chunks =
        m_ws.grow(m_ws.scratch.uploadChunk, 2 * chunkBytes, "uploadChunk", MemoryKind::kHost, false);
    Buffer& packed =
        m_ws.grow(m_ws.scratch.uploadPacked, chunkBytes, "uploadPacked", MemoryKind::kDevice, false);
    Buffer& summary = m_ws.grow(m_ws.scratch.uploadSummary, sizeof(sh::IngestSummary), "uploadSummary",
                                MemoryKind::kDevice, false);
    Buffer& points = m_ws.grow(ix.scratch->points, VkDeviceSize(ix.n) * 16, ix.name + ".points");
    const std::span<const glm::vec3> pts = ix.hostSource;
    // The box, per host thread (the fills run one at a time: the next starts
    // after the previous one's get()).
    const int threads = core::resolveThreads(m_ws.threads, chunkPoints / kHostChunk + 1);
    std::vector<glm::vec3> lo(size_t(threads), pts[0]), hi(size_t(threads), pts[0]);
    auto fill = [&](size_t first, int half) {
        auto* dst =
            reinterpret_cast<glm::vec3*>(static_cast<char*>(chunks.mapped()) + chunkBytes * size_t(half));
        const size_t count = std::min(chunkPoints, pts.size() - first);
        core::parallelChunks(count, kHostChunk, threads, [&](size_t begin, size_t end, int t) {
            glm::vec3 l = lo[size_t(t)], h = hi[size_t(t)];
            for (size_t i = begin; i < end; ++i) {
                const glm::vec3 p = pts[first + i];
                l = glm::min(l, p);
                h = glm::max(h, p);
            }
            lo[size_t(t)] = l;
            hi[size_t(t)] = h;
            std::memcpy(dst + begin, pts.data() + first + begin, (end - begin) * sizeof(glm::vec3));
        });
    };
    const auto t0 = Clock::now();
    fill(0, 0);
    int half = 0;
    for (size_t first = 0; first < pts.size(); first += chunkPoints, half ^= 1) {
        const size_t count = std::min(chunkPoints, pts.size() - first);
        const size_t next = first + chunkPoints;
        // The next chunk's floats, written while this one is copied (its
        // destructor waits: nothing writes the buffer after we leave).
        std::future<void> filling;
        if (next < pts.size()) filling = std::async(std::launch::async, fill, next, half ^ 1);
        VkCommandBuffer cmd = m_ws.ctx.begin();
        {
            const gpu::ScopedLabel label(m_ws.ctx, cmd, "upload");
            const VkBufferCopy region{VkDeviceSize(half) * chunkBytes, 0, VkDeviceSize(count) * 12};
            vkCmdCopyBuffer(cmd, chunks.handle(), packed.handle(), 1, &region);
            m_ws.barrier(cmd);
            sh::IngestPush ip{packed.address(), points.address() + VkDeviceAddress(first) * 16,
                              summary.address(), uint32_t(count), 12u};
            m_ws.dispatch(cmd, Kernel::kIngest, ip, count);
        }
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuUpload += m_ws.ctx.lastGpuMs();
        if (filling.valid()) filling.get();
    }
    setGrid(ix, pts, lo, hi, ix.hostSourceBits);
    m_ws.timings->upload += msSince(t0);
    ix.hostSource = {};
}

void IndexBuild::cmdUpload(VkCommandBuffer cmd, PointIndex& ix) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "upload");
    const VkDeviceSize bytes = VkDeviceSize(ix.n) * 16;
    Buffer& points = m_ws.grow(ix.scratch->points, bytes, ix.name + ".points");
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd,
                    m_ws.grow(ix.scratch->staging, bytes, ix.name + ".staging", MemoryKind::kHost).handle(),
                    points.handle(), 1, &region);
}

void IndexBuild::cmdBuildIndex(VkCommandBuffer cmd, PointIndex& ix, const CounterBlock& blk) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "index build");
    const VkDeviceSize bytes = VkDeviceSize(ix.n) * 16;
    Buffer& points = m_ws.grow(ix.scratch->points, bytes, ix.name + ".points");
    const uint32_t numKeys = 1u << (3 * ix.grid.bits);
    const uint64_t threads = ix.spaceOrder ? spreadThreads(ix.n) : ix.n;  // the keys and scatter passes'
    Buffer& keys = m_ws.grow(ix.scratch->keys, VkDeviceSize(threads) * 4, ix.name + ".keys");
    ix.sortedKeys = &m_ws.setBuffer(ix, ix.store->sortedKeys, ".sortedKeys", VkDeviceSize(ix.n) * 4);
    Buffer& flags = m_ws.grow(ix.scratch->flags, VkDeviceSize(ix.n) * 4, ix.name + ".flags");
    const VkDeviceSize denseBytes = VkDeviceSize(numKeys) * 4;
    ix.dense = &m_ws.setBuffer(ix, ix.store->dense, ".dense", denseBytes);
    ix.sorted = &m_ws.setBuffer(ix, ix.store->sorted, ".sorted", bytes);
    // Cells: at most one per point or key; the upper bound avoids a read-back.
    ix.cellCapacity = std::min<uint64_t>(ix.n, numKeys);
    ix.cells =
        &m_ws.setBuffer(ix, ix.store->cells, ".cells", VkDeviceSize(ix.cellCapacity) * sizeof(sh::Cell));

    blk.fields().maxCount = 0;
    blk.fields().largeCells = 0;
    m_ws.ctx.cmdTraceMark(cmd);  // the trace's phases: fill, keys, scan, scatter, heads, scan, cells, check
    vkCmdFillBuffer(cmd, ix.dense->handle(), 0, denseBytes, 0);
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    const uint32_t spread = ix.spaceOrder ? 1u : 0u;
    sh::KeysPush kp{points.address(), keys.address(), ix.dense->address(), gridParams(ix.grid), ix.n, spread};
    m_ws.dispatch(cmd, Kernel::kCellKeys, kp, threads);
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    m_ws.cmdScan(cmd, ix.dense->address(), numKeys, ix.scratch->scanKeys, "scanKeys");
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    sh::ScatterPush sp{points.address(),
                       keys.address(),
                       ix.dense->address(),
                       ix.sorted->address(),
                       ix.sortedKeys->address(),
                       ix.n,
                       spread};
    m_ws.dispatch(cmd, Kernel::kScatter, sp, threads);
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    sh::CellsPush cp{
        ix.sorted->address(),
        ix.sortedKeys->address(),
        flags.address(),
        ix.dense->address(),
        ix.cells->address(),
        blk.addr(RTHDIST_CTR_CELLS),
        blk.addr(RTHDIST_CTR_MAX_COUNT),
        m_ws.grow(ix.scratch->boundsU, VkDeviceSize(ix.cellCapacity) * 24, ix.name + ".boundsU").address(),
        blk.addr(RTHDIST_CTR_LARGE_CELLS),
        ix.n,
        uint32_t(ix.cellCapacity)};
    m_ws.dispatch(cmd, Kernel::kCellHeads, cp, ix.n);
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    m_ws.cmdScan(cmd, flags.address(), ix.n, ix.scratch->scanFlags, "scanFlags");
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    cmdCellBuild(cmd, std::span(&cp, 1));
    m_ws.barrier(cmd);
    m_ws.ctx.cmdTraceMark(cmd);
    cmdCheckIndex(cmd, ix, blk);  // in the same submission: no extra wait
}

bool IndexBuild::finishIndex(PointIndex& ix, const CounterBlock& blk) {
    ix.numCells = blk.fields().cells;
    verifyIndex(ix, ix.cellCapacity, blk);
    if (ix.scratch != nullptr) m_ws.recycleBuild(*ix.scratch);  // sorted: the unsorted points, keys spent
    return blk.fields().maxCount > kCrowdedCell;
}

void IndexBuild::buildIndexes(std::span<PointIndex* const> sets, bool ingested) {
    if (sets.size() > m_ws.blocks.size())
        throw std::logic_error("buildIndexes: more sets than counter blocks");
    std::vector<PointIndex*> staged;  // staged whole: copied in the build's submission
    for (PointIndex* ix : sets) {
        if (ingested) continue;
        if (ix->hostSource.empty())
            staged.push_back(ix);
        else
            uploadChunked(*ix);  // own submissions, upload time
    }
    auto t0 = Clock::now();
    VkCommandBuffer cmd = m_ws.ctx.begin();
    for (PointIndex* ix : staged) cmdUpload(cmd, *ix);
    const uint32_t uploaded = m_ws.ctx.cmdMark(cmd);
    m_ws.barrier(cmd);
    for (size_t k = 0; k < sets.size(); ++k) cmdBuildIndex(cmd, *sets[k], m_ws.blocks[k]);
    m_ws.ctx.submitAndWait(cmd);
    const double uploadMs = m_ws.ctx.gpuMsBetween(0, uploaded);
    m_ws.timings->upload += uploadMs;
    m_ws.timings->gpuUpload += uploadMs;
    m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs() - uploadMs;
    std::vector<PointIndex*> crowded;
    uint64_t crowdedPoints = 0;
    for (size_t k = 0; k < sets.size(); ++k) {
        if (!finishIndex(*sets[k], m_ws.blocks[k])) continue;
        crowded.push_back(sets[k]);
        crowdedPoints += sets[k]->n;
    }
    // Small sets split side by side (their submissions' round trips are a
    // large share of their split); large ones one after the other, so that
    // the first's spent buffers serve the second.
    if (crowdedPoints <= kSideBySideSplitPoints)
        splitLeaves(crowded);
    else
        for (PointIndex* ix : crowded) splitLeaves(std::span(&ix, 1));
    m_ws.timings->index += msSince(t0) - uploadMs;
}

void IndexBuild::cmdCellBuild(VkCommandBuffer cmd, std::span<const sh::CellsPush> cps) {
    for (const sh::CellsPush& cp : cps) m_ws.dispatch(cmd, Kernel::kCellBuild, cp, cp.n);
    m_ws.barrier(cmd);
    for (const sh::CellsPush& cp : cps) m_ws.dispatch(cmd, Kernel::kCellBounds, cp, cp.n);
    m_ws.barrier(cmd);
    for (const sh::CellsPush& cp : cps) m_ws.dispatch(cmd, Kernel::kCellBoundsFix, cp, cp.cellCapacity);
}

void IndexBuild::cmdCheckIndex(VkCommandBuffer cmd, const PointIndex& ix, const CounterBlock& blk) {
    blk.fields().checkSum = 0;
    blk.fields().checkBad = 0;
    // check_index reads the index's fields; check_queries' (state, perPoint, the outputs) stay 0.
    sh::CheckPush cp{};
    cp.sorted = ix.sorted->address();
    cp.sortedKeys = ix.sortedKeys->address();
    cp.counters = blk.device;
    cp.grid = gridParams(ix.grid);
    cp.n = ix.n;
    m_ws.dispatch(cmd, Kernel::kCheckIndex, cp, ix.n);
}

void IndexBuild::verifyIndex(const PointIndex& ix, uint64_t cellCapacity, const CounterBlock& blk) {
    const uint64_t n = ix.n;
    const uint64_t expectedSum = n % 2 == 0 ? (n / 2) * (n - 1) : n * ((n - 1) / 2);
    std::string why = indexCheckFailure(n, blk.fields().checkBad, blk.fields().checkSum, expectedSum,
                                        ix.numCells, cellCapacity);
    if (!why.empty()) throw SelfCheckError("index of " + ix.name + ": " + why);
}

}  // namespace rthdist::gpu_algo
