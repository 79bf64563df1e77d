// Where the host finds a set's points when it checks the device's records
// (self_check.hpp) and reports witnesses and per-point distances: the float
// arrays the host staged, or, for device input (vulkan_interop.hpp), the
// embedder's buffer, read a few points at a time by vkCmdCopyBuffer.
#pragma once

#include <vulkan/vulkan.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "rthdist/point_view.hpp"

namespace rthdist::gpu {
class Context;
}

namespace rthdist::gpu_algo {

struct PointIndex;

// One view of the embedder's buffer (device input), checked by the caller
// (src/api) against the contract's limits.
struct DeviceInput {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceAddress address = 0;  // of point 0: the buffer's address + offset
    VkDeviceSize offset = 0;      // of point 0 in the buffer (the host's copies)
    uint32_t n = 0;
    uint32_t stride = 12;
    Scalar scalar = Scalar::kFloat32;

    [[nodiscard]] VkDeviceSize pointBytes() const { return 3 * VkDeviceSize(scalarBytes(scalar)); }
};

class SetPoints {
public:
    // Host arrays: the float points the device holds (after the scale).
    void useHost(std::span<const glm::vec3> searched);
    // Device input: `view`, searched as float(p - origin); `ix` is the set's
    // index (per-point output reads its records back).
    void useDevice(gpu::Context& ctx, const DeviceInput& view, const glm::dvec3& origin,
                   const PointIndex& ix);

    [[nodiscard]] size_t size() const { return m_n; }
    [[nodiscard]] bool onDevice() const { return m_ctx != nullptr; }
    // Device input: the points of `indices` not fetched yet (each once);
    // host arrays: none. With cmdCopy and store, a caller fetches the points
    // of several sets in one submission into one kept host buffer.
    [[nodiscard]] std::vector<uint32_t> missing(std::span<const uint32_t> indices) const;
    // Bytes of one fetched point (three scalars of the view).
    [[nodiscard]] VkDeviceSize pointBytes() const { return m_view.pointBytes(); }
    // Records copies of points `wanted` from the embedder's buffer to `host`
    // at byte `at`, pointBytes() each, in order.
    void cmdCopy(VkCommandBuffer cmd, std::span<const uint32_t> wanted, VkBuffer host, VkDeviceSize at) const;
    // Takes the points `wanted` from `bytes` (as cmdCopy laid them out,
    // after the submission completed).
    void store(std::span<const uint32_t> wanted, const char* bytes);
    // Point i as the device holds it (device input: fetched first).
    [[nodiscard]] glm::vec3 searched(uint32_t i) const;
    // Point i as the caller gave it, in double (host arrays: the searched float).
    [[nodiscard]] glm::dvec3 original(uint32_t i) const;
    // Every point as searched, by input index. Device input: the index's
    // records read back (16 bytes per point; per-point output only).
    [[nodiscard]] std::span<const glm::vec3> all();

private:
    std::span<const glm::vec3> m_host;
    size_t m_n = 0;
    gpu::Context* m_ctx = nullptr;
    DeviceInput m_view;
    glm::dvec3 m_origin{0.0};
    const PointIndex* m_ix = nullptr;
    std::unordered_map<uint32_t, glm::dvec3> m_fetched;
    std::vector<glm::vec3> m_all;
};

}  // namespace rthdist::gpu_algo
