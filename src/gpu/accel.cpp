#include "gpu/accel.hpp"

#include <algorithm>
#include <cstring>

#include "gpu/context.hpp"
#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

namespace {

VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

// The geometry, build description and sizes of one acceleration structure.
// info.pGeometries points at geometry, so a BuildDesc stays where it is made.
struct BuildDesc {
    VkAccelerationStructureGeometryKHR geometry =
        vkStruct<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
    VkAccelerationStructureBuildGeometryInfoKHR info = vkStruct<VkAccelerationStructureBuildGeometryInfoKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR);
    VkAccelerationStructureBuildSizesInfoKHR sizes = vkStruct<VkAccelerationStructureBuildSizesInfoKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR);
    uint32_t primitives = 0;

    BuildDesc() = default;
    BuildDesc(const BuildDesc&) = delete;
    BuildDesc& operator=(const BuildDesc&) = delete;

    void querySizes(const Context& ctx) {
        info.geometryCount = 1;
        info.pGeometries = &geometry;
        ctx.rt().getBuildSizes(ctx.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                               &primitives, &sizes);
    }
    void cmdBuild(const Context& ctx, VkCommandBuffer cmd) const {
        const VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
        const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
        ctx.rt().cmdBuildAccel(cmd, 1, &info, &ranges);
    }
};

// A BLAS over `count` opaque VkAabbPositionsKHR at `aabbs`, updatable.
void describeBlas(BuildDesc& d, VkDeviceAddress aabbs, uint32_t count) {
    d.geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
    d.geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    d.geometry.geometry.aabbs = vkStruct<VkAccelerationStructureGeometryAabbsDataKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR);
    d.geometry.geometry.aabbs.data.deviceAddress = aabbs;
    d.geometry.geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
    d.info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    // Built for speed of building: each call builds its BLAS (each radius
    // refits it) and traces it once. On an H200 (session 25) the surface
    // search's builds took 0.85 -> 0.56 ms (202,520 triangles, two radii)
    // and the Dragon pair moved 0.5 apart searched in 2.59 -> 2.19 ms,
    // the rays no slower.
    d.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR |
                   VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
    d.primitives = count;
}

// A TLAS of one instance (its address is set once the instance is written).
void describeTlas(BuildDesc& d) {
    d.geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    d.geometry.geometry.instances = vkStruct<VkAccelerationStructureGeometryInstancesDataKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR);
    d.info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    d.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    d.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    d.primitives = 1;
}

}  // namespace

UniqueAccel AccelStructures::createIn(Buffer& storage, VkDeviceSize size,
                                      VkAccelerationStructureTypeKHR type) {
    if (storage.size() < size)
        storage =
            Buffer(m_ctx, size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, MemoryKind::kDevice);
    VkAccelerationStructureCreateInfoKHR ci = vkStruct<VkAccelerationStructureCreateInfoKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR);
    ci.buffer = storage.handle();
    ci.size = size;
    ci.type = type;
    VkAccelerationStructureKHR as;
    RTHDIST_VK_CHECK(m_ctx.rt().createAccel(m_ctx.device(), &ci, nullptr, &as));
    return UniqueAccel(as, {m_ctx.device(), m_ctx.rt().destroyAccel});
}

VkDeviceAddress AccelStructures::scratchFor(VkDeviceSize bytes) {
    const VkDeviceSize align =
        std::max<VkDeviceSize>(128, m_ctx.asProps().minAccelerationStructureScratchOffsetAlignment);
    if (m_scratch.size() < bytes + align)
        m_scratch = Buffer(m_ctx, bytes + align, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::kDevice);
    return alignUp(m_scratch.address(), align);
}

void AccelStructures::writeInstance() {
    if (!m_instances)
        m_instances =
            Buffer(m_ctx, sizeof(VkAccelerationStructureInstanceKHR),
                   VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR, MemoryKind::kHost);
    VkAccelerationStructureDeviceAddressInfoKHR ai = vkStruct<VkAccelerationStructureDeviceAddressInfoKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR);
    ai.accelerationStructure = m_blas.get();
    VkAccelerationStructureInstanceKHR inst{};
    inst.transform.matrix[0][0] = inst.transform.matrix[1][1] = inst.transform.matrix[2][2] = 1.0f;
    inst.mask = 0xff;
    inst.flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    inst.accelerationStructureReference = m_ctx.rt().getAccelAddress(m_ctx.device(), &ai);
    std::memcpy(m_instances.mapped(), &inst, sizeof(inst));
}

void AccelStructures::release() {
    m_tlas.reset();
    m_blas.reset();
    m_blasBuffer.reset();
    m_tlasBuffer.reset();
    m_scratch.reset();
    m_instances.reset();
    m_count = 0;
}

bool AccelStructures::cmdBuild(VkCommandBuffer cmd, VkDeviceAddress aabbs, uint32_t count, bool update,
                               VkPipelineStageFlags shaderStages) {
    requireWithin(count, m_ctx.limits().maxPrimitives, "a BLAS of search cells", "maxPrimitiveCount");
    const bool doUpdate = update && m_blas && count == m_count;
    BuildDesc blas, tlas;
    describeBlas(blas, aabbs, count);
    blas.querySizes(m_ctx);
    describeTlas(tlas);
    tlas.querySizes(m_ctx);

    if (!doUpdate) {
        m_blas.reset();  // before its storage may be reallocated
        m_blas = createIn(m_blasBuffer, blas.sizes.accelerationStructureSize,
                          VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
        m_count = count;
    }
    // One scratch buffer serves both builds, one after the other.
    const VkDeviceAddress scratch = scratchFor(
        std::max({blas.sizes.buildScratchSize, blas.sizes.updateScratchSize, tlas.sizes.buildScratchSize}));

    blas.info.mode = doUpdate ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR
                              : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    blas.info.srcAccelerationStructure = doUpdate ? m_blas.get() : VK_NULL_HANDLE;
    blas.info.dstAccelerationStructure = m_blas.get();
    blas.info.scratchData.deviceAddress = scratch;
    blas.cmdBuild(m_ctx, cmd);
    // The TLAS build reads the BLAS and reuses the scratch memory.
    cmdBarrier2(
        cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
        VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
        VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
        VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);

    writeInstance();
    tlas.geometry.geometry.instances.data.deviceAddress = m_instances.address();
    const bool rebound = !m_tlas;
    if (!m_tlas)
        m_tlas = createIn(m_tlasBuffer, tlas.sizes.accelerationStructureSize,
                          VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
    tlas.info.dstAccelerationStructure = m_tlas.get();
    tlas.info.scratchData.deviceAddress = scratch;
    tlas.cmdBuild(m_ctx, cmd);
    cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, shaderStages,
                VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    return rebound;
}

}  // namespace rthdist::gpu
