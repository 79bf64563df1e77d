#include "algo/gpu_hausdorff.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <map>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "algo/index_space.hpp"
#include "algo/input_frame.hpp"
#include "algo/self_check.hpp"
#include "cpu/parallel.hpp"
#include "gpu/accel.hpp"
#include "gpu/buffer.hpp"
#include "gpu/context.hpp"
#include "gpu/device_limits.hpp"
#include "gpu/host_import.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu/pipelines.hpp"
#include "rthdist_shared.h"

namespace rthdist::algo {

using gpu::Buffer;
using gpu::Kernel;
using gpu::MemoryKind;
namespace sh = rthdist::shared;

static_assert(sizeof(sh::Cell) == 32 && offsetof(sh::Cell, hi) == 16 && offsetof(sh::Cell, count) == 28);
static_assert(sizeof(sh::QueryState) == 16 && offsetof(sh::QueryState, rLo) == 8);
static_assert(sizeof(sh::GridParams) == 32);
static_assert(sizeof(sh::SearchPush) <= 128 && sizeof(sh::CullPush) <= 128 && sizeof(sh::RefinePush) <= 128);

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

constexpr uint64_t kMaxPairCapacity = uint64_t(1) << 26;  // 512 MiB of pairs at most
// Pooled buffers get this much room to grow (a quarter, at most 64 MiB, never
// past the device's largest buffer).
constexpr VkDeviceSize kMaxSlack = VkDeviceSize(64) << 20;
// Query slots whose device records the self-check compares with the host.
constexpr uint32_t kCheckSamples = 32;
constexpr uint32_t kMaxIterations = 4096;
constexpr size_t kHostChunk = size_t(1) << 16;  // points per host work item
// Density-robust index (issue 17): a uniform grid over the bounding box puts a
// dense cluster into a few cells when a stray point stretches the box. A cell
// of more than kCrowdedCell points (not all one point) switches the index to
// leaves: crowded cells are cut into sub-cells of their own tight box until no
// leaf that can split holds more than kLeafMax points. The neighbourhood pass
// scans at most kCrowdedCell points of a cell (a larger one is split, or holds
// copies of one point, whose first copy stands for all), so no stage's
// work per query depends on how many points share a grid cell. (The Dragon's
// fullest cell holds 134 points; even data stays on the grid path.)
constexpr uint32_t kCrowdedCell = 512;
constexpr uint32_t kLeafMax = RTHDIST_LEAF_MAX;
constexpr int kMaxSplitRounds = 12;
// One-shot sets of at most this many points together are uploaded and
// indexed in one submission, each with scratch buffers of its own.
constexpr size_t kFusedBuildPoints =
    size_t(1) << 25;  // each round narrows a leaf >= 2x per axis; past it: bigger leaves

// A point set sorted into the cells of its own grid.
struct PointIndex {
    uint32_t n = 0;
    GridSpec grid;
    Bounds bounds;
    Buffer* sorted = nullptr;  // vec4: xyz, w = original index bits (cell order)
    Buffer* dense = nullptr;   // uint per key: end of the key's cell
    Buffer* cells = nullptr;   // Cell per occupied cell
    uint32_t numCells = 0;
    uint64_t cellCapacity = 0;     // room of `cells` at the build: min(n, keys)
    Buffer* sortedKeys = nullptr;  // fine key per sorted point (builds coarser levels)
    std::string name;              // "A", "B" or "set#N": names its buffers and its messages
    std::string scratch;           // prefix of its build's pooled scratch buffers ("A", "B", "build")
    const gpu::HostImport* source = nullptr;  // ingest: the caller's array imported in place, if it could be
    // Where its buffers live: the engine's pool (one-shot sets, reused by
    // name by the next call) or a prepared set's own map (exact sizes).
    std::map<std::string, Buffer>* store = nullptr;
    bool owned = false;
    // Leaves: `cells` are sub-cells of crowded grid cells (still contiguous
    // runs inside their grid cells), searched directly while the radius is
    // small; minEdge is the narrowest split sub-cell's edge (first radius).
    bool split = false;
    double minEdge = 0.0;
    // Search cells by level j >= 1 (edge s * 2^j), built on first use.
    struct Level {
        Buffer* cells = nullptr;
        Buffer* fineFirst = nullptr;  // uint per cell: its first level-0 cell
        uint32_t count = 0;
    };
    std::vector<Level> levels;
};

sh::GridParams gridParams(const GridSpec& g) {
    sh::GridParams p{};
    p.originX = float(g.origin.x);
    p.originY = float(g.origin.y);
    p.originZ = float(g.origin.z);
    p.cellSize = float(g.cellSize);
    p.invCellSize = float(1.0 / g.cellSize);
    p.bits = uint32_t(g.bits);
    p.cellsPerAxis = g.cellsPerAxis;
    return p;
}

// The square of the largest excess of q's box over t's box along one axis
// (0 when q's box lies inside t's): a lower bound of h(Q, T)^2.
double boxLowerBound2(const Bounds& q, const Bounds& t) {
    const glm::dvec3 excess = glm::max(glm::max(q.hi - t.hi, t.lo - q.lo), glm::dvec3(0.0));
    const double e = std::max({excess.x, excess.y, excess.z});
    return e * e;
}

// Float copies of the points multiplied by a power of two in double (exact:
// the rule keeps every product a normal float or zero).
std::vector<glm::vec3> scaledCopy(std::span<const glm::vec3> pts, double scale) {
    std::vector<glm::vec3> out(pts.size());
    const int threads = cpu::resolveThreads(0, pts.size() / kHostChunk + 1);
    cpu::parallelChunks(pts.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) out[i] = glm::vec3(glm::dvec3(pts[i]) * scale);
    });
    return out;
}

// The float of orderedBits (common.glsl): the host's read of a reduced bound.
float fromOrderedBits(uint32_t u) {
    return std::bit_cast<float>((u & 0x80000000u) != 0u ? u & 0x7fffffffu : ~u);
}

// The dense key table costs O(2^(3k)) to clear and scan: an automatic bit
// count keeps it within a few entries per point.
int clampedBits(int bits, uint32_t n) {
    while (bits > kMinBits && (uint64_t(1) << (3 * bits)) > 8 * uint64_t(n) + 4096) --bits;
    return bits;
}

// The bit counts and grids of two ingested sets, side by side: their bounds
// come from the device, their bit counts from a strided sample of the
// caller's arrays (chooseBits reads ~32k points in place, ~0.2-0.4 ms each).
// A free function of this file, so no instantiation of its thread is
// exported from the shared library.
void chooseIngestedGrids(const std::array<PointIndex*, 2>& sets,
                         const std::array<std::span<const glm::vec3>, 2>& pts, int bits) {
    cpu::parallelChunks(2, 1, 2, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k) {
            PointIndex& ix = *sets[k];
            const int chosen = bits > 0 ? bits : clampedBits(chooseBits(pts[k], ix.bounds), ix.n);
            ix.grid = makeGrid(ix.bounds, chosen);
        }
    });
}

// A call whose cancel flag was set: unwinds to the guard of the entry point.
struct CallCancelled {};

// Bad input found on the device (ingest.comp): unwinds to the guard, which
// returns it as it is.
struct InputRejected {
    Error error;
};

void throwIfCancelled(const CallOptions& options) {
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) throw CallCancelled{};
}

}  // namespace

// One block of the host-visible counters (offsets RTHDIST_CTR_* of
// rthdist_shared.h, the read-back area after them). The shaders find a
// counter at the block's address plus its offset, so two index builds in one
// submission each count into a block of their own.
struct CounterBlock {
    char* host = nullptr;
    VkDeviceAddress device = 0;
    VkDeviceSize offset = 0;  // in the buffer that holds the blocks
    template <class T>
    T& at(size_t offset) const {
        return *reinterpret_cast<T*>(host + offset);
    }
    [[nodiscard]] VkDeviceAddress addr(size_t offset) const { return device + offset; }
};
constexpr VkDeviceSize kCounterBlockBytes = RTHDIST_CTR_BYTES;
static_assert(RTHDIST_CTR_READBACK + (kCheckSamples + 1) * 32 <= RTHDIST_CTR_INGEST &&
              RTHDIST_CTR_INGEST + sizeof(sh::IngestSummary) <= kCounterBlockBytes);

