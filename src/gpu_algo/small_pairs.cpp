#include "gpu_algo/small_pairs.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <string>

#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {

namespace {

constexpr uint64_t kMaxWorkGpu = uint64_t(1) << 28;
constexpr uint64_t kMaxWorkCpuDevice = uint64_t(1) << 20;

// A step coprime with n near n / golden ratio: the scan's order
// (j * step) mod n visits the cell-sorted targets spread over the set.
uint32_t spreadStep(uint32_t n) {
    if (n <= 2) return 1;
    uint32_t step = std::max<uint32_t>(1, uint32_t(double(n) * 0.6180339887498949));
    while (std::gcd(step, n) != 1) ++step;  // ends at n - 1 at the latest
    return step;
}

}  // namespace

struct SmallPairScan::Layout {
    std::vector<sh::BatchDirection> directions;
    std::vector<uint32_t> chunks;     // (direction, first query) per workgroup: seeds, then scans
    std::vector<uint64_t> nearestAt;  // per direction: its first entry of `nearest`
    uint32_t seedChunks = 0;
    uint32_t scanChunks = 0;
    uint64_t queries = 0;  // entries of `nearest`
    size_t perPair = 2;    // directions per pair
};

SmallPairScan::SmallPairScan(Workspace& ws) : m_ws(ws) {
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(ws.ctx.physicalDevice(), &props);
    m_maxWork = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? kMaxWorkCpuDevice : kMaxWorkGpu;
    // Benchmarks compare both paths on one machine: RTHDIST_SMALL_PAIR_WORK
    // replaces the limit (0: every pair takes the RT path).
    if (const char* env = std::getenv("RTHDIST_SMALL_PAIR_WORK")) m_maxWork = std::strtoull(env, nullptr, 10);
}

bool SmallPairScan::takes(uint64_t queries, uint64_t targets) const {
    return queries > 0 && targets > 0 && queries <= m_maxWork / targets;
}

SmallPairScan::Layout SmallPairScan::layOut(std::span<const SmallPair> pairs, bool directedOnly,
                                            bool perPoint) {
    Layout l;
    l.perPair = directedOnly ? 1 : 2;
    for (const SmallPair& p : pairs) {
        for (size_t k = 0; k < l.perPair; ++k) {
            l.nearestAt.push_back(l.queries);
            l.queries += (k == 0 ? p.a : p.b)->ix.n;
        }
    }
    BatchScratch& s = m_ws.scratch.batch;
    const VkDeviceAddress nearest = m_ws.grow(s.nearest, l.queries * 4, "batch.nearest").address();
    for (size_t i = 0; i < pairs.size(); ++i) {
        for (size_t k = 0; k < l.perPair; ++k) {
            const bool ab = k == 0;
            const DeviceSet& q = ab ? *pairs[i].a : *pairs[i].b;
            const DeviceSet& t = ab ? *pairs[i].b : *pairs[i].a;
            const uint32_t dir = uint32_t(l.directions.size());
            l.directions.push_back(sh::BatchDirection{
                q.ix.sorted->address(), t.ix.sorted->address(), nearest + 4 * l.nearestAt[dir],
                ab ? pairs[i].aScale : pairs[i].bScale, ab ? pairs[i].bScale : pairs[i].aScale, q.ix.n,
                t.ix.n, spreadStep(t.ix.n), std::max<uint32_t>(1, (q.ix.n + RTHDIST_WG - 1) / RTHDIST_WG)});
        }
    }
    const auto dirs = uint32_t(l.directions.size());
    if (!perPoint) {
        for (uint32_t d = 0; d < dirs; ++d) l.chunks.insert(l.chunks.end(), {d, 0u});
        l.seedChunks = dirs;
    }
    for (uint32_t d = 0; d < dirs; ++d) {
        for (uint32_t first = 0; first < l.directions[d].queryCount; first += RTHDIST_WG) {
            l.chunks.insert(l.chunks.end(), {d, first});
            ++l.scanChunks;
        }
    }
    const auto upload = [&](Buffer& b, const void* data, VkDeviceSize bytes, const char* name) {
        std::memcpy(m_ws.grow(b, bytes, name, MemoryKind::kHost).mapped(), data, bytes);
    };
    upload(s.directions, l.directions.data(), l.directions.size() * sizeof(sh::BatchDirection),
           "batch.directions");
    upload(s.chunks, l.chunks.data(), l.chunks.size() * 4, "batch.chunks");
    m_ws.grow(s.maxPacked, VkDeviceSize(dirs) * 8, "batch.maxPacked");
    m_ws.grow(s.witnesses, VkDeviceSize(dirs) * 16, "batch.witnesses", MemoryKind::kReadback);
    if (perPoint) m_ws.grow(s.perPoint, l.queries * 4, "batch.perPoint", MemoryKind::kReadback);
    return l;
}

