// What every stage of the GPU algorithm shares on one device: the context,
// the pipelines and their cache, the acceleration structures, the
// host-visible counter blocks, the pool of scratch buffers, the timings of
// the call in flight; and the helpers every stage records with (barrier,
// dispatch, scan). One Workspace per GpuHausdorff: one caller at a time.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "core/stopwatch.hpp"
#include "gpu/accel.hpp"
#include "gpu/buffer.hpp"
#include "gpu/context.hpp"
#include "gpu/host_import.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu_algo/pipelines.hpp"
#include "gpu_algo/point_index.hpp"
#include "gpu_algo/scratch.hpp"
#include "gpu_algo/space_order.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist_shared.h"

namespace rthdist::gpu_algo {

using gpu::Kernel;
using gpu::MemoryKind;

using core::Clock;
using core::msSince;

inline constexpr uint64_t kMaxPairCapacity = uint64_t(1) << 26;  // 512 MiB of pairs at most
// Pooled buffers get this much room to grow (a quarter, at most 64 MiB, never
// past the device's largest buffer).
inline constexpr VkDeviceSize kMaxSlack = VkDeviceSize(64) << 20;
// Workspace::grow adopts a spare buffer only for a request this large: small
// buffers cost little to allocate, and a large spare is kept for a large request.
inline constexpr VkDeviceSize kAdoptMinBytes = VkDeviceSize(16) << 20;
// Query slots whose device records the self-check compares with the host.
inline constexpr uint32_t kCheckSamples = RTHDIST_CHECK_SAMPLES;
// Queries above its floor a per-point call with a floor hands back sparse
// (core/per_point_floor.hpp; 8 bytes each, on the device and read back); past
// it the dense array is read back instead.
inline constexpr uint32_t kAboveFloorCapacity = uint32_t(1) << 22;

// One block of the host-visible counters (offsets RTHDIST_CTR_* of
// rthdist_shared.h, the read-back area after them). The shaders find a
// counter at the block's address plus its offset, so two index builds in one
// submission each count into a block of their own.
struct CounterBlock {
    char* host = nullptr;
    VkDeviceAddress device = 0;
    VkDeviceSize offset = 0;  // in the buffer that holds the blocks
    // The counters (offsets asserted in rthdist_shared.h) and the ingest
    // summary, where the host zeroes and reads them.
    [[nodiscard]] sh::CounterFields& fields() const { return *reinterpret_cast<sh::CounterFields*>(host); }
    [[nodiscard]] sh::IngestSummary& ingest() const {
        return *reinterpret_cast<sh::IngestSummary*>(host + RTHDIST_CTR_INGEST);
    }
    [[nodiscard]] VkDeviceAddress addr(size_t offset) const { return device + offset; }
};
inline constexpr VkDeviceSize kCounterBlockBytes = RTHDIST_CTR_BYTES;
static_assert(RTHDIST_CTR_READBACK + (kCheckSamples + 1) * 32 <= RTHDIST_CTR_INGEST &&
              RTHDIST_CTR_INGEST + sizeof(sh::IngestSummary) <= kCounterBlockBytes);

// A call whose cancel flag was set: unwinds to the guard of the entry point.
struct CallCancelled {};

// Bad input found on the device (ingest.comp): unwinds to the guard, which
// returns it as it is.
struct InputRejected {
    Error error;
};

void throwIfCancelled(const CallOptions& options);

// Reports progress (the fraction of the whole call), then honours the
// cancel flag: a cancelled call unwinds to the guard (kCancelled).
void reportProgress(const CallOptions& options, const char* stage, double fraction);

struct Workspace {
    // Creates the pipelines (seeded from the cache file in cacheDir, which is
    // then saved) and the counter blocks. threads: the host's passes over the
    // points (EngineOptions::threads; 0: every hardware thread).
    Workspace(gpu::Context& c, const std::string& cacheDir, int threads, const Tuning& tuning);

    gpu::Context& ctx;
    Tuning tuning;                     // the Engine's (EngineOptions::tuning): read by the stages it tunes
    gpu::PipelineCache pipelineCache;  // before the pipelines it seeds
    gpu::Pipelines pipelines;
    gpu::AccelStructures accel;
    bool rayQuery;
    int threads;
    bool tlasBound = false;
    Buffer hostSmall;                    // the counter blocks (RTHDIST_CTR_*), read-backs after each
    std::array<CounterBlock, 2> blocks;  // blocks[0]: every stage; [1]: a second index build
    uint64_t maxPairCapacity = kMaxPairCapacity;
    uint32_t aboveFloorCapacity = kAboveFloorCapacity;  // a floor call's sparse list, at most
    uint32_t cullCellTests = kCullCellTests;            // 0: crowded cells give their first point only
    uint32_t leafGroupLeaves = kLeafGroupLeaves;        // leaves per group of a split index built next
    size_t chunkedUploadPoints = kChunkedUploadPoints;  // a larger host-staged set goes up in chunks
    size_t uploadChunkPoints = kUploadChunkPoints;
    size_t spaceOrderMinPoints =
        kMinSpaceOrderPoints;  // a smaller set's index build takes its points in order
    bool mutant = false;       // tests only: core::searchMutant() when the call started
    Timings* timings = nullptr;
    // Buffers live across calls and only grow: allocation is a large share of
    // a call's cost on discrete GPUs. oneShot: the indexes of one-shot sets A, B.
    Scratch scratch;
    std::array<SetBuffers, 2> oneShot;
    // The caller's arrays imported for the submission in flight (deque:
    // stable addresses for PointIndex::source).
    std::deque<gpu::HostImport> imports;