// A set indexed on the device (DeviceSet in gpu_hausdorff.hpp): its index,
// the buffers it owns (prepared) and the float points the device holds.
struct DeviceSet {
    DeviceSet() = default;
    DeviceSet(const DeviceSet&) = delete;  // ix.store may point into `own`
    DeviceSet& operator=(const DeviceSet&) = delete;

    std::map<std::string, Buffer> own;  // a prepared set's buffers (empty for one-shot sets)
    PointIndex ix;
    std::span<const glm::vec3> input;   // the backend's input (float, before the scale)
    std::vector<glm::vec3> scaledCopy;  // input * scale when scale != 1
    std::span<const glm::vec3> points;  // what the device holds: input or scaledCopy
    double scale = 1.0;
};

struct GpuHausdorff::State {
    gpu::Context& ctx;
    gpu::PipelineCache pipelineCache;  // before the pipelines it seeds
    gpu::Pipelines pipelines;
    gpu::AccelStructures accel;
    bool rayQuery;
    bool tlasBound = false;
    Buffer hostSmall;                    // the counter blocks (RTHDIST_CTR_*), read-backs after each
    std::array<CounterBlock, 2> blocks;  // blocks[0]: every stage; [1]: a second index build
    uint64_t maxPairCapacity = kMaxPairCapacity;
    Timings* timings = nullptr;
    // Buffers live across calls and only grow: allocation is a large share of
    // a call's cost on discrete GPUs.
    std::map<std::string, Buffer> pool;
    // The caller's arrays imported for the submission in flight (deque:
    // stable addresses for PointIndex::source).
    std::deque<gpu::HostImport> imports;

    // A buffer may be replaced only between submissions: every name is used by
    // at most one purpose inside one command buffer.
    Buffer& buf(const std::string& name, VkDeviceSize bytes, MemoryKind kind = MemoryKind::kDevice) {
        return bufIn(pool, name, bytes, kind, true);
    }
    // A buffer of set `ix` (its index and search levels), in the set's store.
    Buffer& setBuf(PointIndex& ix, const std::string& suffix, VkDeviceSize bytes) {
        return bufIn(*ix.store, ix.name + suffix, bytes, MemoryKind::kDevice, !ix.owned);
    }
    // Pooled buffers get room to grow; a prepared set's get their size.
    Buffer& bufIn(std::map<std::string, Buffer>& store, const std::string& name, VkDeviceSize bytes,
                  MemoryKind kind, bool slack) {
        Buffer& b = store[name];
        if (!b || b.size() < bytes) {
            b.reset();
            const VkDeviceSize room =
                !slack ? bytes
                       : std::min<VkDeviceSize>(bytes + std::min(bytes / 4, kMaxSlack),
                                                std::max<VkDeviceSize>(bytes, ctx.limits().maxBufferBytes));
            b = Buffer(
                ctx, std::max<VkDeviceSize>(room, 256),
                gpu::kStorageUsage | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                kind);
            ctx.setDebugName(VK_OBJECT_TYPE_BUFFER, uint64_t(b.handle()), name.c_str());
        }
        return b;
    }

    State(gpu::Context& c, const std::string& cacheDir)
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

    // A counter of block 0 (offsets from rthdist_shared.h): the stages run one at a time.
    template <class T>
    T& counter(size_t offset) {
        return blocks[0].at<T>(offset);
    }
    VkDeviceAddress cellsCounterAddr() const { return blocks[0].addr(RTHDIST_CTR_CELLS); }
    VkDeviceAddress maxCountAddr() const { return blocks[0].addr(RTHDIST_CTR_MAX_COUNT); }

    void barrier(VkCommandBuffer cmd) { gpu::cmdShaderBarrier(cmd, pipelines.shaderStages()); }

    template <class Push>
    void dispatch(VkCommandBuffer cmd, Kernel k, const Push& push, uint64_t items,
                  uint32_t groupSize = RTHDIST_WG) {
        pipelines.cmdDispatch(cmd, k, &push, sizeof(Push), gpu::groupsFor(items, groupSize));
    }