void SmallPairScan::record(VkCommandBuffer cmd, const Layout& l, bool perPoint) {
    const BatchScratch& s = m_ws.scratch.batch;
    const auto dirs = uint32_t(l.directions.size());
    vkCmdFillBuffer(cmd, s.maxPacked.handle(), 0, VkDeviceSize(dirs) * 8, 0);
    m_ws.barrier(cmd);
    // The seed's queries all finish (no early break: the maximum has no
    // witness before them); the scan's stop at the seeded maximum.
    sh::BatchNearestPush p{s.directions.address(), s.chunks.address(), s.maxPacked.address(), 0u, 1u};
    if (l.seedChunks > 0) {
        m_ws.dispatch(cmd, Kernel::kBatchNearest, p, uint64_t(l.seedChunks) * RTHDIST_WG);
        m_ws.barrier(cmd);
    }
    p.earlyBreak = perPoint ? 0u : 1u;
    p.seed = 0u;
    p.chunks = s.chunks.address() + VkDeviceAddress(l.seedChunks) * 8;
    m_ws.dispatch(cmd, Kernel::kBatchNearest, p, uint64_t(l.scanChunks) * RTHDIST_WG);
    m_ws.barrier(cmd);
    const sh::BatchWitnessPush w{s.directions.address(), s.maxPacked.address(), s.witnesses.address(), dirs};
    m_ws.dispatch(cmd, Kernel::kBatchWitness, w, dirs);
    if (perPoint) {
        const VkBufferCopy all{0, 0, l.queries * 4};
        vkCmdCopyBuffer(cmd, s.nearest.handle(), s.perPoint.handle(), 1, &all);
    }
}

std::string SmallPairScan::finishPair(const SmallPair& pair, size_t first, const Layout& l, bool perPoint,
                                      HausdorffResult& out) const {
    const BatchScratch& s = m_ws.scratch.batch;
    const auto* witnesses = static_cast<const uint32_t*>(s.witnesses.mapped());
    for (size_t k = 0; k < l.perPair; ++k) {
        const bool ab = k == 0;
        const DeviceSet& q = ab ? *pair.a : *pair.b;
        const DeviceSet& t = ab ? *pair.b : *pair.a;
        const std::string name = ab ? "h(A,B)" : "h(B,A)";
        const uint32_t* w = witnesses + 4 * (first + k);
        if (w[0] >= q.ix.n || w[1] >= t.ix.n)
            return name + ": the device named query " + std::to_string(w[0]) + " and target " +
                   std::to_string(w[1]) + " of sets of " + std::to_string(q.ix.n) + " and " +
                   std::to_string(t.ix.n) + " points";
        const double qScale = ab ? pair.aScale : pair.bScale, tScale = ab ? pair.bScale : pair.aScale;
        const double searched =
            glm::length(glm::dvec3(q.points[w[0]]) * qScale - glm::dvec3(t.points[w[1]]) * tScale);
        const std::string why = witnessFailure(searched, uint64_t(w[2]) << 32, 0.0);
        if (!why.empty()) return name + ": " + why;
        Directed& d = ab ? out.aToB : out.bToA;
        d.queryIndex = w[0];
        d.targetIndex = w[1];
        d.counters.bits = uint32_t(t.ix.grid.bits);
        d.counters.occupiedCells = t.ix.numCells;
        d.counters.queries = q.ix.n;
        if (!perPoint) continue;
        PerPoint& pp = ab ? out.aNearest : out.bNearest;
        const uint32_t* nearest = static_cast<const uint32_t*>(s.perPoint.mapped()) + l.nearestAt[first + k];
        pp.nearest.assign(nearest, nearest + q.ix.n);
        if (std::any_of(pp.nearest.begin(), pp.nearest.end(), [&](uint32_t i) { return i >= t.ix.n; }))
            return name + ": a per-point nearest index lies past the target set's " + std::to_string(t.ix.n) +
                   " points";
        pp.distance.resize(q.ix.n);
    }
    return "";
}

SmallPairScan::Outcome SmallPairScan::run(std::span<const SmallPair> pairs, const CallOptions& options,
                                          const HausdorffResult& blank) {
    const auto t0 = Clock::now();
    const bool perPoint = options.perPointDistances;
    const Layout l = layOut(pairs, options.directedOnly, perPoint);
    VkCommandBuffer cmd = m_ws.ctx.begin();
    {
        const gpu::ScopedLabel label(m_ws.ctx, cmd, "small pairs");
        record(cmd, l, perPoint);
    }
    m_ws.ctx.submitAndWait(cmd);
    const double gpuMs = m_ws.ctx.lastGpuMs();
    Outcome out;
    out.results.assign(pairs.size(), blank);
    out.failed.resize(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i)
        out.failed[i] = finishPair(pairs[i], i * l.perPair, l, perPoint, out.results[i]);
    // The pairs ran together: each reports an equal share of the scan.
    const double share = 1.0 / double(std::max<size_t>(1, pairs.size()));
    for (HausdorffResult& r : out.results) {
        r.timings.refine = msSince(t0) * share;
        r.timings.gpuRefine = gpuMs * share;
    }
    return out;
}

}  // namespace rthdist::gpu_algo
