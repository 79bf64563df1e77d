// The boundary voxels of a label box on a Vulkan compute device: one compute
// pass (shaders/masks_gpu/boundary.comp) writes a bitmask, bit i set when voxel i
// of the box is selected and has a neighbour under the connectivity that is
// not selected or lies outside the box (masks/boundary.hpp's definition, for
// a box of whole rows outside which nothing is selected).
//
// Needs any Vulkan 1.3 compute device with buffer device addresses
// (gpu::computeRequirements, as the splat renderer); no ray tracing; lavapipe
// qualifies. Its own device, opened on the index the caller's Engine uses.
// No Vulkan types in this header. Internal to the masks tools and tests.
//
// Limits: a box of at most 2^32 - 1 voxels (32-bit voxel indices in the
// shader); more, or a buffer past the device's limits -> kOutOfMemory naming
// it (the caller may extract on the host instead).
// Threading: one BoundaryPass per thread; the staging and bitmask memory it
// returns belongs to it until the next call.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::masks_gpu {

// The box the pass reads: nx * ny * nz labels, x fastest, 8-bit (four to a
// 32-bit word) or 32-bit, written by the caller into stagingFor()'s memory.
struct LabelBox {
    uint32_t nx = 0, ny = 0, nz = 0;
    bool eightBit = true;
    int32_t value = 1;       // the selected label, unless anyNonZero
    bool anyNonZero = true;  // every non-zero label is selected
    int connectivity = 6;    // 6, 18 or 26

    [[nodiscard]] uint64_t voxels() const { return uint64_t(nx) * ny * nz; }
    [[nodiscard]] uint64_t labelBytes() const { return voxels() * (eightBit ? 1 : 4); }
};

class BoundaryPass {
public:
    // deviceIndex -1 = the best usable device (discrete first). kNoDevice
    // with every rejected device's reasons when none qualifies.
    [[nodiscard]] static Result<std::unique_ptr<BoundaryPass>> create(int deviceIndex = -1,
                                                                      bool validation = false);
    ~BoundaryPass();
    BoundaryPass(const BoundaryPass&) = delete;
    BoundaryPass& operator=(const BoundaryPass&) = delete;

    // Host memory for the labels of `boxes` (one span of box.labelBytes()
    // bytes each) that the next mark(boxes) uploads: the caller writes each
    // box's labels there.
    [[nodiscard]] Result<std::vector<std::span<uint8_t>>> stagingFor(std::span<const LabelBox> boxes);
    // The boundary bitmask of each box staged by stagingFor (the same boxes:
    // dimensions and label widths), all in one submission: ceil(voxels / 32)
    // words per box, bit (i & 31) of word (i >> 5) for voxel i. Valid until
    // the next call.
    [[nodiscard]] Result<std::vector<std::span<const uint32_t>>> mark(std::span<const LabelBox> boxes);

    [[nodiscard]] const std::string& deviceName() const;
    // Device milliseconds of the last mark() (upload, pass, read-back).
    [[nodiscard]] double lastGpuMs() const;
    // Messages of the validation layer so far (0 when validation is off).
    [[nodiscard]] uint64_t validationMessageCount() const;

private:
    struct Impl;
    explicit BoundaryPass(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

}  // namespace rthdist::masks_gpu