    // Exclusive scan of uint[n] at `data`, recursively over block sums.
    void cmdScan(VkCommandBuffer cmd, VkDeviceAddress data, uint32_t n, const std::string& tag,
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

    // Host half of an index build: the points into the set's staging buffer
    // (vec4) in one parallel pass that also takes their bounds, then the bit
    // count and the grid. Nothing is submitted.
    void stageIndex(PointIndex& ix, std::span<const glm::vec3> pts, int bits) {
        ix.n = uint32_t(pts.size());
        const VkDeviceSize bytes = VkDeviceSize(ix.n) * 16;
        Buffer& staging = buf(ix.scratch + ".staging", bytes, MemoryKind::kHost);
        auto* dst = static_cast<float*>(staging.mapped());
        const int threads = cpu::resolveThreads(0, ix.n / kHostChunk + 1);
        std::vector<glm::vec3> lo(size_t(threads), pts[0]), hi(size_t(threads), pts[0]);
        cpu::parallelChunks(ix.n, kHostChunk, threads, [&](size_t begin, size_t end, int t) {
            glm::vec3 l = lo[size_t(t)], h = hi[size_t(t)];
            for (size_t i = begin; i < end; ++i) {
                const glm::vec3 p = pts[i];
                dst[4 * i + 0] = p.x;
                dst[4 * i + 1] = p.y;
                dst[4 * i + 2] = p.z;
                dst[4 * i + 3] = 0.0f;
                l = glm::min(l, p);
                h = glm::max(h, p);
            }
            lo[size_t(t)] = l;
            hi[size_t(t)] = h;
        });
        for (int t = 1; t < threads; ++t) {
            lo[0] = glm::min(lo[0], lo[size_t(t)]);
            hi[0] = glm::max(hi[0], hi[size_t(t)]);
        }
        ix.bounds.lo = glm::dvec3(lo[0]);
        ix.bounds.hi = glm::dvec3(hi[0]);
        if (bits <= 0) {
            bits = clampedBits(chooseBits(pts, ix.bounds), ix.n);
        }
        ix.grid = makeGrid(ix.bounds, bits);
    }

    // The staged points' copy to the device (before cmdBuildIndex, with a
    // barrier between: several sets' copies run back to back).
    void cmdUpload(VkCommandBuffer cmd, PointIndex& ix) {
        const VkDeviceSize bytes = VkDeviceSize(ix.n) * 16;
        Buffer& points = buf(ix.scratch + ".points", bytes);
        const VkBufferCopy region{0, 0, bytes};
        vkCmdCopyBuffer(cmd, buf(ix.scratch + ".staging", bytes, MemoryKind::kHost).handle(), points.handle(),
                        1, &region);
    }

    // The device ingest path (ingest.comp) for packed float host arrays:
    // the device reads each array from a host-visible copy (the host's only
    // pass over the points) or, with imports on (gpu/host_import.hpp), where
    // it lies. The device uploads it, checks it and takes its bounds. Sets
    // `ix.n`; nothing is submitted.
    void stageSource(PointIndex& ix, std::span<const glm::vec3> pts) {
        ix.n = uint32_t(pts.size());
        const size_t bytes = size_t(ix.n) * 12;
        if (std::optional<gpu::HostImport> im = gpu::HostImport::create(ctx, pts.data(), bytes)) {
            imports.push_back(std::move(*im));
            ix.source = &imports.back();
            return;
        }
        ix.source = nullptr;
        Buffer& source = buf(ix.scratch + ".source", bytes, MemoryKind::kHost);
        auto* dst = static_cast<char*>(source.mapped());
        const char* src = reinterpret_cast<const char*>(pts.data());
        const int threads = cpu::resolveThreads(0, ix.n / kHostChunk + 1);
        cpu::parallelChunks(ix.n, kHostChunk, threads, [&](size_t begin, size_t end, int) {
            std::memcpy(dst + begin * 12, src + begin * 12, (end - begin) * 12);
        });
    }

    // Records the upload of a staged source (stageSource) into device memory.
    void cmdUploadSource(VkCommandBuffer cmd, const PointIndex& ix) {
        const VkDeviceSize bytes = VkDeviceSize(ix.n) * 12;
        const VkBuffer from =
            ix.source ? ix.source->handle() : buf(ix.scratch + ".source", bytes, MemoryKind::kHost).handle();
        const VkBufferCopy region{ix.source ? ix.source->offset() : 0, 0, bytes};
        vkCmdCopyBuffer(cmd, from, buf(ix.scratch + ".raw", bytes).handle(), 1, &region);
    }

    // Records the ingest of an uploaded source into the set's vec4 points
    // and its summary in `blk`.
    void cmdIngest(VkCommandBuffer cmd, const PointIndex& ix, const CounterBlock& blk) {
        auto& summary = blk.at<sh::IngestSummary>(RTHDIST_CTR_INGEST);
        for (int k = 0; k < 3; ++k) {
            summary.lo[k] = 0xffffffffu;
            summary.hi[k] = 0u;
        }
        summary.firstBad = 0xffffffffu;
        sh::IngestPush ip{buf(ix.scratch + ".raw", VkDeviceSize(ix.n) * 12).address(),
                          buf(ix.scratch + ".points", VkDeviceSize(ix.n) * 16).address(),
                          blk.addr(RTHDIST_CTR_INGEST), ix.n, 12u};
        dispatch(cmd, Kernel::kIngest, ip, ix.n);
    }

    // After the ingest's submission: the set's bounds from `blk`, or the
    // error naming its first point that is not finite (as summarizeSet
    // words it for host input).
    void finishIngest(PointIndex& ix, const CounterBlock& blk) {
        const auto& summary = blk.at<sh::IngestSummary>(RTHDIST_CTR_INGEST);
        if (summary.firstBad != 0xffffffffu)
            throw InputRejected{Error{ErrorCode::kInvalidArgument, "point set " + ix.name + ": point " +
                                                                       std::to_string(summary.firstBad) +
                                                                       " has a NaN or infinite coordinate"}};
        for (int k = 0; k < 3; ++k) {
            ix.bounds.lo[k] = double(fromOrderedBits(summary.lo[k]));
            ix.bounds.hi[k] = double(fromOrderedBits(summary.hi[k]));
        }
    }

    // Device half of an index build, recorded into `cmd` after the upload:
    // cell keys, counting sort over the dense key table, run-length encoding
    // into cells with tight boxes, the self-check. Counters go to `blk`;
    // scratch buffers are the set's own (ix.scratch), so two sets can be
    // built in one submission.
    void cmdBuildIndex(VkCommandBuffer cmd, PointIndex& ix, const CounterBlock& blk) {
        const VkDeviceSize bytes = VkDeviceSize(ix.n) * 16;
        Buffer& points = buf(ix.scratch + ".points", bytes);
        const uint32_t numKeys = 1u << (3 * ix.grid.bits);
        Buffer& keys = buf(ix.scratch + ".keys", VkDeviceSize(ix.n) * 4);
        ix.sortedKeys = &setBuf(ix, ".sortedKeys", VkDeviceSize(ix.n) * 4);
        Buffer& flags = buf(ix.scratch + ".flags", VkDeviceSize(ix.n) * 4);
        const VkDeviceSize denseBytes = VkDeviceSize(numKeys) * 4;
        ix.dense = &setBuf(ix, ".dense", denseBytes);
        ix.sorted = &setBuf(ix, ".sorted", bytes);
        // Cells: at most one per point or key; the upper bound avoids a read-back.
        ix.cellCapacity = std::min<uint64_t>(ix.n, numKeys);
        ix.cells = &setBuf(ix, ".cells", VkDeviceSize(ix.cellCapacity) * sizeof(sh::Cell));

        blk.at<uint32_t>(RTHDIST_CTR_MAX_COUNT) = 0;
        blk.at<uint32_t>(RTHDIST_CTR_LARGE_CELLS) = 0;
        vkCmdFillBuffer(cmd, ix.dense->handle(), 0, denseBytes, 0);
        barrier(cmd);
        sh::KeysPush kp{points.address(), keys.address(), ix.dense->address(), gridParams(ix.grid), ix.n};
        dispatch(cmd, Kernel::kCellKeys, kp, ix.n);
        barrier(cmd);
        cmdScan(cmd, ix.dense->address(), numKeys, ix.scratch + ".scanKeys", 0);
        barrier(cmd);
        sh::ScatterPush sp{points.address(),     keys.address(),           ix.dense->address(),
                           ix.sorted->address(), ix.sortedKeys->address(), ix.n};
        dispatch(cmd, Kernel::kScatter, sp, ix.n);
        barrier(cmd);
        sh::CellsPush cp{ix.sorted->address(),
                         ix.sortedKeys->address(),
                         flags.address(),
                         ix.dense->address(),
                         ix.cells->address(),
                         blk.addr(RTHDIST_CTR_CELLS),
                         blk.addr(RTHDIST_CTR_MAX_COUNT),
                         buf(ix.scratch + ".boundsU", VkDeviceSize(ix.cellCapacity) * 24).address(),
                         blk.addr(RTHDIST_CTR_LARGE_CELLS),
                         ix.n,
                         uint32_t(ix.cellCapacity)};
        dispatch(cmd, Kernel::kCellHeads, cp, ix.n);
        barrier(cmd);
        cmdScan(cmd, flags.address(), ix.n, ix.scratch + ".scanFlags", 0);
        barrier(cmd);
        cmdCellBuild(cmd, cp);
        barrier(cmd);
        cmdCheckIndex(cmd, ix, blk);  // in the same submission: no extra wait
    }

    // After the build's submission: the self-check's verdict and the cell
    // count from `blk`; crowded cells are split into leaves (own submissions).
    void finishIndex(PointIndex& ix, const CounterBlock& blk) {
        ix.numCells = blk.at<uint32_t>(RTHDIST_CTR_CELLS);
        verifyIndex(ix, ix.cellCapacity, blk);
        if (blk.at<uint32_t>(RTHDIST_CTR_MAX_COUNT) > kCrowdedCell) splitLeaves(ix);
    }

    // Indexes the staged sets (one or two) in one submission: both uploads
    // back to back, then each build; then each set's checks and leaves.
    template <size_t N>
    void buildIndexes(const std::array<PointIndex*, N>& sets, bool ingested = false) {
        static_assert(N <= std::tuple_size_v<decltype(blocks)>, "a counter block per set");
        if (sets.size() > blocks.size())
            throw std::logic_error("buildIndexes: more sets than counter blocks");
        auto t0 = Clock::now();
        VkCommandBuffer cmd = ctx.begin();
        for (PointIndex* ix : sets)
            if (!ingested) cmdUpload(cmd, *ix);
        const uint32_t uploaded = ctx.cmdMark(cmd);
        barrier(cmd);
        for (size_t k = 0; k < sets.size(); ++k) cmdBuildIndex(cmd, *sets[k], blocks[k]);
        ctx.submitAndWait(cmd);
        const double uploadMs = ctx.gpuMsBetween(0, uploaded);
        timings->upload += uploadMs;
        timings->gpuUpload += uploadMs;
        timings->gpuIndex += ctx.lastGpuMs() - uploadMs;
        for (size_t k = 0; k < sets.size(); ++k) finishIndex(*sets[k], blocks[k]);
        timings->index += msSince(t0) - uploadMs;
    }

    // Cuts the crowded cells of `ix` into leaves (leaf_*.comp), round by
    // round, then checks the index again. Each round is one submission: a
    // counting sort by slot inside every cell, and the cells of the new order.
    void splitLeaves(PointIndex& ix) {
        const VkDeviceSize n = ix.n;
        Buffer* sorted[2] = {ix.sorted, &setBuf(ix, ".sorted2", n * 16)};
        Buffer* gridKeys[2] = {ix.sortedKeys, &setBuf(ix, ".sortedKeys2", n * 4)};
        Buffer* leaves[2] = {&setBuf(ix, ".leaves0", n * sizeof(sh::Cell)),
                             &setBuf(ix, ".leaves1", n * sizeof(sh::Cell))};
        Buffer& slotKeys = buf("slotKeys", n * 4);
        Buffer& outSlotKeys = buf("outSlotKeys", n * 4);
        Buffer& flags = buf("flags", n * 4);
        Buffer* cells = ix.cells;
        int cur = 0;
        counter<uint32_t>(RTHDIST_CTR_MIN_EDGE) = 0x7f800000u;  // +inf
        for (int round = 0; round < kMaxSplitRounds; ++round) {
            // All slots together: one per kept cell, 8^k <= count per split one.
            const uint64_t numSlots = uint64_t(ix.n) + ix.numCells;
            gpu::requireWithin(numSlots, uint64_t(UINT32_MAX), "slots of a leaf split", "2^32 - 1");
            Buffer& slotBase = buf("slotBase", VkDeviceSize(ix.numCells) * 4);
            Buffer& dense = buf("slotDense", VkDeviceSize(numSlots) * 4);
            Buffer* outCells = leaves[round % 2];
            counter<uint32_t>(RTHDIST_CTR_MAX_COUNT) = 0;
            counter<uint32_t>(RTHDIST_CTR_LARGE_CELLS) = 0;
            VkCommandBuffer cmd = ctx.begin();
            sh::SplitPush sp{cells->address(),
                             slotBase.address(),
                             sorted[cur]->address(),
                             gridKeys[cur]->address(),
                             dense.address(),
                             slotKeys.address(),
                             sorted[1 - cur]->address(),
                             gridKeys[1 - cur]->address(),
                             outSlotKeys.address(),
                             blocks[0].addr(RTHDIST_CTR_MIN_EDGE),
                             ix.numCells,
                             ix.n,
                             kLeafMax};
            dispatch(cmd, Kernel::kLeafSlots, sp, ix.numCells);
            vkCmdFillBuffer(cmd, dense.handle(), 0, VkDeviceSize(numSlots) * 4, 0);
            barrier(cmd);
            cmdScan(cmd, slotBase.address(), ix.numCells, "scanSlots", 0);
            barrier(cmd);
            dispatch(cmd, Kernel::kLeafKeys, sp, ix.n);
            barrier(cmd);
            cmdScan(cmd, dense.address(), uint32_t(numSlots), "scanDense", 0);
            barrier(cmd);
            dispatch(cmd, Kernel::kLeafScatter, sp, ix.n);
            barrier(cmd);
            sh::CellsPush cp{sorted[1 - cur]->address(),
                             outSlotKeys.address(),
                             flags.address(),
                             dense.address(),
                             outCells->address(),
                             cellsCounterAddr(),
                             maxCountAddr(),
                             boundsU(n).address(),
                             blocks[0].addr(RTHDIST_CTR_LARGE_CELLS),
                             ix.n,
                             ix.n};
            dispatch(cmd, Kernel::kCellHeads, cp, ix.n);
            barrier(cmd);
            cmdScan(cmd, flags.address(), ix.n, "scanFlags", 0);
            barrier(cmd);
            cmdCellBuild(cmd, cp);
            ctx.submitAndWait(cmd);
            timings->gpuIndex += ctx.lastGpuMs();
            cur = 1 - cur;
            cells = outCells;
            ix.numCells = counter<uint32_t>(RTHDIST_CTR_CELLS);
            if (counter<uint32_t>(RTHDIST_CTR_MAX_COUNT) <= kLeafMax) break;
        }
        ix.sorted = sorted[cur];
        ix.sortedKeys = gridKeys[cur];
        ix.cells = cells;
        ix.split = true;
        const float edge = std::bit_cast<float>(counter<uint32_t>(RTHDIST_CTR_MIN_EDGE));
        ix.minEdge = std::isfinite(edge) ? double(edge) : 0.0;
        VkCommandBuffer cmd = ctx.begin();
        cmdCheckIndex(cmd, ix, blocks[0]);
        ctx.submitAndWait(cmd);
        verifyIndex(ix, ix.n, blocks[0]);
    }

    // Search cells of level `level` (>= 1) of T, coarsened from the level
    // below on first use (coarsen.comp: head flags, scan, build).
    const PointIndex::Level& searchLevel(PointIndex& T, int level) {
        while (int(T.levels.size()) < level) {
            const int j = int(T.levels.size()) + 1;
            Buffer* finer = j == 1 ? T.cells : T.levels.back().cells;
            Buffer* finerFineFirst = j == 1 ? T.cells : T.levels.back().fineFirst;  // unused at j = 1
            const uint32_t numFiner = j == 1 ? T.numCells : T.levels.back().count;
            const std::string tag = ".level" + std::to_string(j);
            PointIndex::Level lv;
            lv.cells = &setBuf(T, tag, VkDeviceSize(numFiner) * sizeof(sh::Cell));
            lv.fineFirst = &setBuf(T, tag + ".fineFirst", VkDeviceSize(numFiner) * 4);
            Buffer& flags = buf("coarseFlags", VkDeviceSize(numFiner) * 4);
            auto t0 = Clock::now();
            VkCommandBuffer cmd = ctx.begin();
            sh::CoarsenPush co{finer->address(),
                               T.sortedKeys->address(),
                               flags.address(),
                               lv.cells->address(),
                               cellsCounterAddr(),
                               finerFineFirst->address(),
                               lv.fineFirst->address(),
                               numFiner,
                               0,
                               uint32_t(3 * j)};
            dispatch(cmd, Kernel::kCoarsen, co, numFiner);
            barrier(cmd);
            cmdScan(cmd, flags.address(), numFiner, "scanCoarse", 0);
            barrier(cmd);
            co.mode = 1;
            dispatch(cmd, Kernel::kCoarsen, co, numFiner);
            ctx.submitAndWait(cmd);
            timings->gpuIndex += ctx.lastGpuMs();
            timings->index += msSince(t0);
            lv.count = counter<uint32_t>(RTHDIST_CTR_CELLS);
            T.levels.push_back(lv);
        }
        return T.levels[size_t(level - 1)];
    }

    // One ray per active slot, in traces of at most maxRayDispatch rays
    // (each trace sees its first slot in SearchPush::slotBase).
    void cmdTraceRaysSplit(VkCommandBuffer cmd, sh::SearchPush sp) {
        const uint64_t chunk = std::max<uint64_t>(1, ctx.limits().maxRayDispatch);
        for (uint64_t first = 0; first < sp.numActive; first += chunk) {
            sp.slotBase = uint32_t(first);
            pipelines.cmdTraceRays(cmd, &sp, sizeof(sp),
                                   uint32_t(std::min<uint64_t>(chunk, sp.numActive - first)));
        }
    }

    // Scratch of the parallel box reduction of large cells (6 uints per cell).
    Buffer& boundsU(uint64_t cellCapacity) { return buf("boundsU", VkDeviceSize(cellCapacity) * 24); }

    // One Cell per run of equal keys (heads flagged and scanned before):
    // small cells' boxes by their head thread, large cells' in parallel.
    void cmdCellBuild(VkCommandBuffer cmd, const sh::CellsPush& cp) {
        dispatch(cmd, Kernel::kCellBuild, cp, cp.n);
        barrier(cmd);
        dispatch(cmd, Kernel::kCellBounds, cp, cp.n);
        barrier(cmd);
        dispatch(cmd, Kernel::kCellBoundsFix, cp, cp.cellCapacity);
    }

    // Self-check of an index, recorded after its build (check_index.comp);
    // verifyIndex reads the verdict once the submission has completed.
    void cmdCheckIndex(VkCommandBuffer cmd, const PointIndex& ix, const CounterBlock& blk) {
        blk.at<uint64_t>(RTHDIST_CTR_CHECK_SUM) = 0;
        blk.at<uint64_t>(RTHDIST_CTR_CHECK_BAD) = 0;
        sh::CheckPush cp{
            ix.sorted->address(), ix.sortedKeys->address(), 0, blk.device, gridParams(ix.grid), ix.n, 0u};
        dispatch(cmd, Kernel::kCheckIndex, cp, ix.n);
    }
    void verifyIndex(const PointIndex& ix, uint64_t cellCapacity, const CounterBlock& blk) {
        const uint64_t n = ix.n;
        const uint64_t expectedSum = n % 2 == 0 ? (n / 2) * (n - 1) : n * ((n - 1) / 2);
        std::string why = indexCheckFailure(n, blk.at<uint64_t>(RTHDIST_CTR_CHECK_BAD),
                                            blk.at<uint64_t>(RTHDIST_CTR_CHECK_SUM), expectedSum, ix.numCells,
                                            cellCapacity);
        if (!why.empty()) throw SelfCheckError("index of " + ix.name + ": " + why);
    }

    // Reports progress (the fraction of the whole call), then honours the
    // cancel flag: a cancelled call unwinds to the guard (kCancelled).
    void report(const CallOptions& options, const char* stage, double fraction) {
        if (options.progress) options.progress(stage, std::clamp(fraction, 0.0, 1.0));
        throwIfCancelled(options);
    }

    // What the stages of one direction h(Q, T) share. Each direction of a
    // pair counts into a counter block of its own and keeps its query states
    // in buffers of its own (tag), so both can be culled in one submission.
    struct DirectionRun {
        const PointIndex& Q;
        PointIndex& T;
        std::span<const glm::vec3> qPts, tPts;  // the host's copies of what the device holds
        const CounterBlock& blk;
        PerPoint* perPoint = nullptr;
        Directed out;
        double lowerBound2Exact = 0.0;  // the boxes' bound (double), for the witness check
        float lowerBound2 = 0.0f;       // < 0: per-point (no early break)
        float epsilon = 0.0f;
        Buffer* state = nullptr;                 // QueryState per query slot
        Buffer* active[2] = {nullptr, nullptr};  // active slots, ping-pong
        int cur = 0;                             // active[cur] holds this iteration's slots
        std::vector<uint32_t> checkSlots;        // the self-check's sampled query slots
        [[nodiscard]] std::string name() const { return Q.name + "->" + T.name; }
    };

    // Sets up h(Q, T) (Q's points in Q's cell order are the queries): its
    // bounds, epsilon and buffers; nothing is recorded.
    void startDirection(DirectionRun& d, const std::string& tag) {
        Counters& cnt = d.out.counters;
        cnt.bits = uint32_t(d.T.grid.bits);
        cnt.occupiedCells = d.T.numCells;
        cnt.queries = d.Q.n;
        // Witness-less lower bound from the two boxes alone (no pass over the
        // points): each face of Q's tight box holds a query, whose distance
        // to BV(T), hence to T, is at least that face's excess over T's box
        // on its axis. Shrunk a little so float rounding never kills the
        // query that realizes h.
        d.lowerBound2Exact = boxLowerBound2(d.Q.bounds, d.T.bounds);
        // Per-point distances need every query's NN: a negative bound turns
        // the early break off in every shader (deadThreshold returns 0).
        d.lowerBound2 = d.perPoint ? -1.0f : float(d.lowerBound2Exact * (1.0 - 1e-5));
        double maxAbs = 0.0;
        for (const Bounds* b : {&d.Q.bounds, static_cast<const Bounds*>(&d.T.bounds)})
            maxAbs = std::max({maxAbs, std::abs(b->lo.x), std::abs(b->lo.y), std::abs(b->lo.z),
                               std::abs(b->hi.x), std::abs(b->hi.y), std::abs(b->hi.z)});
        d.epsilon = float(maxAbs * 4e-7 + d.T.grid.cellSize * 1e-5);
        d.state = &buf(tag + ".state", VkDeviceSize(d.Q.n) * sizeof(sh::QueryState));
        d.active[0] = &buf(tag + ".active0", VkDeviceSize(d.Q.n) * 4);
        d.active[1] = &buf(tag + ".active1", VkDeviceSize(d.Q.n) * 4);
        d.checkSlots = sampleSlots(d.Q.n, kCheckSamples);
    }

    // Records the neighbourhood pass and the compaction of the survivors
    // (their slots in active[0], their count at RTHDIST_CTR_ACTIVE).
    void cmdCull(VkCommandBuffer cmd, DirectionRun& d) {
        std::memset(d.blk.host, 0, 32);  // ACTIVE .. PAIRS
        sh::CullPush cull{d.Q.sorted->address(),
                          d.T.sorted->address(),
                          d.T.dense->address(),
                          d.state->address(),
                          d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                          gridParams(d.T.grid),
                          d.Q.n,
                          d.lowerBound2,
                          d.epsilon,
                          0u,             // search cells are coarser than the block's cells
                          kCrowdedCell};  // past it: split leaves, or copies of one point
        dispatch(cmd, Kernel::kCull, cull, d.Q.n);
        barrier(cmd);
        sh::CompactPush comp{d.state->address(),
                             d.active[0]->address(),
                             d.blk.device,
                             d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                             d.Q.n,
                             d.lowerBound2};
        dispatch(cmd, Kernel::kCompact, comp, d.Q.n);
    }

    // Records the self-check of a direction (check_queries.comp: every query
    // settled below the final maximum, the witness's records copied by the
    // shader) and the copies of the sampled queries' records into the
    // block's read-back area. Recorded right after the cull, it is the
    // direction's check when no query survives the cull (no extra
    // submission); otherwise (afterCull: the shader then returns at once) it
    // is recorded again after the search.
    void cmdCheckQueries(VkCommandBuffer cmd, const DirectionRun& d, bool afterCull) {
        d.blk.at<uint64_t>(RTHDIST_CTR_CHECK_BAD) = 0;
        const VkDeviceSize readback = d.blk.offset + RTHDIST_CTR_READBACK;
        const VkDeviceSize witnessAt = readback + VkDeviceSize(d.checkSlots.size()) * 32;
        sh::CheckPush cp{d.Q.sorted->address(),
                         0,
                         d.state->address(),
                         d.blk.device,
                         {},
                         d.Q.n,
                         d.perPoint ? 1u : 0u,
                         hostSmall.address() + witnessAt,
                         afterCull ? 1u : 0u,
                         0u};
        dispatch(cmd, Kernel::kCheckQueries, cp, d.Q.n);
        std::vector<VkBufferCopy> sortedCopies, stateCopies;
        for (size_t k = 0; k < d.checkSlots.size(); ++k) {
            const VkDeviceSize at = readback + VkDeviceSize(k) * 32;
            sortedCopies.push_back({VkDeviceSize(d.checkSlots[k]) * 16, at, 16});
            stateCopies.push_back({VkDeviceSize(d.checkSlots[k]) * sizeof(sh::QueryState), at + 16, 16});
        }
        vkCmdCopyBuffer(cmd, d.Q.sorted->handle(), hostSmall.handle(), uint32_t(sortedCopies.size()),
                        sortedCopies.data());
        vkCmdCopyBuffer(cmd, d.state->handle(), hostSmall.handle(), uint32_t(stateCopies.size()),
                        stateCopies.data());
    }

    // The self-check's verdict once its submission completed: every query
    // settled, the sampled records and the witness's agree with the host's
    // copy of the points. Returns the witness's records (the query slot of
    // the maximum).
    SampledQuery finishCheck(const DirectionRun& d) {
        const uint64_t packed = d.blk.at<uint64_t>(RTHDIST_CTR_MAX_PACKED);
        const char* readback = d.blk.host + RTHDIST_CTR_READBACK;
        std::vector<SampledQuery> sampled(d.checkSlots.size() + 1);
        for (size_t k = 0; k < sampled.size(); ++k) {
            sampled[k].slot = k < d.checkSlots.size() ? d.checkSlots[k] : uint32_t(packed & 0xffffffffu);
            std::memcpy(sampled[k].sorted, readback + k * 32, 16);
            std::memcpy(&sampled[k].state, readback + k * 32 + 16, 16);
        }
        const uint64_t bad = d.blk.at<uint64_t>(RTHDIST_CTR_CHECK_BAD);
        std::string why = bad != 0
                              ? std::to_string(bad) + " of " + std::to_string(d.Q.n) +
                                    " queries ended unsettled or above the maximum"
                              : sampledQueryFailure(sampled, d.qPts, d.tPts, packed, d.perPoint != nullptr);
        if (!why.empty()) throw SelfCheckError(d.name() + ": " + why);
        return sampled.back();
    }

    // The direction's result from its checked witness (and its per-point
    // distances).
    Directed finishDirection(DirectionRun& d, const SampledQuery& witness) {
        Directed& out = d.out;
        out.queryIndex = std::bit_cast<uint32_t>(witness.sorted[3]);
        out.targetIndex = uint32_t(witness.state.best & 0xffffffffu);
        out.queryPoint = d.qPts[out.queryIndex];
        out.targetPoint = d.tPts[out.targetIndex];
        out.distance = glm::length(glm::dvec3(out.queryPoint) - glm::dvec3(out.targetPoint));
        std::string why = witnessFailure(out.distance, d.blk.at<uint64_t>(RTHDIST_CTR_MAX_PACKED),
                                         std::sqrt(d.lowerBound2Exact));
        if (!why.empty()) throw SelfCheckError(d.name() + ": " + why);
        if (d.perPoint) readPerPoint(d.Q, *d.state, d.qPts, d.tPts, *d.perPoint);
        return out;
    }

    // The culls of the directions (one or two) in one submission, each
    // followed by its self-check; returns each direction's survivors.
    template <size_t N>
    std::array<uint32_t, N> runCulls(const std::array<DirectionRun*, N>& dirs) {
        const auto t0 = Clock::now();
        VkCommandBuffer cmd = ctx.begin();
        for (DirectionRun* d : dirs) cmdCull(cmd, *d);
        barrier(cmd);
        const uint32_t culled = ctx.cmdMark(cmd);
        for (DirectionRun* d : dirs) cmdCheckQueries(cmd, *d, true);
        ctx.submitAndWait(cmd);
        timings->gpuCull += ctx.gpuMsBetween(0, culled);
        std::array<uint32_t, N> survivors{};
        for (size_t k = 0; k < N; ++k) {
            survivors[k] = dirs[k]->blk.template at<uint32_t>(RTHDIST_CTR_ACTIVE);
            dirs[k]->out.counters.survivingQueries = survivors[k];
            dirs[k]->out.counters.culledByNeighbourhood = dirs[k]->Q.n - survivors[k];
        }
        timings->cull += msSince(t0);
        return survivors;
    }

    // The search of a direction that has survivors, then its self-check
    // (one more submission); returns the checked witness.
    SampledQuery searchAndCheck(DirectionRun& d, uint32_t survivors, const CallOptions& options,
                                double progressFrom, double progressTo) {
        runSearch(d, survivors, options, progressFrom, progressTo);
        const auto t0 = Clock::now();
        VkCommandBuffer cmd = ctx.begin();
        cmdCheckQueries(cmd, d, false);
        ctx.submitAndWait(cmd);
        SampledQuery witness = finishCheck(d);
        timings->check += msSince(t0);
        return witness;
    }

    // Candidate search with a growing radius until no query is active.
    void runSearch(DirectionRun& d, uint32_t numActive, const CallOptions& options, double progressFrom,
                   double progressTo) {
        const PointIndex& T = d.T;
        // Small first radius, grown geometrically: measured against starting
        // at the threshold's root, which makes every ray visit far more boxes
        // (docs/bench/gpu.md, growth sweep).
        double radius = 2.0 * T.grid.cellSize;
        // Leaves: start at half the narrowest split sub-cell's edge, about the
        // nearest-neighbour spacing of ~8 points per sub-cell (measured on
        // lavapipe, cluster + outlier: 2x the edge made rays visit ~4x more
        // leaves, 1/4 cost an iteration); the growth reaches the grid's scale
        // in a few iterations.
        if (T.split && T.minEdge > 0.0) radius = std::min(radius, 0.5 * T.minEdge);
        // Room for ~4 pairs per cell, or per query when a split index sends
        // the crowded regions' queries to the search (a full buffer costs a
        // repeated iteration).
        const uint64_t pairBase = std::max<uint64_t>(T.numCells, T.split ? numActive : 0u);
        uint64_t pairCapacity =
            std::min(std::clamp<uint64_t>(pairBase * 4, 1u << 16, 1u << 22), maxPairCapacity);
        Buffer* pairs = nullptr;
        int builtLevel = -1;  // level of the BLAS now built (-1: none yet)
        while (numActive > 0) {
            if (++d.out.counters.iterations > kMaxIterations)
                throw std::runtime_error("candidate search did not converge");
            if (!pairs) {
                pairs = &buf("pairs", pairCapacity * 8);
                pairCapacity = std::min<uint64_t>(pairs->size() / 8, maxPairCapacity);
            }
            const int level = searchLevelFor(T, radius);
            const IterationCounts counts =
                iterate(d, level, level == builtLevel, radius, *pairs, pairCapacity, numActive);
            const uint64_t pairCount = counts.pairs;
            builtLevel = level;
            numActive = counts.stillOpen;
            report(options, "search",
                   progressFrom + (progressTo - progressFrom) *
                                      (0.2 + 0.8 * (1.0 - double(numActive) /
                                                              double(std::max<uint64_t>(
                                                                  1, d.out.counters.survivingQueries)))));
            if (pairCount > pairCapacity && pairCapacity < maxPairCapacity) {
                // Some queries lost pairs: redo them at the same radius with room.
                pairCapacity =
                    std::min<uint64_t>(maxPairCapacity, std::max<uint64_t>(pairCount, pairCapacity * 2));
                pairs = nullptr;
            } else if (pairCount <= pairCapacity) {
                radius *= double(options.radiusGrowth);
            }
        }
    }

    // Search cells about an eighth of the radius wide: level j with
    // s * 2^j <= R / 8, at least 1, at most bits - 1. Wider cells mean fewer
    // boxes per ray but longer scans in the refinement; R/2 and R/4 were
    // slower overall on the lavapipe scenarios (README). A split index
    // searches its leaves (level 0) until level 1 is due.
    static int searchLevelFor(const PointIndex& T, double radius) {
        const int wanted = int(std::floor(std::log2(radius / (8.0 * T.grid.cellSize))));
        return T.split && wanted < 1 ? 0 : std::clamp(wanted, 1, std::max(1, T.grid.bits - 1));
    }

    // The search cells of `level` (0: the index's own cells or leaves).
    PointIndex::Level levelCells(PointIndex& T, int level) {
        return level > 0 ? searchLevel(T, level) : PointIndex::Level{T.cells, nullptr, T.numCells};
    }

    // What one radius of the search reported.
    struct IterationCounts {
        uint64_t pairs = 0;      // (query, cell) pairs the rays appended (some may not fit)
        uint32_t stillOpen = 0;  // queries going on to the next radius (or retrying)
    };

    // One radius in one submission: the search (cmdSearch), then the
    // refinement sized by the device from the pairs the rays appended
    // (cmdRefine, indirect dispatch), then the resolution of every active
    // query. The host reads the counts once, at the end.
    IterationCounts iterate(DirectionRun& d, int level, bool sameLevel, double radius, Buffer& pairs,
                            uint64_t pairCapacity, uint32_t numActive) {
        const PointIndex::Level lv = levelCells(d.T, level);
        const auto t0 = Clock::now();
        d.blk.at<uint64_t>(RTHDIST_CTR_PAIRS) = 0;
        d.blk.at<uint32_t>(RTHDIST_CTR_NEXT_ACTIVE) = 0;
        VkCommandBuffer cmd = ctx.begin();
        cmdSearch(cmd, d, lv, sameLevel, radius, pairs, pairCapacity, numActive);
        const uint32_t searched = ctx.cmdMark(cmd);
        barrier(cmd);
        cmdRefine(cmd, d, lv, level > 0, float(radius), pairs, pairCapacity, numActive);
        ctx.submitAndWait(cmd);
        const double searchGpu = ctx.gpuMsBetween(0, searched), allGpu = ctx.lastGpuMs();
        timings->gpuSearch += searchGpu;
        timings->gpuRefine += allGpu - searchGpu;
        // The wall time split between the two stages as their device time is.
        const double wall = msSince(t0), searchShare = allGpu > 0.0 ? searchGpu / allGpu : 1.0;
        timings->search += wall * searchShare;
        timings->refine += wall * (1.0 - searchShare);
        d.out.counters.rays += numActive;
        IterationCounts counts{d.blk.at<uint64_t>(RTHDIST_CTR_PAIRS),
                               d.blk.at<uint32_t>(RTHDIST_CTR_NEXT_ACTIVE)};
        d.out.counters.candidatePairs += std::min<uint64_t>(counts.pairs, pairCapacity);
        d.cur = 1 - d.cur;
        return counts;
    }

    // Records the search of one radius: the level's boxes grown by the
    // radius, the BLAS refitted (same level) or rebuilt, one ray per active
    // query; the rays append (query, cell) pairs.
    void cmdSearch(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool sameLevel,
                   double radius, Buffer& pairs, uint64_t pairCapacity, uint32_t numActive) {
        PointIndex& T = d.T;
        const float r = float(radius);
        // The ray only has to start inside the grown boxes: a short one
        // crosses few other boxes (leaves are far smaller than grid cells).
        const float rayTMax = float(std::min(T.grid.cellSize, T.split ? radius : T.grid.cellSize) * 1e-3);
        Buffer& aabbs = buf("aabbs", VkDeviceSize(lv.count) * 24);
        // Per-box slack: float rounding at the box's magnitude (the old
        // global epsilon used the largest coordinate of both sets) plus,
        // for a grid index, the grid's absolute term.
        sh::BoxesPush bp{
            lv.cells->address(), aabbs.address(), lv.count,
            r + r * 1e-6f,       4e-7f,           T.split ? 0.0f : float(T.grid.cellSize * 1e-5)};
        dispatch(cmd, Kernel::kGrowBoxes, bp, lv.count);
        gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_SHADER_READ_BIT);
        // Same cells: the boxes only grew, so refit; new level: rebuild.
        if (accel.cmdBuild(cmd, aabbs.address(), lv.count, sameLevel, pipelines.shaderStages()) ||
            !tlasBound) {
            pipelines.bindTlas(accel.tlas());
            tlasBound = true;
        }
        sh::SearchPush sp{d.Q.sorted->address(),
                          T.sorted->address(),
                          lv.cells->address(),
                          d.state->address(),
                          d.active[d.cur]->address(),
                          pairs.address(),
                          d.blk.device,
                          d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                          numActive,
                          uint32_t(pairCapacity),
                          r,
                          d.lowerBound2,
                          rayTMax,
                          sameLevel ? 1u : 0u,
                          0u};
        if (rayQuery)
            dispatch(cmd, Kernel::kSearchRayQuery, sp, numActive);
        else
            cmdTraceRaysSplit(cmd, sp);
    }

