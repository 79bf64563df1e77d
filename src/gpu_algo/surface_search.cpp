#include "gpu_algo/surface_search.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "core/float_box.hpp"
#include "core/parallel.hpp"
#include "gpu/barriers.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/surface_tree.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

namespace {

constexpr uint32_t kMaxTriangles = uint32_t(1) << 30;  // corner indices 3t + 2 stay in 32 bits
constexpr size_t kStageChunk = size_t(1) << 14;

using Box = core::FloatBox;

// Whether two sets of corners are the same, every float bit for bit (a kept
// tree's and a call's): chunks compared on the worker pool, ~36 bytes a
// triangle read twice (for the bunny's 69,451 triangles ~0.1 ms on one
// thread), taken where the tree is wanted only.
bool sameCorners(std::span<const glm::vec3> kept, std::span<const glm::vec3> now, int threads) {
    if (kept.size() != now.size()) return false;
    const size_t triangles = now.size() / 3;
    const int workers = core::resolveThreads(threads, triangles / kStageChunk + 1);
    std::atomic<bool> same{true};
    core::parallelChunks(triangles, kStageChunk, workers, [&](size_t begin, size_t end, int) {
        if (!same.load(std::memory_order_relaxed)) return;
        if (std::memcmp(&kept[3 * begin], &now[3 * begin], (end - begin) * 3 * sizeof(glm::vec3)) != 0)
            same.store(false, std::memory_order_relaxed);
    });
    return same.load();
}

}  // namespace

SurfaceRadii::SurfaceRadii(double meanSide, double area, uint64_t queries, double diagonal) {
    m_cover = diagonal * (1.0 + 0x1p-10) + 0x1p-24;
    const double spacing = queries > 0 ? std::sqrt(std::max(area, 0.0) / double(queries)) : 0.0;
    m_first = std::min(std::max({meanSide * 0.5, spacing * 0.5, diagonal * 0x1p-20, 0x1p-24}), m_cover);
}

uint64_t surfaceHostWork(const Tuning& tuning, int threads) {
    return tuning.surfaceHostWork.value_or(kSurfaceHostWorkPerThread *
                                           uint64_t(core::resolveThreads(threads)));
}

bool descendOnly(const Tuning& tuning, uint64_t queries) {
    return tuning.surfaceDescend.value_or(queries <= kDescendQueries);
}

uint32_t tailLaneBits(const Tuning& tuning, bool cpuDevice, uint64_t descending, uint64_t queries) {
    const auto fits = [&](uint32_t bits) {
        return bits <= kTailMostLaneBits && (queries << bits) <= kTailMostThreads;
    };
    uint32_t bits = 0;
    if (tuning.surfaceTailLanes) {
        while (fits(bits + 1) && (uint64_t(2) << bits) <= *tuning.surfaceTailLanes) ++bits;
    } else if (!cpuDevice) {
        while (fits(bits + 1) && (descending << (bits + 1)) <= kTailThreads) ++bits;
    }
    return bits;
}

bool openQueriesToHost(uint64_t open, uint64_t triangles, uint64_t hostWork) {
    return open > 0 && triangles > 0 && open <= hostWork / triangles;
}

std::vector<double> SurfaceRadii::start() const {
    std::vector<double> radii{m_first};
    if (m_first < m_cover) radii.push_back(std::min(4.0 * m_first, m_cover));
    return radii;
}

// Per worker of the staging pass: its share of the radii's statistics.
struct SurfaceSearch::Stats {
    Box box;
    double sides = 0.0, area = 0.0;
    void add(const Stats& o) {
        box.add(o.box);
        sides += o.sides;
        area += o.area;
    }
};

// The tail's tree of one call (tailTree): kept from the call before, or built.
struct SurfaceSearch::TailTree {
    bool kept = false;
    SurfaceTree tree;  // empty where kept (or where no tail is wanted: nothing to stage)
    VkDeviceSize nodeBytes = 0, cornerBytes = 0;
    [[nodiscard]] VkDeviceSize bytes() const { return nodeBytes + cornerBytes; }
};

