// BLAS over procedural AABBs (one per occupied cell) and a one-instance TLAS.
// Between radius iterations the boxes only grow, so the BLAS is refit
// (update build) instead of rebuilt when the driver allows updates.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.hpp"
#include "gpu/unique_handle.hpp"

namespace rthdist::gpu {

class Context;

class AccelStructures {
public:
    explicit AccelStructures(Context& ctx) : m_ctx(ctx) {}
    ~AccelStructures() = default;
    AccelStructures(const AccelStructures&) = delete;
    AccelStructures& operator=(const AccelStructures&) = delete;

    // Records a BLAS build over `count` VkAabbPositionsKHR at `aabbs` (update
    // when `update` and a BLAS of the same count exists), then the TLAS build.
    // Returns true when the TLAS handle changed (descriptor must be rebound).
    bool cmdBuild(VkCommandBuffer cmd, VkDeviceAddress aabbs, uint32_t count, bool update,
                  VkPipelineStageFlags shaderStages);
    [[nodiscard]] VkAccelerationStructureKHR tlas() const { return m_tlas.get(); }
    // Releases both structures and their memory now.
    void release();

private:
    // Creates an acceleration structure of `size` bytes in `storage`, which
    // is (re)allocated when too small.
    UniqueAccel createIn(Buffer& storage, VkDeviceSize size, VkAccelerationStructureTypeKHR type);
    // The scratch buffer, grown to `bytes` when smaller; its aligned address.
    VkDeviceAddress scratchFor(VkDeviceSize bytes);
    // The TLAS's one instance: the BLAS, identity transform.
    void writeInstance();

    Context& m_ctx;
    Buffer m_blasBuffer, m_tlasBuffer, m_scratch, m_instances;
    UniqueAccel m_blas, m_tlas;  // declared after their storage: destroyed before it
    uint32_t m_count = 0;
};

}  // namespace rthdist::gpu
