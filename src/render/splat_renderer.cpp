#include "render/splat_renderer.hpp"

#include <cstddef>
#include <cstring>
#include <limits>
#include <new>

#include "gpu/buffer.hpp"
#include "gpu/context.hpp"
#include "render/splat_shared.h"

// SPIR-V embedded at build time (cmake/Shaders.cmake).
#include "splat.comp.h"

namespace rthdist::render {

namespace sh = shared;
static_assert(sizeof(sh::SplatPush) == 96 && offsetof(sh::SplatPush, centreX) == 24 &&
              offsetof(sh::SplatPush, count) == 84);

struct SplatRenderer::Impl {
    std::unique_ptr<gpu::Context> ctx;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;

    ~Impl() {
        if (!ctx) return;
        if (pipeline) vkDestroyPipeline(ctx->device(), pipeline, nullptr);
        if (layout) vkDestroyPipelineLayout(ctx->device(), layout, nullptr);
    }

    void createPipeline() {
        VkDevice d = ctx->device();
        VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(sh::SplatPush)};
        VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        pl.pushConstantRangeCount = 1;
        pl.pPushConstantRanges = &range;
        RTHDIST_VK_CHECK(vkCreatePipelineLayout(d, &pl, nullptr, &layout));

        VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        mi.codeSize = sizeof(k_spv_splat_comp);
        mi.pCode = k_spv_splat_comp;
        VkShaderModule module;
        RTHDIST_VK_CHECK(vkCreateShaderModule(d, &mi, nullptr, &module));
        VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
        ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        ci.stage.module = module;
        ci.stage.pName = "main";
        ci.layout = layout;
        VkResult r = vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline);
        vkDestroyShaderModule(d, module, nullptr);
        RTHDIST_VK_CHECK(r);
    }
};

SplatRenderer::SplatRenderer(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
SplatRenderer::~SplatRenderer() = default;

const std::string& SplatRenderer::deviceName() const { return m_impl->ctx->deviceName(); }
uint64_t SplatRenderer::validationMessageCount() const { return m_impl->ctx->validationMessageCount(); }

Result<std::unique_ptr<SplatRenderer>> SplatRenderer::create(int deviceIndex, bool validation) {
    auto ctx = gpu::Context::create(Backend::kAuto, deviceIndex, validation);
    if (!ctx) return ctx.error();
    auto impl = std::make_unique<Impl>();
    impl->ctx = std::move(ctx.value());
    try {
        impl->createPipeline();
    } catch (const gpu::VulkanError& e) {
        return Error{ErrorCode::kInternal, e.what()};
    }
    return std::unique_ptr<SplatRenderer>(new SplatRenderer(std::move(impl)));
}

Result<SplatFrame> SplatRenderer::render(std::span<const glm::vec3> points, std::span<const uint32_t> rgba,
                                         const SplatCamera& camera, int width, int height, float radius) {
    if (points.size() != rgba.size())
        return Error{ErrorCode::kInvalidArgument, "splat: " + std::to_string(points.size()) + " points but " +
                                                      std::to_string(rgba.size()) + " colours"};
    if (width < 1 || height < 1 || !(radius > 0.0f))
        return Error{ErrorCode::kInvalidArgument, "splat: the image must be at least 1x1 and the radius > 0"};
    if (points.size() > std::numeric_limits<uint32_t>::max())
        return Error{ErrorCode::kInvalidArgument, "splat: more than 2^32-1 points"};

    gpu::Context& ctx = *m_impl->ctx;
    const size_t pixelCount = size_t(width) * size_t(height);
    try {
        // Inputs are read once by the shader, so they stay in host memory
        // (no staging copy); the pixel words live on the device.
        gpu::Buffer pointBuf(ctx, points.size_bytes(), gpu::kStorageUsage, gpu::MemoryKind::kHost);
        gpu::Buffer colourBuf(ctx, rgba.size_bytes(), gpu::kStorageUsage, gpu::MemoryKind::kHost);
        gpu::Buffer pixelBuf(ctx, pixelCount * sizeof(uint64_t), gpu::kStorageUsage,
                             gpu::MemoryKind::kDevice);
        gpu::Buffer readBack(ctx, pixelCount * sizeof(uint64_t), gpu::kStorageUsage, gpu::MemoryKind::kHost);
        static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
        if (!points.empty()) std::memcpy(pointBuf.mapped(), points.data(), points.size_bytes());
        if (!rgba.empty()) std::memcpy(colourBuf.mapped(), rgba.data(), rgba.size_bytes());

        sh::SplatPush pc{};
        pc.points = pointBuf.address();
        pc.colours = colourBuf.address();
        pc.pixels = pixelBuf.address();
        pc.centreX = camera.centre.x;
        pc.centreY = camera.centre.y;
        pc.centreZ = camera.centre.z;
        pc.cosYaw = camera.cosYaw;
        pc.sinYaw = camera.sinYaw;
        pc.cosPitch = camera.cosPitch;
        pc.sinPitch = camera.sinPitch;
        pc.loX = camera.loX;
        pc.hiY = camera.hiY;
        pc.hiZ = camera.hiZ;
        pc.scale = camera.scale;
        pc.offX = camera.offX;
        pc.offY = camera.offY;
        pc.invDepthExtent = camera.invDepthExtent;
        pc.radius = radius;
        pc.count = uint32_t(points.size());
        pc.width = uint32_t(width);
        pc.height = uint32_t(height);

        VkCommandBuffer cmd = ctx.begin();
        vkCmdFillBuffer(cmd, pixelBuf.handle(), 0, VK_WHOLE_SIZE, ~0u);  // every word ~0: empty
        gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        if (pc.count > 0) {
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_impl->pipeline);
            vkCmdPushConstants(cmd, m_impl->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
            vkCmdDispatch(cmd, (pc.count + RTHDIST_SPLAT_WG - 1) / RTHDIST_SPLAT_WG, 1, 1);
        }
        gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        VkBufferCopy copy{0, 0, pixelCount * sizeof(uint64_t)};
        vkCmdCopyBuffer(cmd, pixelBuf.handle(), readBack.handle(), 1, &copy);
        gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        ctx.submitAndWait(cmd);

        SplatFrame frame;
        frame.width = width;
        frame.height = height;
        frame.depth.assign(pixelCount, std::numeric_limits<float>::infinity());
        frame.rgba.assign(pixelCount, 0u);
        const auto* words = static_cast<const uint64_t*>(readBack.mapped());
        for (size_t i = 0; i < pixelCount; ++i) {
            const uint64_t w = words[i];
            if (w == ~uint64_t(0)) continue;
            const uint32_t depthBits = uint32_t(w >> 32);
            std::memcpy(&frame.depth[i], &depthBits, sizeof depthBits);
            frame.rgba[i] = uint32_t(w);
        }
        return frame;
    } catch (const gpu::VulkanError& e) {
        const bool memory =
            e.result() == VK_ERROR_OUT_OF_DEVICE_MEMORY || e.result() == VK_ERROR_OUT_OF_HOST_MEMORY;
        return Error{memory ? ErrorCode::kOutOfMemory : ErrorCode::kInternal, e.what()};
    } catch (const std::bad_alloc&) {
        return Error{ErrorCode::kOutOfMemory, "splat: host memory for a " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " image"};
    }
}

}  // namespace rthdist::render