SurfaceCandidates SurfaceSearch::run(const core::FramedQueries& queries, std::span<const glm::vec3> corners,
                                     const std::atomic<bool>* cancel, uint64_t cornersVersion) {
    if (corners.empty() || corners.size() % 3 != 0 || corners.size() / 3 >= kMaxTriangles)
        throw gpu::LimitError("the surface search takes 1 to 2^30 - 1 triangles, not " +
                              std::to_string(corners.size() / 3));
    if (queries.count == 0 || queries.count > UINT32_MAX)
        throw gpu::LimitError("the surface search takes 1 to 2^32 - 1 queries, not " +
                              std::to_string(queries.count));
    m_queries = uint32_t(queries.count);
    m_triangles = uint32_t(corners.size() / 3);
    m_built = false;
    m_version = cornersVersion;
    m_ws.pipelines.prepareSurfaceSearch(m_ws.pipelineCache.handle());

    SurfaceCandidates out;
    // Descending only (descendOnly): the tree first, so that the upload
    // buffer holds the inputs and it for one submission.
    const bool descend = descendOnly(m_ws.tuning, m_queries);
    auto t0 = Clock::now();
    const TailTree tree = descend ? tailTree(corners, out) : TailTree{};
    const Stats stats = stage(queries, corners, !descend, tree.bytes());
    std::vector<double> start;  // the radii of the first submission (none where descending only)
    if (descend) {
        stageTail(tree, corners, inputBytes(false));
    } else {
        const SurfaceRadii radii(stats.sides / double(m_triangles), stats.area, m_queries,
                                 glm::length(glm::dvec3(stats.box.hi) - glm::dvec3(stats.box.lo)));
        out.firstRadius = radii.first();
        m_rayTMax = radii.first() * 1e-3;
        start = radii.start();
    }
    out.stageMs = msSince(t0) - out.tailBuildMs;  // the tree's build is part of submitMs, as after the radii

    // The first submission: the upload, then the radii (the first settles
    // most queries) and the read-back, and the tail's where queries are
    // open; or, descending only, every query's descent from none.
    t0 = Clock::now();
    std::fill_n(static_cast<uint32_t*>(m_counts.mapped()), 2 * SurfaceRadii::kStartRadii + 1, 0u);
    VkCommandBuffer cmd = m_ws.ctx.begin();
    cmdUpload(cmd, !descend);
    bool toHost = false;
    if (descend) {
        m_ws.ctx.cmdTraceMark(cmd);  // (RTHDIST_SUBMIT_TRACE: the upload, the descent, the read-back)
        cmdTail(cmd, tree, inputBytes(false), 0.0, m_queries, out);
        m_ws.ctx.cmdTraceMark(cmd);
        cmdReadBack(cmd);
        m_ws.ctx.submitAndWait(cmd);
        finishTail(tree, corners, out);
        if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) throw CallCancelled{};
    } else {
        uint64_t open = 0;  // after the last radius that searched a query
        for (const sh::SurfaceRadiusCount& c : submitRadii(cmd, start, out)) {
            open = c.searched - std::min(c.settled, c.searched);
            if (c.searched == 0) break;
            ++out.radii;
            out.rays += c.searched;
        }
        if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) throw CallCancelled{};
        // A few open queries go back to the host (measured exactly there),
        // the others descend the tail's tree.
        toHost = open > 0 && openQueriesToHost(open, m_triangles, surfaceHostWork(m_ws.tuning, m_ws.threads));
        if (open > 0 && !toHost) {
            submitTail(corners, start.back(), open, out);
            if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) throw CallCancelled{};
        }
    }
    out.submitMs = msSince(t0) + (descend ? out.tailBuildMs : 0.0);

    // Every query's best, as the last submission copied it: its triangle is
    // the low word; where the open queries go back, a query is open as the
    // rays' shader tells (its best not within the last radius, or none).
    t0 = Clock::now();
    const auto* packed = static_cast<const uint64_t*>(m_readback.mapped());
    const float settled2 = toHost ? std::nextafter(float(start.back() * start.back()), 0.0f) : 0.0f;
    const size_t chunk = core::balancedChunk(m_queries, m_ws.threads);
    std::vector<std::vector<uint32_t>> openParts(toHost ? (m_queries + chunk - 1) / chunk : 0);
    out.triangle.resize(m_queries);
    out.distance2.resize(m_queries);
    out.tops.chunk = chunk;
    out.tops.top.resize((m_queries + chunk - 1) / chunk);
    core::parallelChunks(m_queries, chunk, m_ws.threads, [&](size_t begin, size_t end, int) {
        for (size_t q = begin; q < end; ++q) {
            const uint64_t best = packed[q];
            const auto t = uint32_t(best & 0xffffffffu);
            float d2 = 0.0f;
            const auto bits = uint32_t(best >> 32);
            std::memcpy(&d2, &bits, sizeof(d2));
            out.triangle[q] = t < m_triangles ? t : UINT32_MAX;
            out.distance2[q] = t < m_triangles ? d2 : std::numeric_limits<float>::infinity();
            if (!toHost) continue;
            if (!(d2 <= settled2)) openParts[begin / chunk].push_back(uint32_t(q));
        }
        // (while this chunk's distances are in this thread's cache)
        out.tops.top[begin / chunk] = core::SearchedTops::topOf(out.distance2, begin, end);
    });
    out.open = core::concatenateParts<std::vector<uint32_t>>(openParts);
    out.readbackMs = msSince(t0);
    return out;
}