    // Records the refinement of one radius: the pairs that fit are scanned
    // exactly (as many groups as the device counted pairs for), then every
    // active query is resolved (exact, dead, or on to the next radius) into
    // the other active buffer.
    void cmdRefine(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool coarse, float r,
                   Buffer& pairs, uint64_t pairCapacity, uint32_t numActive) {
        Buffer& args = buf("refineArgs", 16);
        sh::RefineArgsPush ap{d.blk.device, args.address(), uint32_t(pairCapacity),
                              std::max<uint32_t>(1, ctx.limits().maxGroupsX)};
        pipelines.cmdDispatch(cmd, Kernel::kRefineArgs, &ap, sizeof(ap), 1);
        gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
        sh::RefinePush rp{d.Q.sorted->address(),
                          d.T.sorted->address(),
                          lv.cells->address(),
                          d.state->address(),
                          d.active[d.cur]->address(),
                          pairs.address(),
                          d.blk.device,
                          d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                          d.T.cells->address(),
                          coarse ? lv.fineFirst->address() : 0,
                          uint32_t(pairCapacity),
                          d.lowerBound2,
                          lv.count,
                          d.T.numCells};
        pipelines.cmdDispatchIndirect(cmd, Kernel::kRefine, &rp, sizeof(rp), args.handle(), 0);
        barrier(cmd);
        sh::ResolvePush rs{d.state->address(),
                           d.active[d.cur]->address(),
                           d.active[1 - d.cur]->address(),
                           d.blk.device,
                           d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                           numActive,
                           r,
                           d.lowerBound2};
        dispatch(cmd, Kernel::kResolve, rs, numActive);
    }

