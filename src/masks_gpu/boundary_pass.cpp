// The boundary pass (boundary_pass.hpp): the box is staged in host-visible
// memory, copied to the device, marked by shaders/masks_gpu/boundary.comp and the
// bitmask copied back, all in one submission. Buffers grow to the largest box
// seen and are reused by later calls.
#include "masks_gpu/boundary_pass.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <new>
#include <optional>
#include <vector>

#include "gpu/buffer.hpp"
#include "gpu/compute_pipeline.hpp"
#include "gpu/context.hpp"
#include "masks_gpu/boundary_shared.h"

// SPIR-V embedded at build time (cmake/Shaders.cmake).
#include "boundary.comp.h"

namespace rthdist::masks_gpu {

namespace sh = shared;
static_assert(sizeof(sh::BoundaryPush) == 56 && offsetof(sh::BoundaryPush, nx) == 16);

namespace {

uint64_t wordsOf(const LabelBox& box) { return (box.voxels() + 31) / 32; }
uint64_t labelWordsOf(const LabelBox& box) { return (box.labelBytes() + 3) / 4; }

constexpr uint64_t kAlign = 256;  // every box's region starts at a multiple (device addresses)
uint64_t aligned(uint64_t bytes) { return (bytes + kAlign - 1) / kAlign * kAlign; }

// Where each box's labels and bitmask sit in the shared buffers.
struct Layout {
    std::vector<uint64_t> labelAt, bitAt;
    uint64_t labelBytes = 0, bitBytes = 0;

    explicit Layout(std::span<const LabelBox> boxes) {
        for (const LabelBox& b : boxes) {
            labelAt.push_back(labelBytes);
            bitAt.push_back(bitBytes);
            labelBytes += aligned(labelWordsOf(b) * 4);
            bitBytes += aligned(wordsOf(b) * 4);
        }
    }
};

std::optional<Error> checkBox(const LabelBox& box) {
    if (box.connectivity != 6 && box.connectivity != 18 && box.connectivity != 26)
        return Error{ErrorCode::kInvalidArgument, "masks: connectivity must be 6, 18 or 26"};
    if (box.voxels() == 0) return Error{ErrorCode::kInvalidArgument, "masks: an empty label box"};
    if (box.voxels() > std::numeric_limits<uint32_t>::max())
        return Error{ErrorCode::kOutOfMemory,
                     "masks: the GPU boundary pass takes boxes of at most 2^32 - 1 voxels, not " +
                         std::to_string(box.voxels())};
    return std::nullopt;
}

// A buffer of at least `bytes`, grown (never shrunk) in place.
void ensure(gpu::Context& ctx, gpu::Buffer& buffer, uint64_t bytes, gpu::MemoryKind kind) {
    if (buffer && buffer.size() >= bytes) return;
    buffer.reset();
    buffer = gpu::Buffer(ctx, std::max<uint64_t>(bytes, 4096), gpu::kStorageUsage, kind);
}

Error errorOf(const gpu::VulkanError& e) {
    Error err{e.outOfMemory() ? ErrorCode::kOutOfMemory : ErrorCode::kInternal,
              std::string("masks: ") + e.what()};
    err.vkResult = int(e.result());
    return err;
}

}  // namespace

struct BoundaryPass::Impl {
    std::unique_ptr<gpu::Context> ctx;  // declared first: outlives the pipeline and buffers
    gpu::UniquePipelineLayout layout;
    gpu::UniquePipeline pipeline;
    gpu::Buffer staging, labels, bits, readBack;

    void createPipeline() {
        layout = gpu::createPipelineLayout(ctx->device(), {}, VK_SHADER_STAGE_COMPUTE_BIT,
                                           sizeof(sh::BoundaryPush));
        pipeline = gpu::createComputePipeline(*ctx, k_spv_boundary_comp, layout.get(), VK_NULL_HANDLE, 0,
                                              "masks boundary");
    }

    sh::BoundaryPush pushOf(const LabelBox& box, uint64_t labelAt, uint64_t bitAt) const {
        sh::BoundaryPush pc{};
        pc.labels = labels.address() + labelAt;
        pc.bits = bits.address() + bitAt;
        pc.nx = box.nx;
        pc.ny = box.ny;
        pc.nz = box.nz;
        pc.words = uint32_t(wordsOf(box));
        pc.value = box.value;
        pc.anyNonZero = box.anyNonZero ? 1u : 0u;
        pc.eightBit = box.eightBit ? 1u : 0u;
        pc.maxL1 = box.connectivity == 6 ? 1u : box.connectivity == 18 ? 2u : 3u;
        return pc;
    }