void SurfaceSearch::release() {
    for (gpu::Buffer* b : {&m_points, &m_corners, &m_boxes, &m_best, &m_aabbs, &m_staging, &m_readback,
                           &m_counts, &m_nodes, &m_leafCorners})
        b->reset();
    m_treeCorners = {};
    m_treeVersion = 0;
}

VkDeviceSize SurfaceSearch::inputBytes(bool rays) const {
    return VkDeviceSize(m_queries) * 16 + (rays ? VkDeviceSize(m_triangles) * (48 + sizeof(sh::Cell)) : 0);
}

SurfaceSearch::Stats SurfaceSearch::stage(const core::FramedQueries& queries,
                                          std::span<const glm::vec3> corners, bool rays, VkDeviceSize extra) {
    const VkDeviceSize pointBytes = VkDeviceSize(m_queries) * 16;
    const VkDeviceSize cornerBytes = VkDeviceSize(m_triangles) * 48;
    const VkDeviceSize boxBytes = VkDeviceSize(m_triangles) * sizeof(sh::Cell);
    gpu::Buffer& staging =
        m_ws.grow(m_staging, inputBytes(rays) + extra, "surface.staging", gpu::MemoryKind::kHost);
    m_ws.grow(m_points, pointBytes, "surface.queries");
    if (rays) {
        m_ws.grow(m_corners, cornerBytes, "surface.corners");
        m_ws.grow(m_boxes, boxBytes, "surface.boxes");
        m_ws.grow(m_aabbs, VkDeviceSize(m_triangles) * 24, "surface.aabbs");
    }
    m_ws.grow(m_best, VkDeviceSize(m_queries) * 8, "surface.best");
    m_ws.grow(m_readback, VkDeviceSize(m_queries) * 8, "surface.readback", gpu::MemoryKind::kReadback);
    // Each radius's counts, then the tail's (one uint).
    m_ws.grow(m_counts, SurfaceRadii::kStartRadii * sizeof(sh::SurfaceRadiusCount) + 4, "surface.counts",
              gpu::MemoryKind::kHost, false);

    auto* bytes = static_cast<char*>(staging.mapped());
    auto* points = reinterpret_cast<float*>(bytes);
    auto* cornerOut = reinterpret_cast<float*>(bytes + pointBytes);
    char* boxOut = bytes + pointBytes + cornerBytes;
    const size_t queryChunk = core::balancedChunk(m_queries, m_ws.threads);
    const size_t triangleChunk = core::balancedChunk(m_triangles, m_ws.threads, size_t(1) << 10);
    const int workers = core::resolveThreads(
        m_ws.threads, m_queries / queryChunk + (rays ? m_triangles / triangleChunk : 0) + 1);
    std::vector<Stats> each(static_cast<size_t>(workers));
    core::parallelChunks(m_queries, queryChunk, workers, [&](size_t begin, size_t end, int thread) {
        // Framed a block at a time into this thread's own memory (their box
        // read there, not from the upload buffer, which may be uncached),
        // then copied up.
        constexpr size_t kBlock = 256;
        glm::vec4 block[kBlock];
        Box box;
        for (size_t b = begin; b < end; b += kBlock) {
            const size_t e = std::min(end, b + kBlock);
            queries.writeTo(b, e, block);
            for (size_t i = 0; i < e - b; ++i) box.add(glm::vec3(block[i]));
            std::memcpy(points + 4 * b, block, (e - b) * sizeof(glm::vec4));
        }
        each[size_t(thread)].box.add(box);
    });
    if (!rays) {
        Stats all;
        for (const Stats& e : each) all.add(e);
        return all;
    }
    core::parallelChunks(m_triangles, triangleChunk, workers, [&](size_t begin, size_t end, int thread) {
        Stats mine;
        for (size_t t = begin; t < end; ++t) {
            Box tri;
            for (size_t k = 0; k < 3; ++k) {
                const glm::vec3& c = corners[3 * t + k];
                const float p[4] = {c.x, c.y, c.z, 0.0f};
                std::memcpy(cornerOut + 4 * (3 * t + k), p, sizeof(p));
                tri.add(c);
            }
            const sh::Cell cell{
                {tri.lo.x, tri.lo.y, tri.lo.z}, uint32_t(t), {tri.hi.x, tri.hi.y, tri.hi.z}, 1u};
            std::memcpy(boxOut + t * sizeof(sh::Cell), &cell, sizeof(cell));
            const glm::vec3 e = tri.hi - tri.lo;
            mine.sides += double(std::max({e.x, e.y, e.z}));
            const glm::dvec3 a(corners[3 * t]), b(corners[3 * t + 1]), c(corners[3 * t + 2]);
            mine.area += 0.5 * glm::length(glm::cross(b - a, c - a));
            mine.box.add(tri);
        }
        each[size_t(thread)].add(mine);
    });
    Stats all;
    for (const Stats& s : each) all.add(s);
    return all;
}

