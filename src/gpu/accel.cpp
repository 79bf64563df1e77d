#include "gpu/accel.hpp"

#include <algorithm>
#include <cstring>

#include "gpu/context.hpp"

namespace rthdist::gpu {

namespace {

VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

}  // namespace

VkAccelerationStructureKHR AccelStructures::createIn(Buffer& storage, VkDeviceSize size,
                                                     VkAccelerationStructureTypeKHR type) {
    if (storage.size() < size)
        storage =
            Buffer(m_ctx, size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, MemoryKind::kDevice);
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    ci.buffer = storage.handle();
    ci.size = size;
    ci.type = type;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    RTHDIST_VK_CHECK(m_ctx.rt().createAccel(m_ctx.device(), &ci, nullptr, &as));
    return as;
}

void AccelStructures::release() {
    const RtFunctions& rt = m_ctx.rt();
    if (m_tlas) rt.destroyAccel(m_ctx.device(), m_tlas, nullptr);
    if (m_blas) rt.destroyAccel(m_ctx.device(), m_blas, nullptr);
    m_tlas = m_blas = VK_NULL_HANDLE;
    m_blasBuffer.reset();
    m_tlasBuffer.reset();
    m_scratch.reset();
    m_instances.reset();
    m_count = 0;
}

bool AccelStructures::cmdBuild(VkCommandBuffer cmd, VkDeviceAddress aabbs, uint32_t count, bool update,
                               VkPipelineStageFlags shaderStages) {
    requireWithin(count, m_ctx.limits().maxPrimitives, "a BLAS of search cells", "maxPrimitiveCount");
    const RtFunctions& rt = m_ctx.rt();
    VkDevice d = m_ctx.device();
    const VkDeviceSize scratchAlign =
        std::max<VkDeviceSize>(128, m_ctx.asProps().minAccelerationStructureScratchOffsetAlignment);
    const bool doUpdate = update && m_blas && count == m_count;
    bool rebound = false;

    VkAccelerationStructureGeometryKHR geom{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geom.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    geom.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    geom.geometry.aabbs = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR};
    geom.geometry.aabbs.data.deviceAddress = aabbs;
    geom.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
    VkAccelerationStructureBuildGeometryInfoKHR bi{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    bi.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    bi.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
               VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
    bi.geometryCount = 1;
    bi.pGeometries = &geom;
    VkAccelerationStructureBuildSizesInfoKHR sizes{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    rt.getBuildSizes(d, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &bi, &count, &sizes);

    // TLAS sizes (one instance) to size a scratch buffer shared by both builds.
    VkAccelerationStructureGeometryKHR tgeom{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    tgeom.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    tgeom.geometry.instances = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
    VkAccelerationStructureBuildGeometryInfoKHR tbi{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    tbi.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    tbi.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    tbi.geometryCount = 1;
    tbi.pGeometries = &tgeom;
    const uint32_t one = 1;
    VkAccelerationStructureBuildSizesInfoKHR tsizes{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    rt.getBuildSizes(d, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &tbi, &one, &tsizes);

    if (!doUpdate) {
        if (m_blas) rt.destroyAccel(d, m_blas, nullptr);
        m_blas = VK_NULL_HANDLE;
        m_blas = createIn(m_blasBuffer, sizes.accelerationStructureSize,
                          VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
        m_count = count;
    }
    VkDeviceSize scratchNeed =
        std::max({sizes.buildScratchSize, sizes.updateScratchSize, tsizes.buildScratchSize});
    if (m_scratch.size() < scratchNeed + scratchAlign)
        m_scratch = Buffer(m_ctx, scratchNeed + scratchAlign, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                           MemoryKind::kDevice);
    const VkDeviceAddress scratch = alignUp(m_scratch.address(), scratchAlign);

    bi.mode = doUpdate ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR
                       : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    bi.srcAccelerationStructure = doUpdate ? m_blas : VK_NULL_HANDLE;
    bi.dstAccelerationStructure = m_blas;
    bi.scratchData.deviceAddress = scratch;
    VkAccelerationStructureBuildRangeInfoKHR range{count, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    rt.cmdBuildAccel(cmd, 1, &bi, &ranges);

    // The TLAS build reads the BLAS and reuses the scratch memory.
    cmdBarrier(
        cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
        VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
        VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
        VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);

    if (!m_instances) {
        m_instances =
            Buffer(m_ctx, sizeof(VkAccelerationStructureInstanceKHR),
                   VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR, MemoryKind::kHost);
    }
    VkAccelerationStructureDeviceAddressInfoKHR ai{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    ai.accelerationStructure = m_blas;
    VkAccelerationStructureInstanceKHR inst{};
    inst.transform.matrix[0][0] = inst.transform.matrix[1][1] = inst.transform.matrix[2][2] = 1.0f;
    inst.mask = 0xff;
    inst.flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    inst.accelerationStructureReference = rt.getAccelAddress(d, &ai);
    std::memcpy(m_instances.mapped(), &inst, sizeof(inst));

    if (!m_tlas) {
        m_tlas = createIn(m_tlasBuffer, tsizes.accelerationStructureSize,
                          VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
        rebound = true;
    }
    tgeom.geometry.instances.data.deviceAddress = m_instances.address();
    tbi.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    tbi.dstAccelerationStructure = m_tlas;
    tbi.scratchData.deviceAddress = scratch;
    VkAccelerationStructureBuildRangeInfoKHR trange{1, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* tranges = &trange;
    rt.cmdBuildAccel(cmd, 1, &tbi, &tranges);
    cmdBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
               VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, shaderStages,
               VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    return rebound;
}

}  // namespace rthdist::gpu
