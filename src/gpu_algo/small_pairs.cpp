#include "gpu_algo/small_pairs.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <numeric>
#include <string>

#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {

namespace {

constexpr uint64_t kMaxWorkGpu = uint64_t(1) << 28;
constexpr uint64_t kMaxWorkCpuDevice = uint64_t(1) << 20;
// Points of one side at most, and queries of one submission.
constexpr uint64_t kMaxSide = uint64_t(1) << 22;
constexpr uint64_t kMaxQueries = uint64_t(1) << 24;

uint64_t pairQueries(const SmallPair& p) { return p.a.points.size() + p.b.points.size(); }

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
    // Benchmarks compare both paths on one machine: Tuning::smallPairWork
    // replaces the limit (0: every pair takes the RT path).
    m_limits = core::ScanLimits{
        kMaxSide, ws.tuning.smallPairWork.value_or(ws.ctx.cpuDevice() ? kMaxWorkCpuDevice : kMaxWorkGpu)};
}

SmallPairScan::Layout SmallPairScan::layOut(std::span<const SmallPair> pairs, bool directedOnly,
                                            bool perPoint) {
    Layout l;
    l.perPair = directedOnly ? 1 : 2;
    for (const SmallPair& p : pairs) {
        for (size_t k = 0; k < l.perPair; ++k) {
            l.nearestAt.push_back(l.queries);
            l.queries += (k == 0 ? p.a : p.b).points.size();
        }
    }
    BatchScratch& s = m_ws.scratch.batch;
    const VkDeviceAddress nearest = m_ws.grow(s.nearest, l.queries * 4, "batch.nearest").address();
    for (const SmallPair& p : pairs) {
        for (size_t k = 0; k < l.perPair; ++k) {
            const ScanSet& q = k == 0 ? p.a : p.b;
            const ScanSet& t = k == 0 ? p.b : p.a;
            const auto nq = uint32_t(q.points.size()), nt = uint32_t(t.points.size());
            const VkDeviceAddress out = nearest + 4 * l.nearestAt[l.directions.size()];
            l.directions.push_back(
                sh::BatchDirection{q.records, t.records, out, q.scale, t.scale, nq, nt, spreadStep(nt),
                                   std::max<uint32_t>(1, (nq + RTHDIST_WG - 1) / RTHDIST_WG)});
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
    // Every query's nearest (or killing) target comes back: per-point output,
    // and the certificate's band (finishPair).
    m_ws.grow(s.perPoint, l.queries * 4, "batch.perPoint", MemoryKind::kReadback);
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
    const VkBufferCopy all{0, 0, l.queries * 4};
    vkCmdCopyBuffer(cmd, s.nearest.handle(), s.perPoint.handle(), 1, &all);
    gpu::cmdHostReadBarrier(cmd);
}

std::string SmallPairScan::finishPair(const SmallPair& pair, size_t first, const Layout& l, bool perPoint,
                                      HausdorffResult& out) const {
    const BatchScratch& s = m_ws.scratch.batch;
    const auto* witnesses = static_cast<const uint32_t*>(s.witnesses.mapped());
    auto material = std::make_shared<detail::ProofMaterial>();
    out.proofMaterial = material;  // filled below
    for (size_t k = 0; k < l.perPair; ++k) {
        const bool ab = k == 0;
        const ScanSet& q = ab ? pair.a : pair.b;
        const ScanSet& t = ab ? pair.b : pair.a;
        const std::string name = ab ? "h(A,B)" : "h(B,A)";
        const uint32_t* w = witnesses + 4 * (first + k);
        const size_t nq = q.points.size(), nt = t.points.size();
        if (w[0] >= nq || w[1] >= nt)
            return name + ": the device named query " + std::to_string(w[0]) + " and target " +
                   std::to_string(w[1]) + " of sets of " + std::to_string(nq) + " and " + std::to_string(nt) +
                   " points";
        const double searched = glm::length(glm::dvec3(q.points[w[0]]) * q.pointsScale -
                                            glm::dvec3(t.points[w[1]]) * t.pointsScale);
        const std::string why = witnessFailure(searched, uint64_t(w[2]) << 32, 0.0);
        if (!why.empty()) return name + ": " + why;
        Directed& d = ab ? out.aToB : out.bToA;
        d.queryIndex = w[0];
        d.targetIndex = w[1];
        d.counters.bits = uint32_t(t.bits);
        d.counters.occupiedCells = t.cells;
        d.counters.queries = nq;
        const uint32_t* nearest = static_cast<const uint32_t*>(s.perPoint.mapped()) + l.nearestAt[first + k];
        if (std::any_of(nearest, nearest + nq, [&](uint32_t i) { return i >= nt; }))
            return name + ": a query's nearest index lies past the target set's " + std::to_string(nt) +
                   " points";
        (ab ? material->aToB : material->bToA) = bandOf(q, t, nearest, std::bit_cast<float>(w[2]));
        if (!perPoint) continue;
        PerPoint& pp = ab ? out.aNearest : out.bNearest;
        pp.nearest.assign(nearest, nearest + nq);
        pp.distance.resize(nq);
    }
    return "";
}

core::DirectionBand SmallPairScan::bandOf(const ScanSet& q, const ScanSet& t, const uint32_t* nearest,
                                          float maxD2) {
    // The certificate's band (core/certificate.hpp) from every query's
    // nearest or killing target (batch_nearest.comp writes both): the
    // queries whose pair, in double over the searched points, lies within
    // 2e of the float maximum. Outside it a query's pair is nearer than
    // hf - 2e there, hence than hf - e in the caller's coordinates.
    core::DirectionBand band;
    band.present = true;
    band.hf = std::sqrt(double(maxD2));
    band.slack =
        core::searchSlack(std::max(core::largestMagnitude(q.points), core::largestMagnitude(t.points)) *
                          std::max(q.pointsScale, t.pointsScale));
    band.scale = q.inputScale;
    for (size_t i = 0; i < q.points.size(); ++i) {
        const double u = core::exactDistance(glm::dvec3(q.points[i]) * q.pointsScale,
                                             glm::dvec3(t.points[nearest[i]]) * t.pointsScale);
        if (u >= band.hf - 2.0 * band.slack) band.queries.push_back({i, nearest[i]});
    }
    return band;
}

SmallPairScan::Outcome SmallPairScan::submit(std::span<const SmallPair> pairs, const Layout& l,
                                             const CallOptions& options, const HausdorffResult& blank,
                                             const std::function<void(VkCommandBuffer)>& before) {
    const auto t0 = Clock::now();
    const bool perPoint = options.perPointDistances;
    VkCommandBuffer cmd = m_ws.ctx.begin();
    {
        const gpu::ScopedLabel label(m_ws.ctx, cmd, "small pairs");
        if (before) before(cmd);
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
    const double wallMs = msSince(t0);
    for (HausdorffResult& r : out.results) {
        r.timings.refine = wallMs * share;
        r.timings.gpuRefine = gpuMs * share;
    }
    return out;
}

SmallPairScan::Outcome SmallPairScan::run(std::span<const SmallPair> pairs, const CallOptions& options,
                                          const HausdorffResult& blank) {
    // One submission per group of pairs with at most kMaxQueries queries
    // (the scratch per query stays bounded however long the batch).
    Outcome out;
    for (size_t first = 0; first < pairs.size();) {
        size_t end = first;
        uint64_t queries = 0;
        while (end < pairs.size() && (end == first || queries + pairQueries(pairs[end]) <= kMaxQueries))
            queries += pairQueries(pairs[end++]);
        const std::span<const SmallPair> group = pairs.subspan(first, end - first);
        const Layout l = layOut(group, options.directedOnly, options.perPointDistances);
        Outcome part = submit(group, l, options, blank, nullptr);
        std::move(part.results.begin(), part.results.end(), std::back_inserter(out.results));
        std::move(part.failed.begin(), part.failed.end(), std::back_inserter(out.failed));
        first = end;
    }
    return out;
}

SmallPairScan::Outcome SmallPairScan::runHostArrays(std::span<const glm::vec3> a,
                                                    std::span<const glm::vec3> b, double scale,
                                                    const CallOptions& options,
                                                    const HausdorffResult& blank) {
    const auto t0 = Clock::now();
    BatchScratch& s = m_ws.scratch.batch;
    const VkDeviceSize bytes = VkDeviceSize(a.size() + b.size()) * 16;
    auto* staged =
        static_cast<uint32_t*>(m_ws.grow(s.staged, bytes, "batch.staged", MemoryKind::kHost).mapped());
    size_t at = 0;
    for (std::span<const glm::vec3> set : {a, b}) {
        for (size_t i = 0; i < set.size(); ++i, at += 4) {
            // Scaled as the RT path's host copy is (exact: a power of two
            // into float range; the scale itself may lie outside it).
            const glm::vec3 p(glm::dvec3(set[i]) * scale);
            staged[at] = std::bit_cast<uint32_t>(p.x);
            staged[at + 1] = std::bit_cast<uint32_t>(p.y);
            staged[at + 2] = std::bit_cast<uint32_t>(p.z);
            staged[at + 3] = uint32_t(i);  // the input index, as the records' w bits
        }
    }
    const VkDeviceAddress records = m_ws.grow(s.records, bytes, "batch.records").address();
    const SmallPair pair{ScanSet{records, 1.0f, a, scale, 0, 0, scale},
                         ScanSet{records + a.size() * 16, 1.0f, b, scale, 0, 0, scale}};
    const Layout l = layOut(std::span(&pair, 1), options.directedOnly, options.perPointDistances);
    const double staging = msSince(t0);
    uint32_t copied = 0;
    Outcome out = submit(std::span(&pair, 1), l, options, blank, [&](VkCommandBuffer cmd) {
        const VkBufferCopy all{0, 0, bytes};
        vkCmdCopyBuffer(cmd, s.staged.handle(), s.records.handle(), 1, &all);
        copied = m_ws.ctx.cmdMark(cmd);
        m_ws.barrier(cmd);
    });
    Timings& t = out.results[0].timings;
    t.upload = staging;
    t.gpuUpload = m_ws.ctx.gpuMsBetween(0, copied);
    t.gpuRefine -= t.gpuUpload;
    return out;
}

ScanSet scanSetOf(const DeviceSet& set, double scale) {
    return ScanSet{set.ix.sorted->address(), float(scale),    set.points,       scale,
                   set.ix.grid.bits,         set.ix.numCells, set.scale * scale};
}

}  // namespace rthdist::gpu_algo
