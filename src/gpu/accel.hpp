// BLAS over procedural AABBs (one per occupied cell) and a one-instance TLAS.
// Between radius iterations the boxes only grow, so the BLAS is refit
// (update build) instead of rebuilt when the driver allows updates.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.hpp"

namespace rthdist::gpu {

class Context;

class AccelStructures {
public:
    explicit AccelStructures(Context& ctx) : m_ctx(ctx) {}
    ~AccelStructures() { release(); }
    AccelStructures(const AccelStructures&) = delete;
    AccelStructures& operator=(const AccelStructures&) = delete;

    // Records a BLAS build over `count` VkAabbPositionsKHR at `aabbs` (update
    // when `update` and a BLAS of the same count exists), then the TLAS build.
    // Returns true when the TLAS handle changed (descriptor must be rebound).
    bool cmdBuild(VkCommandBuffer cmd, VkDeviceAddress aabbs, uint32_t count, bool update,
                  VkPipelineStageFlags shaderStages);
    [[nodiscard]] VkAccelerationStructureKHR tlas() const { return m_tlas; }
    void release();

private:
    // Creates an acceleration structure of `size` bytes in `storage`, which
    // is (re)allocated when too small.
    VkAccelerationStructureKHR createIn(Buffer& storage, VkDeviceSize size,
                                        VkAccelerationStructureTypeKHR type);

    Context& m_ctx;
    VkAccelerationStructureKHR m_blas = VK_NULL_HANDLE, m_tlas = VK_NULL_HANDLE;
    Buffer m_blasBuffer, m_tlasBuffer, m_scratch, m_instances;
    uint32_t m_count = 0;
};

}  // namespace rthdist::gpu