void SurfaceSearch::cmdUpload(VkCommandBuffer cmd, bool rays) {
    const VkDeviceSize pointBytes = VkDeviceSize(m_queries) * 16;
    const VkDeviceSize cornerBytes = VkDeviceSize(m_triangles) * 48;
    const VkDeviceSize boxBytes = VkDeviceSize(m_triangles) * sizeof(sh::Cell);
    const VkBufferCopy toPoints{0, 0, pointBytes};
    vkCmdCopyBuffer(cmd, m_staging.handle(), m_points.handle(), 1, &toPoints);
    if (rays) {
        const VkBufferCopy toCorners{pointBytes, 0, cornerBytes};
        const VkBufferCopy toBoxes{pointBytes + cornerBytes, 0, boxBytes};
        vkCmdCopyBuffer(cmd, m_staging.handle(), m_corners.handle(), 1, &toCorners);
        vkCmdCopyBuffer(cmd, m_staging.handle(), m_boxes.handle(), 1, &toBoxes);
    }
    vkCmdFillBuffer(cmd, m_best.handle(), 0, VkDeviceSize(m_queries) * 8, 0xffffffffu);  // none
    gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
}

std::vector<sh::SurfaceRadiusCount> SurfaceSearch::submitRadii(VkCommandBuffer cmd,
                                                               std::span<const double> radii,
                                                               SurfaceCandidates& out) {
    if (radii.size() > SurfaceRadii::kStartRadii) throw std::logic_error("more radii than counts");
    const auto* counts = static_cast<const sh::SurfaceRadiusCount*>(m_counts.mapped());
    std::vector<std::pair<uint32_t, uint32_t>> buildMarks;
    double settled = -1.0;  // no query is settled before the first radius
    for (size_t i = 0; i < radii.size(); ++i) {
        // Everything of the radius before (its rays read the BLAS this one refits).
        if (i > 0)
            gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                             VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
        const uint32_t from = m_ws.ctx.cmdMark(cmd);
        const double settled2 = settled < 0.0 ? -1.0 : settled * settled;
        const uint32_t built = cmdRadius(cmd, radii[i], settled2, m_built,
                                         m_counts.address() + i * sizeof(sh::SurfaceRadiusCount));
        buildMarks.emplace_back(from, built);
        m_built = true;
        settled = radii[i];
    }
    // Every query's best for the host (the tail may not follow).
    cmdReadBack(cmd);
    m_ws.ctx.submitAndWait(cmd);
    ++out.submissions;
    out.gpuMs += m_ws.ctx.lastGpuMs();
    for (const auto& [from, to] : buildMarks) out.gpuBuildMs += m_ws.ctx.gpuMsBetween(from, to);
    return {counts, counts + radii.size()};
}

