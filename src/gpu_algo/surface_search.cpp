#include "gpu_algo/surface_search.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "gpu/barriers.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/workspace.hpp"
#include "rthdist_surface_search.h"

namespace rthdist::gpu_algo {

namespace {

// Radii recorded in one submission (each: boxes, refit, rays); the host
// reads how many queries each searched and stops at the first that searched
// none.
constexpr size_t kRadiiPerSubmission = 4;
constexpr uint32_t kMaxTriangles = uint32_t(1) << 30;  // corner indices 3t + 2 stay in 32 bits

struct Frame {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};
    void add(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
};

// The radii: from half the mean longest side of the triangles' boxes (a
// query on or near the surface settles at once), doubling, up to the
// diagonal of the union of both inputs' boxes, where every grown box holds
// every query (the last radius settles every query that is left).
std::vector<double> radiusSchedule(std::span<const glm::vec3> queries, std::span<const glm::vec3> corners) {
    Frame all;
    double sides = 0.0;
    for (size_t t = 0; t + 2 < corners.size(); t += 3) {
        Frame tri;
        for (size_t k = 0; k < 3; ++k) tri.add(corners[t + k]);
        const glm::vec3 e = tri.hi - tri.lo;
        sides += double(std::max({e.x, e.y, e.z}));
        all.add(tri.lo);
        all.add(tri.hi);
    }
    for (const glm::vec3& q : queries) all.add(q);
    const double diagonal = glm::length(glm::dvec3(all.hi) - glm::dvec3(all.lo));
    const double cover = diagonal * (1.0 + 0x1p-10) + 0x1p-24;
    const double meanSide = sides / double(corners.size() / 3);
    double r = std::max({meanSide * 0.5, diagonal * 0x1p-20, 0x1p-24});
    std::vector<double> radii;
    for (; r < cover; r *= 2.0) radii.push_back(r);
    radii.push_back(cover);
    return radii;
}

}  // namespace

SurfaceCandidates SurfaceSearch::run(std::span<const glm::vec3> queries, std::span<const glm::vec3> corners) {
    if (corners.empty() || corners.size() % 3 != 0 || corners.size() / 3 >= kMaxTriangles)
        throw gpu::LimitError("the surface search takes 1 to 2^30 - 1 triangles, not " +
                              std::to_string(corners.size() / 3));
    if (queries.empty() || queries.size() > UINT32_MAX)
        throw gpu::LimitError("the surface search takes 1 to 2^32 - 1 queries, not " +
                              std::to_string(queries.size()));
    m_queries = uint32_t(queries.size());
    m_triangles = uint32_t(corners.size() / 3);
    m_ws.pipelines.prepareSurfaceSearch(m_ws.pipelineCache.handle());
    const std::vector<double> radii = radiusSchedule(queries, corners);
    m_rayTMax = radii.front() * 1e-3;
    upload(queries, corners);

    SurfaceCandidates out;
    double settled = -1.0;  // no query is settled before the first radius
    for (size_t first = 0; first < radii.size(); first += kRadiiPerSubmission) {
        const auto batch =
            std::span(radii).subspan(first, std::min(kRadiiPerSubmission, radii.size() - first));
        const std::vector<uint32_t> searched = runRadii(batch, settled, first == 0);
        out.gpuMs += m_ws.ctx.lastGpuMs();
        bool done = false;
        for (uint32_t s : searched) {
            done = done || s == 0;
            if (done) break;
            ++out.radii;
            out.rays += s;
        }
        if (done) break;
        settled = batch.back();
    }

    // Every query's best back to the host: its triangle is the low word.
    gpu::Buffer& back = m_ws.grow(m_readback, VkDeviceSize(m_queries) * 8, "surface.readback",
                                  gpu::MemoryKind::kReadback, false);
    VkCommandBuffer cmd = m_ws.ctx.begin();
    const VkBufferCopy region{0, 0, VkDeviceSize(m_queries) * 8};
    vkCmdCopyBuffer(cmd, m_best.handle(), back.handle(), 1, &region);
    gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                    VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    m_ws.ctx.submitAndWait(cmd);
    const auto* packed = static_cast<const uint64_t*>(back.mapped());
    out.triangle.resize(m_queries);
    for (uint32_t q = 0; q < m_queries; ++q) {
        const auto t = uint32_t(packed[q] & 0xffffffffu);
        out.triangle[q] = t < m_triangles ? t : UINT32_MAX;
    }
    return out;
}

void SurfaceSearch::upload(std::span<const glm::vec3> queries, std::span<const glm::vec3> corners) {
    const VkDeviceSize pointBytes = VkDeviceSize(m_queries) * 16;
    const VkDeviceSize cornerBytes = VkDeviceSize(m_triangles) * 48;
    const VkDeviceSize boxBytes = VkDeviceSize(m_triangles) * sizeof(sh::Cell);
    gpu::Buffer& staging = m_ws.grow(m_staging, pointBytes + cornerBytes + boxBytes, "surface.staging",
                                     gpu::MemoryKind::kHost, false);
    auto* bytes = static_cast<char*>(staging.mapped());
    auto* points = reinterpret_cast<float*>(bytes);
    for (size_t i = 0; i < queries.size(); ++i) {
        const float p[4] = {queries[i].x, queries[i].y, queries[i].z, 0.0f};
        std::memcpy(points + 4 * i, p, sizeof(p));
    }
    auto* cornerOut = reinterpret_cast<float*>(bytes + pointBytes);
    auto* boxOut = bytes + pointBytes + cornerBytes;
    for (uint32_t t = 0; t < m_triangles; ++t) {
        Frame box;
        for (size_t k = 0; k < 3; ++k) {
            const glm::vec3& c = corners[3 * size_t(t) + k];
            const float p[4] = {c.x, c.y, c.z, 0.0f};
            std::memcpy(cornerOut + 4 * (3 * size_t(t) + k), p, sizeof(p));
            box.add(c);
        }
        const sh::Cell cell{{box.lo.x, box.lo.y, box.lo.z}, t, {box.hi.x, box.hi.y, box.hi.z}, 1u};
        std::memcpy(boxOut + size_t(t) * sizeof(sh::Cell), &cell, sizeof(cell));
    }
    m_ws.grow(m_points, pointBytes, "surface.queries", gpu::MemoryKind::kDevice, false);
    m_ws.grow(m_corners, cornerBytes, "surface.corners", gpu::MemoryKind::kDevice, false);
    m_ws.grow(m_boxes, boxBytes, "surface.boxes", gpu::MemoryKind::kDevice, false);
    m_ws.grow(m_best, VkDeviceSize(m_queries) * 8, "surface.best", gpu::MemoryKind::kDevice, false);
    m_ws.grow(m_aabbs, VkDeviceSize(m_triangles) * 24, "surface.aabbs", gpu::MemoryKind::kDevice, false);
    m_ws.grow(m_searched, kRadiiPerSubmission * 4, "surface.searched", gpu::MemoryKind::kHost, false);

    VkCommandBuffer cmd = m_ws.ctx.begin();
    const VkBufferCopy toPoints{0, 0, pointBytes};
    const VkBufferCopy toCorners{pointBytes, 0, cornerBytes};
    const VkBufferCopy toBoxes{pointBytes + cornerBytes, 0, boxBytes};
    vkCmdCopyBuffer(cmd, staging.handle(), m_points.handle(), 1, &toPoints);
    vkCmdCopyBuffer(cmd, staging.handle(), m_corners.handle(), 1, &toCorners);
    vkCmdCopyBuffer(cmd, staging.handle(), m_boxes.handle(), 1, &toBoxes);
    vkCmdFillBuffer(cmd, m_best.handle(), 0, VkDeviceSize(m_queries) * 8, 0xffffffffu);  // none
    m_ws.ctx.submitAndWait(cmd);
}

std::vector<uint32_t> SurfaceSearch::runRadii(std::span<const double> radii, double settledBefore,
                                              bool firstBuild) {
    auto* searched = static_cast<uint32_t*>(m_searched.mapped());
    std::fill_n(searched, kRadiiPerSubmission, 0u);
    VkCommandBuffer cmd = m_ws.ctx.begin();
    double settled = settledBefore;
    for (size_t i = 0; i < radii.size(); ++i) {
        // Everything of the radius before (its rays read the BLAS this one refits).
        if (i > 0)
            gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                             VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
        const double settled2 = settled < 0.0 ? -1.0 : settled * settled;
        cmdRadius(cmd, radii[i], settled2, !(firstBuild && i == 0), m_searched.address() + 4 * i);
        settled = radii[i];
    }
    gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    m_ws.ctx.submitAndWait(cmd);
    return {searched, searched + radii.size()};
}

void SurfaceSearch::cmdRadius(VkCommandBuffer cmd, double radius, double settled2, bool update,
                              VkDeviceAddress searched) {
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
    sh::SurfaceSearchPush sp{};
    sp.queries = m_points.address();
    sp.corners = m_corners.address();
    sp.best = m_best.address();
    sp.searched = searched;
    sp.numQueries = m_queries;
    sp.radius = r;
    // Rounded down: a query is settled only when its best is within the radius.
    sp.settled2 = settled2 < 0.0 ? -1.0f : std::nextafter(float(settled2), 0.0f);
    sp.rayTMax = float(m_rayTMax);
    sp.mutant = m_ws.mutant ? 1u : 0u;
    if (m_ws.rayQuery) {
        m_ws.dispatch(cmd, Kernel::kSurfaceSearchRayQuery, sp, m_queries);
        return;
    }
    const uint64_t chunk = std::max<uint64_t>(1, m_ws.ctx.limits().maxRayDispatch);
    for (uint64_t first = 0; first < m_queries; first += chunk) {
        sp.slotBase = uint32_t(first);
        m_ws.pipelines.cmdTraceSurfaceRays(cmd, &sp, sizeof(sp),
                                           uint32_t(std::min<uint64_t>(chunk, m_queries - first)));
    }
}

}  // namespace rthdist::gpu_algo