    // Every query is EXACT after a per-point run: its state holds its NN.
    void readPerPoint(const PointIndex& Q, const Buffer& state, std::span<const glm::vec3> qPts,
                      std::span<const glm::vec3> tPts, PerPoint& out) {
        const VkDeviceSize stateBytes = VkDeviceSize(Q.n) * sizeof(sh::QueryState);
        const VkDeviceSize pointBytes = VkDeviceSize(Q.n) * 16;
        Buffer& host = buf("readback", stateBytes + pointBytes, MemoryKind::kHost);
        VkCommandBuffer cmd = ctx.begin();
        VkBufferCopy c1{0, 0, stateBytes};
        vkCmdCopyBuffer(cmd, state.handle(), host.handle(), 1, &c1);
        VkBufferCopy c2{0, stateBytes, pointBytes};
        vkCmdCopyBuffer(cmd, Q.sorted->handle(), host.handle(), 1, &c2);
        ctx.submitAndWait(cmd);
        const auto* states = static_cast<const sh::QueryState*>(host.mapped());
        const auto* sorted =
            reinterpret_cast<const float*>(static_cast<const char*>(host.mapped()) + stateBytes);
        out.distance.assign(Q.n, 0.0);
        out.nearest.assign(Q.n, 0);
        for (uint32_t i = 0; i < Q.n; ++i) {
            const uint32_t qi = std::bit_cast<uint32_t>(sorted[4 * i + 3]);
            const uint32_t ti = uint32_t(states[i].best & 0xffffffffu);
            if (qi >= qPts.size() || ti >= tPts.size() || states[i].status != RTHDIST_EXACT)
                throw std::runtime_error("per-point read-back: query " + std::to_string(i) +
                                         " has no exact NN");
            out.nearest[qi] = ti;
            out.distance[qi] = glm::length(glm::dvec3(qPts[qi]) - glm::dvec3(tPts[ti]));
        }
    }