void SurfaceSearch::cmdReadBack(VkCommandBuffer cmd) {
    gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    const VkBufferCopy region{0, 0, VkDeviceSize(m_queries) * 8};
    vkCmdCopyBuffer(cmd, m_best.handle(), m_readback.handle(), 1, &region);
    gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

SurfaceSearch::TailTree SurfaceSearch::tailTree(std::span<const glm::vec3> corners, SurfaceCandidates& out) {
    TailTree t;
    t.kept = !m_treeCorners.empty() && ((m_version != 0 && m_version == m_treeVersion) ||
                                        sameCorners(m_treeCorners, corners, m_ws.threads));
    out.tailTreeReused = t.kept;
    if (t.kept) return t;
    const auto t0 = Clock::now();
    m_treeCorners.clear();  // m_nodes and m_leafCorners hold no tree until the tail's submission is done
    t.tree = buildSurfaceTree(corners, m_ws.threads);
    t.nodeBytes = VkDeviceSize(t.tree.nodes.size()) * sizeof(sh::Cell);
    t.cornerBytes = VkDeviceSize(t.tree.order.size()) * 48;
    m_ws.grow(m_nodes, t.nodeBytes, "surface.nodes");
    m_ws.grow(m_leafCorners, t.cornerBytes, "surface.leafCorners");
    out.tailBuildMs = msSince(t0);
    return t;
}

void SurfaceSearch::stageTail(const TailTree& tree, std::span<const glm::vec3> corners, VkDeviceSize at) {
    if (tree.kept) return;
    gpu::Buffer& staging =
        at == 0 ? m_ws.grow(m_staging, tree.bytes(), "surface.staging", gpu::MemoryKind::kHost) : m_staging;
    if (staging.size() < at + tree.bytes())
        throw std::logic_error("the upload buffer holds no room for the tree");
    auto* bytes = static_cast<char*>(staging.mapped()) + at;
    std::memcpy(bytes, tree.tree.nodes.data(), tree.nodeBytes);
    // Each sorted position's corners, a's fourth word its triangle's index.
    auto* leafCorners = reinterpret_cast<uint32_t*>(bytes + tree.nodeBytes);
    const std::vector<uint32_t>& order = tree.tree.order;
    core::parallelChunks(order.size(), kStageChunk, m_ws.threads, [&](size_t begin, size_t end, int) {
        for (size_t p = begin; p < end; ++p) {
            const uint32_t t = order[p];
            uint32_t record[12];
            for (size_t k = 0; k < 3; ++k) {
                std::memcpy(&record[4 * k], &corners[3 * size_t(t) + k], sizeof(glm::vec3));
                record[4 * k + 3] = 0u;
            }
            record[3] = t;
            std::memcpy(leafCorners + 12 * p, record, sizeof(record));
        }
    });
}

void SurfaceSearch::cmdTail(VkCommandBuffer cmd, const TailTree& tree, VkDeviceSize at, double settled,
                            uint64_t descending, SurfaceCandidates& out) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "surface tail");
    if (!tree.kept) {
        const VkBufferCopy toNodes{at, 0, tree.nodeBytes};
        const VkBufferCopy toCorners{at + tree.nodeBytes, 0, tree.cornerBytes};
        vkCmdCopyBuffer(cmd, m_staging.handle(), m_nodes.handle(), 1, &toNodes);
        vkCmdCopyBuffer(cmd, m_staging.handle(), m_leafCorners.handle(), 1, &toCorners);
        // (A kept tree's copies were made visible to compute reads by
        // this barrier in the submission that made them.)
        gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                         VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }
    sh::SurfaceTailPush tp{};
    tp.queries = m_points.address();
    tp.best = m_best.address();
    tp.nodes = m_nodes.address();
    tp.leafCorners = m_leafCorners.address();
    tp.counts = m_counts.address() + SurfaceRadii::kStartRadii * sizeof(sh::SurfaceRadiusCount);
    tp.numQueries = m_queries;
    // The radii's settle2 of the last radius: the queries open after it
    // (settled 0: every query, a best of none compares false).
    tp.settled2 = std::nextafter(float(settled * settled), 0.0f);
    tp.mutant = m_ws.mutant ? 1u : 0u;
    tp.laneBits = tailLaneBits(m_ws.tuning, m_ws.ctx.cpuDevice(), descending, m_queries);
    out.tailLanes = 1u << tp.laneBits;
    m_ws.dispatch(cmd, Kernel::kSurfaceTail, tp, uint64_t(m_queries) << tp.laneBits);
}

