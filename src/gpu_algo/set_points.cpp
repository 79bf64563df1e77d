#include "gpu_algo/set_points.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>

#include "gpu/barriers.hpp"
#include "gpu/buffer.hpp"
#include "gpu/context.hpp"
#include "gpu_algo/point_index.hpp"

namespace rthdist::gpu_algo {

void SetPoints::useHost(std::span<const glm::vec3> searched) {
    *this = SetPoints{};
    m_host = searched;
    m_n = searched.size();
}

void SetPoints::useDevice(gpu::Context& ctx, const DeviceInput& view, const glm::dvec3& origin,
                          const PointIndex& ix) {
    *this = SetPoints{};
    m_ctx = &ctx;
    m_view = view;
    m_n = view.n;
    m_origin = origin;
    m_ix = &ix;
}

std::vector<uint32_t> SetPoints::missing(std::span<const uint32_t> indices) const {
    std::vector<uint32_t> wanted;
    if (!m_ctx) return wanted;
    for (uint32_t i : indices)
        if (i < m_n && !m_fetched.count(i) && std::find(wanted.begin(), wanted.end(), i) == wanted.end())
            wanted.push_back(i);
    return wanted;
}

void SetPoints::cmdCopy(VkCommandBuffer cmd, std::span<const uint32_t> wanted, VkBuffer host,
                        VkDeviceSize at) const {
    if (wanted.empty()) return;
    const VkDeviceSize bytes = m_view.pointBytes();
    std::vector<VkBufferCopy> regions;
    for (size_t k = 0; k < wanted.size(); ++k)
        regions.push_back({m_view.offset + VkDeviceSize(wanted[k]) * m_view.stride, at + k * bytes, bytes});
    vkCmdCopyBuffer(cmd, m_view.buffer, host, uint32_t(regions.size()), regions.data());
}

void SetPoints::store(std::span<const uint32_t> wanted, const char* bytes) {
    const VkDeviceSize size = m_view.pointBytes();
    for (size_t k = 0; k < wanted.size(); ++k, bytes += size) {
        glm::dvec3 p;
        if (m_view.scalar == Scalar::kFloat64) {
            double v[3];
            std::memcpy(v, bytes, sizeof(v));
            p = {v[0], v[1], v[2]};
        } else {
            float v[3];
            std::memcpy(v, bytes, sizeof(v));
            p = {v[0], v[1], v[2]};
        }
        m_fetched[wanted[k]] = p;
    }
}

glm::dvec3 SetPoints::original(uint32_t i) const {
    if (!m_ctx) return glm::dvec3(m_host[i]);
    const auto it = m_fetched.find(i);
    if (it == m_fetched.end())
        throw std::logic_error("SetPoints: point " + std::to_string(i) + " not fetched");
    return it->second;
}

glm::vec3 SetPoints::searched(uint32_t i) const {
    if (!m_ctx) return m_host[i];
    // The rounding of ingest_f64.comp (and of core::roundedCopy): the
    // difference in double, rounded to the nearest float.
    return glm::vec3(original(i) - m_origin);
}

std::span<const glm::vec3> SetPoints::all() {
    if (!m_ctx) return m_host;
    if (m_all.size() == m_n) return m_all;
    const VkDeviceSize bytes = VkDeviceSize(m_n) * 16;
    gpu::Buffer host(*m_ctx, bytes, gpu::kStorageUsage, gpu::MemoryKind::kReadback);
    VkCommandBuffer cmd = m_ctx->begin();
    // The index's records were written by shaders of earlier submissions.
    gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, m_ix->sorted->handle(), host.handle(), 1, &region);
    m_ctx->submitAndWait(cmd);
    const auto* rec = static_cast<const float*>(host.mapped());
    m_all.assign(m_n, glm::vec3(0.0f));
    for (size_t s = 0; s < m_n; ++s) {
        const uint32_t i = std::bit_cast<uint32_t>(rec[4 * s + 3]);
        if (i >= m_n)
            throw std::runtime_error("per-point read-back: a record names point " + std::to_string(i));
        m_all[i] = glm::vec3(rec[4 * s], rec[4 * s + 1], rec[4 * s + 2]);
    }
    return m_all;
}

}  // namespace rthdist::gpu_algo