    // Stages `input` (float, before the scale) as set `name` for an index
    // build: in the pool (one-shot) or in buffers of its own (owned: a
    // prepared set). The host pass counts as upload time.
    void stageSet(DeviceSet& set, std::span<const glm::vec3> input, double scale, int bits,
                  const std::string& name, const std::string& scratch, bool owned = false) {
        const auto t0 = Clock::now();
        set.input = input;
        set.scale = scale;
        if (scale != 1.0) set.scaledCopy = scaledCopy(input, scale);
        set.points = scale != 1.0 ? std::span<const glm::vec3>(set.scaledCopy) : input;
        set.ix.name = name;
        set.ix.scratch = scratch;
        set.ix.owned = owned;
        set.ix.store = owned ? &set.own : &pool;
        stageIndex(set.ix, set.points, bits);
        timings->upload += msSince(t0);
    }

    // A prepared set keeps only the buffers its index uses after a leaf split.
    static void releaseUnused(DeviceSet& set) {
        for (auto it = set.own.begin(); it != set.own.end();) {
            const Buffer* b = &it->second;
            const bool used =
                b == set.ix.sorted || b == set.ix.dense || b == set.ix.cells || b == set.ix.sortedKeys;
            it = used ? std::next(it) : set.own.erase(it);
        }
    }