void SurfaceSearch::finishTail(const TailTree& tree, std::span<const glm::vec3> corners,
                               SurfaceCandidates& out) {
    if (!tree.kept) m_treeCorners.assign(corners.begin(), corners.end());
    m_treeVersion = m_version;
    ++out.submissions;
    out.tailGpuMs = m_ws.ctx.lastGpuMs();
    out.gpuMs += out.tailGpuMs;
    out.tailQueries = static_cast<const uint32_t*>(
        m_counts.mapped())[SurfaceRadii::kStartRadii * sizeof(sh::SurfaceRadiusCount) / sizeof(uint32_t)];
}

void SurfaceSearch::submitTail(std::span<const glm::vec3> corners, double settled, uint64_t open,
                               SurfaceCandidates& out) {
    // (The radii's submission has finished with what the upload buffer held.)
    const TailTree tree = tailTree(corners, out);
    stageTail(tree, corners, 0);
    VkCommandBuffer cmd = m_ws.ctx.begin();
    cmdTail(cmd, tree, 0, settled, open, out);
    cmdReadBack(cmd);
    m_ws.ctx.submitAndWait(cmd);
    finishTail(tree, corners, out);
}

uint32_t SurfaceSearch::cmdRadius(VkCommandBuffer cmd, double radius, double settled2, bool update,
                                  VkDeviceAddress counts) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "surface search");
    const auto r = float(radius);
    // The boxes' slack: rounding at the box's magnitude (grow_boxes.comp).
    const sh::BoxesPush bp{m_boxes.address(), m_aabbs.address(), m_triangles, r + r * 1e-6f, 4e-7f, 0.0f};
    m_ws.dispatch(cmd, Kernel::kGrowBoxes, bp, m_triangles);
    gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_SHADER_READ_BIT);
    // The boxes only grow between radii: refit.
    if (m_ws.accel.cmdBuild(cmd, m_aabbs.address(), m_triangles, update, m_ws.pipelines.shaderStages()) ||
        !m_ws.tlasBound) {
        m_ws.pipelines.bindTlas(m_ws.accel.tlas());
        m_ws.tlasBound = true;
    }
    const uint32_t built = m_ws.ctx.cmdMark(cmd);
    sh::SurfaceSearchPush sp{};
    sp.queries = m_points.address();
    sp.corners = m_corners.address();
    sp.best = m_best.address();
    sp.counts = counts;
    sp.numQueries = m_queries;
    sp.radius = r;
    // Rounded down: a query is settled only when its best is within the radius.
    sp.settled2 = settled2 < 0.0 ? -1.0f : std::nextafter(float(settled2), 0.0f);
    sp.settle2 = std::nextafter(float(radius * radius), 0.0f);
    sp.rayTMax = float(m_rayTMax);
    sp.mutant = m_ws.mutant ? 1u : 0u;
    if (m_ws.rayQuery) {
        m_ws.dispatch(cmd, Kernel::kSurfaceSearchRayQuery, sp, m_queries);
        return built;
    }
    const uint64_t chunk = std::max<uint64_t>(1, m_ws.ctx.limits().maxRayDispatch);
    for (uint64_t first = 0; first < m_queries; first += chunk) {
        sp.slotBase = uint32_t(first);
        m_ws.pipelines.cmdTraceSurfaceRays(cmd, &sp, sizeof(sp),
                                           uint32_t(std::min<uint64_t>(chunk, m_queries - first)));
    }
    return built;
}

}  // namespace rthdist::gpu_algo
