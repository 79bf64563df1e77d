#include "render/splat_renderer.hpp"

#include <array>
#include <cstddef>
#include <cstring>
#include <limits>
#include <new>
#include <optional>

#include "gpu/buffer.hpp"
#include "gpu/compute_pipeline.hpp"
#include "gpu/context.hpp"
#include "render/splat_shared.h"

// SPIR-V embedded at build time (cmake/Shaders.cmake).
#include "splat.comp.h"

namespace rthdist::render {

namespace sh = shared;
static_assert(sizeof(sh::SplatPush) == 96 && offsetof(sh::SplatPush, centreX) == 24 &&
              offsetof(sh::SplatPush, count) == 84);

namespace {

std::optional<Error> checkArguments(size_t points, size_t colours, int width, int height, float radius) {
    if (points != colours)
        return Error{ErrorCode::kInvalidArgument, "splat: " + std::to_string(points) + " points but " +
                                                      std::to_string(colours) + " colours"};
    if (width < 1 || height < 1 || !(radius > 0.0f))
        return Error{ErrorCode::kInvalidArgument, "splat: the image must be at least 1x1 and the radius > 0"};
    if (points > std::numeric_limits<uint32_t>::max())
        return Error{ErrorCode::kInvalidArgument, "splat: more than 2^32-1 points"};
    return std::nullopt;
}

// The camera and image of the pass; the buffer addresses are the caller's.
sh::SplatPush cameraPush(const SplatCamera& camera, float radius, size_t count, int width, int height) {
    sh::SplatPush pc{};
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
    pc.count = uint32_t(count);
    pc.width = uint32_t(width);
    pc.height = uint32_t(height);
    return pc;
}

// Splits the pixel words into depth and colour; ~0 words stay empty.
SplatFrame unpackFrame(const uint64_t* words, int width, int height) {
    const size_t pixelCount = size_t(width) * size_t(height);
    SplatFrame frame;
    frame.width = width;
    frame.height = height;
    frame.depth.assign(pixelCount, std::numeric_limits<float>::infinity());
    frame.rgba.assign(pixelCount, 0u);
    for (size_t i = 0; i < pixelCount; ++i) {
        const uint64_t w = words[i];
        if (w == ~uint64_t(0)) continue;
        const uint32_t depthBits = uint32_t(w >> 32);
        std::memcpy(&frame.depth[i], &depthBits, sizeof depthBits);
        frame.rgba[i] = uint32_t(w);
    }
    return frame;
}

}  // namespace

struct SplatRenderer::Impl {
    std::unique_ptr<gpu::Context> ctx;  // declared first: outlives the pipeline
    gpu::UniquePipelineLayout layout;
    gpu::UniquePipeline pipeline;

    void createPipeline() {
        layout =
            gpu::createPipelineLayout(ctx->device(), {}, VK_SHADER_STAGE_COMPUTE_BIT, sizeof(sh::SplatPush));
        pipeline =
            gpu::createComputePipeline(*ctx, k_spv_splat_comp, layout.get(), VK_NULL_HANDLE, 0, "splat");
    }

    // Clears the pixel words, splats every point into them and copies them
    // to `readBack` (the host-read barrier is Context::submitAndWait's).
    void cmdSplat(VkCommandBuffer cmd, const sh::SplatPush& pc, const gpu::Buffer& pixels,
                  const gpu::Buffer& readBack) const {
        {
            gpu::ScopedLabel label(*ctx, cmd, "splat: clear");
            vkCmdFillBuffer(cmd, pixels.handle(), 0, VK_WHOLE_SIZE, ~0u);  // every word ~0: empty
            // All transfer stages: where vkCmdFillBuffer runs (clear or copy)
            // changed across spec versions and validation layers.
            gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                             VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
        if (pc.count > 0) {
            gpu::ScopedLabel label(*ctx, cmd, "splat: points");
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.get());
            vkCmdPushConstants(cmd, layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
            vkCmdDispatch(cmd, (pc.count + RTHDIST_SPLAT_WG - 1) / RTHDIST_SPLAT_WG, 1, 1);
        }
        gpu::ScopedLabel label(*ctx, cmd, "splat: read back");
        gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                         VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        const VkBufferCopy copy{0, 0, pixels.size()};
        vkCmdCopyBuffer(cmd, pixels.handle(), readBack.handle(), 1, &copy);
    }

    // Throws VulkanError, LimitError or std::bad_alloc on failure.
    SplatFrame renderFrame(std::span<const glm::vec3> points, std::span<const uint32_t> rgba,
                           const SplatCamera& camera, int width, int height, float radius) {
        const VkDeviceSize pixelBytes = VkDeviceSize(width) * VkDeviceSize(height) * sizeof(uint64_t);
        // Inputs are read once by the shader, so they stay in host memory
        // (no staging copy); the pixel words live on the device.
        gpu::Buffer pointBuf(*ctx, points.size_bytes(), gpu::kStorageUsage, gpu::MemoryKind::kHost);
        gpu::Buffer colourBuf(*ctx, rgba.size_bytes(), gpu::kStorageUsage, gpu::MemoryKind::kHost);
        gpu::Buffer pixelBuf(*ctx, pixelBytes, gpu::kStorageUsage, gpu::MemoryKind::kDevice);
        gpu::Buffer readBack(*ctx, pixelBytes, gpu::kStorageUsage, gpu::MemoryKind::kReadback);
        static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
        if (!points.empty()) std::memcpy(pointBuf.mapped(), points.data(), points.size_bytes());
        if (!rgba.empty()) std::memcpy(colourBuf.mapped(), rgba.data(), rgba.size_bytes());

        sh::SplatPush pc = cameraPush(camera, radius, points.size(), width, height);
        pc.points = pointBuf.address();
        pc.colours = colourBuf.address();
        pc.pixels = pixelBuf.address();
        VkCommandBuffer cmd = ctx->begin();
        cmdSplat(cmd, pc, pixelBuf, readBack);
        ctx->submitAndWait(cmd);
        return unpackFrame(static_cast<const uint64_t*>(readBack.mapped()), width, height);
    }
};

SplatRenderer::SplatRenderer(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
SplatRenderer::~SplatRenderer() = default;

const std::string& SplatRenderer::deviceName() const { return m_impl->ctx->deviceName(); }
uint64_t SplatRenderer::validationMessageCount() const { return m_impl->ctx->validationMessageCount(); }

Result<std::unique_ptr<SplatRenderer>> SplatRenderer::create(int deviceIndex, bool validation) {
    // Compute only: no ray tracing, so any Vulkan 1.3 compute device with
    // 64-bit buffer atomics qualifies.
    const std::array<gpu::DeviceRequirements, 1> needs{gpu::computeRequirements()};
    auto ctx =
        gpu::Context::create(needs, "the splat renderer", deviceIndex, validation, tuningFromEnvironment());
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
    if (std::optional<Error> err = checkArguments(points.size(), rgba.size(), width, height, radius))
        return *err;
    try {
        return m_impl->renderFrame(points, rgba, camera, width, height, radius);
    } catch (const gpu::VulkanError& e) {
        return Error{e.outOfMemory() ? ErrorCode::kOutOfMemory : ErrorCode::kInternal, e.what()};
    } catch (const gpu::LimitError& e) {  // an image past the device's maxBufferSize
        return Error{ErrorCode::kOutOfMemory, std::string("splat: ") + e.what()};
    } catch (const std::bad_alloc&) {
        return Error{ErrorCode::kOutOfMemory, "splat: host memory for a " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " image"};
    }
}

}  // namespace rthdist::render