    // One-shot H of two packed float host arrays through the ingest path:
    // one submission uploads and ingests both, the host reads their bounds
    // (the grid and the bit count need them), a second builds both indexes.
    // Returns false, having done nothing else, when the sets need the exact
    // power-of-two scale (index_space.hpp), which the host path applies.
    bool ingestPair(DeviceSet& da, DeviceSet& db, std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                    const CallOptions& options) {
        const auto t0 = Clock::now();
        std::array<DeviceSet*, 2> sets = {&da, &db};
        std::array<std::span<const glm::vec3>, 2> inputs = {a, b};
        for (size_t k = 0; k < 2; ++k) {
            DeviceSet& set = *sets[k];
            set.input = set.points = inputs[k];
            set.ix.name = set.ix.scratch = k == 0 ? "A" : "B";
            set.ix.store = &pool;
            stageSource(set.ix, inputs[k]);
        }
        VkCommandBuffer cmd = ctx.begin();
        for (DeviceSet* set : sets) cmdUploadSource(cmd, set->ix);
        const uint32_t uploaded = ctx.cmdMark(cmd);
        barrier(cmd);
        for (size_t k = 0; k < 2; ++k) cmdIngest(cmd, sets[k]->ix, blocks[k]);
        ctx.submitAndWait(cmd);
        imports.clear();  // the device has read the caller's arrays
        const double uploadMs = ctx.gpuMsBetween(0, uploaded);
        timings->upload += msSince(t0) - (ctx.lastGpuMs() - uploadMs);
        timings->gpuUpload += uploadMs;
        timings->gpuIndex += ctx.lastGpuMs() - uploadMs;
        for (size_t k = 0; k < 2; ++k) finishIngest(sets[k]->ix, blocks[k]);
        const double magnitude = std::max(largestMagnitude(da.ix.bounds), largestMagnitude(db.ix.bounds));
        if (exactScale(magnitude) != 1.0) return false;
        const auto t1 = Clock::now();
        chooseIngestedGrids({&da.ix, &db.ix}, inputs, options.bits);
        timings->index += msSince(t1);
        buildIndexes(std::array{&da.ix, &db.ix}, /*uploaded=*/true);
        return true;
    }