    // Upload, the pass of every box and read-back in one command buffer.
    void record(VkCommandBuffer cmd, std::span<const LabelBox> boxes, const Layout& at) {
        {
            gpu::ScopedLabel label(*ctx, cmd, "masks: upload");
            const VkBufferCopy copy{0, 0, at.labelBytes};
            vkCmdCopyBuffer(cmd, staging.handle(), labels.handle(), 1, &copy);
            gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
        }
        {
            gpu::ScopedLabel label(*ctx, cmd, "masks: boundary");
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.get());
            for (size_t k = 0; k < boxes.size(); ++k) {
                sh::BoundaryPush pc = pushOf(boxes[k], at.labelAt[k], at.bitAt[k]);
                const uint64_t groups = std::min<uint64_t>(
                    (pc.words + RTHDIST_BOUNDARY_WG - 1) / RTHDIST_BOUNDARY_WG, ctx->limits().maxGroupsX);
                pc.wordStride = uint32_t(groups * RTHDIST_BOUNDARY_WG);
                vkCmdPushConstants(cmd, layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
                vkCmdDispatch(cmd, uint32_t(groups), 1, 1);
            }
        }
        gpu::ScopedLabel label(*ctx, cmd, "masks: read back");
        gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        const VkBufferCopy copy{0, 0, at.bitBytes};
        vkCmdCopyBuffer(cmd, bits.handle(), readBack.handle(), 1, &copy);
    }
};

BoundaryPass::BoundaryPass(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
BoundaryPass::~BoundaryPass() = default;

const std::string& BoundaryPass::deviceName() const { return m_impl->ctx->deviceName(); }
double BoundaryPass::lastGpuMs() const { return m_impl->ctx->lastGpuMs(); }
uint64_t BoundaryPass::validationMessageCount() const { return m_impl->ctx->validationMessageCount(); }

Result<std::unique_ptr<BoundaryPass>> BoundaryPass::create(int deviceIndex, bool validation) {
    const std::array<gpu::DeviceRequirements, 1> needs{gpu::computeRequirements()};
    auto ctx = gpu::Context::create(needs, "the masks boundary pass", deviceIndex, validation,
                                    tuningFromEnvironment());
    if (!ctx) return ctx.error();
    auto impl = std::make_unique<Impl>();
    impl->ctx = std::move(ctx.value());
    try {
        impl->createPipeline();
    } catch (const gpu::VulkanError& e) {
        return errorOf(e);
    }
    return std::unique_ptr<BoundaryPass>(new BoundaryPass(std::move(impl)));
}

namespace {

std::optional<Error> checkBoxes(std::span<const LabelBox> boxes) {
    if (boxes.empty()) return Error{ErrorCode::kInvalidArgument, "masks: no label box"};
    for (const LabelBox& box : boxes)
        if (auto err = checkBox(box)) return err;
    return std::nullopt;
}

}  // namespace

Result<std::vector<std::span<uint8_t>>> BoundaryPass::stagingFor(std::span<const LabelBox> boxes) {
    if (auto err = checkBoxes(boxes)) return *err;
    Impl& m = *m_impl;
    const Layout at(boxes);
    try {
        ensure(*m.ctx, m.staging, at.labelBytes, gpu::MemoryKind::kHost);
    } catch (const gpu::VulkanError& e) {
        return errorOf(e);
    } catch (const gpu::LimitError& e) {
        return Error{ErrorCode::kOutOfMemory, std::string("masks: ") + e.what()};
    }
    std::vector<std::span<uint8_t>> out;
    for (size_t k = 0; k < boxes.size(); ++k)
        out.emplace_back(static_cast<uint8_t*>(m.staging.mapped()) + at.labelAt[k],
                         size_t(boxes[k].labelBytes()));
    return out;
}

Result<std::vector<std::span<const uint32_t>>> BoundaryPass::mark(std::span<const LabelBox> boxes) {
    if (auto err = checkBoxes(boxes)) return *err;
    Impl& m = *m_impl;
    const Layout at(boxes);
    if (!m.staging || m.staging.size() < at.labelBytes)
        return Error{ErrorCode::kInvalidArgument, "masks: mark() of boxes larger than those staged"};
    try {
        ensure(*m.ctx, m.labels, at.labelBytes, gpu::MemoryKind::kDevice);
        ensure(*m.ctx, m.bits, at.bitBytes, gpu::MemoryKind::kDevice);
        ensure(*m.ctx, m.readBack, at.bitBytes, gpu::MemoryKind::kReadback);
        VkCommandBuffer cmd = m.ctx->begin();
        m.record(cmd, boxes, at);
        m.ctx->submitAndWait(cmd);
    } catch (const gpu::VulkanError& e) {
        return errorOf(e);
    } catch (const gpu::LimitError& e) {
        return Error{ErrorCode::kOutOfMemory, std::string("masks: ") + e.what()};
    } catch (const std::bad_alloc&) {
        return Error{ErrorCode::kOutOfMemory, "masks: host memory for the boundary pass"};
    }
    std::vector<std::span<const uint32_t>> out;
    const auto* base = static_cast<const uint8_t*>(m.readBack.mapped());
    for (size_t k = 0; k < boxes.size(); ++k)
        out.emplace_back(reinterpret_cast<const uint32_t*>(base + at.bitAt[k]), size_t(wordsOf(boxes[k])));
    return out;
}

}  // namespace rthdist::masks_gpu