    // Buffers this call is done with (recycle): a later grow adopts one
    // instead of allocating. Device memory costs on both ends (allocation
    // and release run at ~40-50 GB/s on an H200: 1.7 s and 1.4 s of a
    // 300M x 400M call before), so the index builds' scratch and the leaf
    // split's spent ping-pong buffers become the directions' query states.
    std::vector<Buffer> spare;
    VkDeviceSize adoptMinBytes = kAdoptMinBytes;  // tests: 0, every request may adopt
    uint64_t adopted = 0;                         // spare buffers adopted so far (tests)

    // `b` with room for `bytes` at least: replaced (contents lost) when too
    // small, by a spare buffer of the same kind where one fits (at most
    // twice the size, the smallest such; not where exact sizes are asked),
    // else a new one with room to grow
    // (slack: a quarter more, at most kMaxSlack, never past the device's
    // largest buffer) unless exact sizes are asked. `name` labels it in GPU
    // captures and validation messages.
    Buffer& grow(Buffer& b, VkDeviceSize bytes, const std::string& name,
                 MemoryKind kind = MemoryKind::kDevice, bool slack = true);
    // Moves `b` (if it holds a buffer of at least adoptMinBytes) to `spare`:
    // nothing of this call reads or writes it again through any pointer, and
    // its slot is empty after. A smaller buffer stays in its slot (the
    // slot's next grow reuses it).
    void recycle(Buffer& b);
    // A build's scratch (points, keys, flags, boundsU) once its index is
    // built and checked: the leaf split and the next build adopt from it.
    void recycleBuild(BuildScratch& build);
    // Both builds' scratch and the leaf split's (LeafScratch), once every
    // index of the call is built: before the directions' buffers are grown.
    void recycleBuildScratch();
    // A buffer of set `ix`'s index (exact size for a prepared set).
    Buffer& setBuffer(PointIndex& ix, Buffer& b, const char* what, VkDeviceSize bytes) {
        return grow(b, bytes, ix.name + what, MemoryKind::kDevice, !ix.owned);
    }

    // A counter of block 0 (offsets from rthdist_shared.h): the stages run one at a time.
    [[nodiscard]] sh::CounterFields& counters() const { return blocks[0].fields(); }
    [[nodiscard]] VkDeviceAddress cellsCounterAddr() const { return blocks[0].addr(RTHDIST_CTR_CELLS); }
    [[nodiscard]] VkDeviceAddress maxCountAddr() const { return blocks[0].addr(RTHDIST_CTR_MAX_COUNT); }

    // Shader and transfer writes before the next shader or transfer reads.
    void barrier(VkCommandBuffer cmd) { gpu::cmdShaderBarrier(cmd, pipelines.shaderStages()); }

    // One thread per item (groups of groupSize), push constants `push`.
    template <class Push>
    void dispatch(VkCommandBuffer cmd, Kernel k, const Push& push, uint64_t items,
                  uint32_t groupSize = RTHDIST_WG) {
        pipelines.cmdDispatch(cmd, k, &push, sizeof(Push), gpu::groupsFor(items, groupSize));
    }

    // Whether one dispatch of RTHDIST_WG-thread groups holds `items` threads
    // (an indirect dispatch has no split into several).
    [[nodiscard]] bool oneDispatchHolds(uint32_t items) const {
        return gpu::groupsFor(items, RTHDIST_WG) <= ctx.limits().maxGroupsX;
    }

    // One thread per query the radius in flight searches: the groups
    // search_advance.comp (or the host, for a submission's first radius)
    // wrote at `blk`'s RTHDIST_CTR_SEARCH_ARGS, where one dispatch holds
    // `bound` queries; else `bound` threads, those past the device's count
    // returning at once.
    template <class Push>
    void dispatchSearched(VkCommandBuffer cmd, Kernel k, const Push& push, uint32_t bound,
                          const CounterBlock& blk) {
        if (oneDispatchHolds(bound))
            pipelines.cmdDispatchIndirect(cmd, k, &push, sizeof(Push), hostSmall.handle(),
                                          blk.offset + RTHDIST_CTR_SEARCH_ARGS);
        else
            dispatch(cmd, k, push, bound);
    }

    // Exclusive scan of uint[n] at `data`, recursively over block sums:
    // `sums` holds each level's; `name` labels them.
    void cmdScan(VkCommandBuffer cmd, VkDeviceAddress data, uint32_t n, ScanScratch& sums, const char* name,
                 size_t level = 0);
};

}  // namespace rthdist::gpu_algo