    // One-shot H of two float sets through the host path: each staged by
    // the host (vec4 copy, bounds, bit count), uploaded and indexed. Small
    // sets: both in one submission (scratch of their own). Large ones: one
    // after the other in the same scratch (a submission is then cheap beside
    // the work, and the device holds one set's scratch, not two).
    void hostPair(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double scale,
                  const CallOptions& options, HausdorffResult& res) {
        DeviceSet da, db;
        const bool together = a.size() + b.size() <= kFusedBuildPoints;
        stageSet(da, a, scale, options.bits, "A", together ? "A" : "build");
        if (!together) buildIndexes(std::array{&da.ix});
        stageSet(db, b, scale, options.bits, "B", together ? "B" : "build");
        report(options, "index", 0.05);
        if (together)
            buildIndexes(std::array{&da.ix, &db.ix});
        else
            buildIndexes(std::array{&db.ix});
        report(options, "index", 0.1);
        runPair(da, db, options, res, 0.1);
    }

    // H (or h) of two indexed sets of one scale into `res`; progress covers
    // [from, 1] of the call.
    void runPair(DeviceSet& a, DeviceSet& b, const CallOptions& options, HausdorffResult& res, double from) {
        const bool pp = options.perPointDistances;
        const double mid = options.directedOnly ? 1.0 : from + 0.5 * (1.0 - from);
        DirectionRun ab{a.ix, b.ix, a.points, b.points, blocks[0], pp ? &res.aNearest : nullptr};
        DirectionRun ba{b.ix, a.ix, b.points, a.points, blocks[1], pp ? &res.bNearest : nullptr};
        startDirection(ab, "ab");
        if (!options.directedOnly) startDirection(ba, "ba");
        // Both culls (and their checks) in one submission; a direction with
        // survivors searches, then checks again.
        std::array<uint32_t, 2> survivors{};
        if (options.directedOnly)
            survivors[0] = runCulls(std::array{&ab})[0];
        else
            survivors = runCulls(std::array{&ab, &ba});
        report(options, "cull", from + 0.2 * (1.0 - from));
        const auto directed = [&](DirectionRun& d, uint32_t n, double lo, double hi) {
            const SampledQuery witness = n > 0 ? searchAndCheck(d, n, options, lo, hi) : finishCheck(d);
            const auto t0 = Clock::now();
            Directed out = finishDirection(d, witness);
            timings->check += msSince(t0);
            return out;
        };
        res.aToB = directed(ab, survivors[0], from, mid);
        res.hausdorff = res.aToB.distance;
        if (!options.directedOnly) {
            res.bToA = directed(ba, survivors[1], mid, 1.0);
            res.hausdorff = std::max(res.hausdorff, res.bToA.distance);
        }
        // Witnesses and per-point distances from the unscaled inputs, in double.
        if (a.scale != 1.0) restoreOriginal(res, PointView(a.input), PointView(b.input));
    }

    HausdorffResult emptyResult(const CallOptions& options) const {
        HausdorffResult res;
        res.backend = ctx.backend();
        res.device = ctx.deviceName();
        res.directedOnly = options.directedOnly;
        return res;
    }

    // Runs `work` with its timings in `timings`, and turns what it throws
    // into the error codes of the API (the accel structures are dropped, so
    // the next call starts clean).
    template <class Work>
    std::optional<Error> guarded(Timings& into, Work&& work) {
        timings = &into;
        std::optional<Error> err;
        try {
            work();
        } catch (const InputRejected& e) {
            err = e.error;
        } catch (const CallCancelled&) {
            err = Error{ErrorCode::kCancelled, "the call was cancelled (CallOptions::cancel)"};
        } catch (const gpu::VulkanError& e) {
            const bool oom =
                e.result() == VK_ERROR_OUT_OF_DEVICE_MEMORY || e.result() == VK_ERROR_OUT_OF_HOST_MEMORY;
            err = oom ? Error{ErrorCode::kOutOfMemory,
                              std::string("the inputs do not fit the device: ") + e.what()}
                      : Error{ErrorCode::kInternal, e.what()};
            err->vkResult = int(e.result());
        } catch (const gpu::LimitError& e) {
            err =
                Error{ErrorCode::kOutOfMemory, std::string("the inputs do not fit the device: ") + e.what()};
        } catch (const std::exception& e) {
            err = Error{ErrorCode::kInternal, e.what()};
        }
        timings = nullptr;
        imports.clear();  // never past the call: the caller may free its arrays
        if (err) {
            accel.release();
            tlasBound = false;
        }
        return err;
    }
};

GpuHausdorff::GpuHausdorff(std::unique_ptr<State> state) : m_state(std::move(state)) {}
GpuHausdorff::~GpuHausdorff() = default;

void GpuHausdorff::setMaxPairCapacity(uint64_t pairs) {
    m_state->maxPairCapacity = std::max<uint64_t>(1, pairs);
}

Result<std::unique_ptr<GpuHausdorff>> GpuHausdorff::create(gpu::Context& ctx, const std::string& cacheDir) {
    try {
        return std::unique_ptr<GpuHausdorff>(new GpuHausdorff(std::make_unique<State>(ctx, cacheDir)));
    } catch (const gpu::VulkanError& e) {
        return Error{ErrorCode::kInternal, std::string("pipeline creation failed: ") + e.what()};
    }
}

Result<HausdorffResult> GpuHausdorff::compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                              double scale, const CallOptions& options) {
    State& st = *m_state;
    HausdorffResult res = st.emptyResult(options);
    // Squared distances are float on the device: coordinates so large (or so
    // small) that they overflow (or underflow) are scaled by a power of two,
    // which is exact; values and witnesses are recomputed from the inputs.
    // Each set is indexed once with its own grid: as targets for the other
    // direction, and as cell-ordered (Morton) queries for its own.
    auto err = st.guarded(res.timings, [&] { st.hostPair(a, b, scale, options, res); });
    if (err) return *err;
    return res;
}

Result<HausdorffResult> GpuHausdorff::computePacked(std::span<const glm::vec3> a,
                                                    std::span<const glm::vec3> b,
                                                    const CallOptions& options) {
    State& st = *m_state;
    HausdorffResult res = st.emptyResult(options);
    auto err = st.guarded(res.timings, [&] {
        DeviceSet da, db;
        if (!st.ingestPair(da, db, a, b, options)) {
            // Coordinates past 2^40 or below 2^-40: the host path scales them.
            const double magnitude = std::max(largestMagnitude(da.ix.bounds), largestMagnitude(db.ix.bounds));
            st.hostPair(a, b, exactScale(magnitude), options, res);
            return;
        }
        st.report(options, "index", 0.1);
        st.runPair(da, db, options, res, 0.1);
    });
    if (err) return *err;
    return res;
}

bool GpuHausdorff::ingests(size_t aPoints, size_t bPoints) { return aPoints + bPoints <= kFusedBuildPoints; }

Result<HausdorffResult> GpuHausdorff::compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                              const CallOptions& options) {
    return compute(a, b, exactScale(std::max(largestMagnitude(a), largestMagnitude(b))), options);
}

Result<std::shared_ptr<DeviceSet>> GpuHausdorff::prepare(std::span<const glm::vec3> points, double scale,
                                                         int bits, const std::string& name,
                                                         Timings& timings) {
    auto set = std::make_shared<DeviceSet>();
    auto err = m_state->guarded(timings, [&] {
        m_state->stageSet(*set, points, scale, bits, name, "build", true);
        m_state->buildIndexes(std::array{&set->ix});
        State::releaseUnused(*set);
    });
    if (err) return *err;
    return set;
}

Result<HausdorffResult> GpuHausdorff::compute(DeviceSet& a, DeviceSet& b, const CallOptions& options) {
    HausdorffResult res = m_state->emptyResult(options);
    auto err = m_state->guarded(res.timings, [&] {
        throwIfCancelled(options);
        m_state->runPair(a, b, options, res, 0.0);
    });
    if (err) return *err;
    return res;
}

uint64_t GpuHausdorff::deviceBytes(const DeviceSet& set) {
    uint64_t bytes = 0;
    for (const auto& [name, buffer] : set.own) bytes += buffer.size();
    return bytes;
}

int GpuHausdorff::bits(const DeviceSet& set) { return set.ix.grid.bits; }

const std::string& GpuHausdorff::pipelineCachePath() const { return m_state->pipelineCache.path(); }
const std::string& GpuHausdorff::pipelineCacheStatus() const { return m_state->pipelineCache.loadStatus(); }

}  // namespace rthdist::algo
