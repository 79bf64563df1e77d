// Headless Vulkan point splatting for the CLI's pictures (issue 5).
//
// One compute pass: every point is projected with an orthographic camera
// (SplatCamera, the same one tools/cli/point_render uses in software) and
// written as a disc of `radius` pixels into a per-pixel 64-bit word with
// atomicMin((depth bits << 32) | RGBA8), so the nearest splat wins each pixel
// whatever order the invocations run in (equal depths keep the smaller colour
// word). The host reads the words back and splits them into depth and colour;
// shading and annotation stay with the caller.
//
// Needs any Vulkan 1.3 compute device with buffer device addresses, 64-bit
// integers and buffer atomics, scalar block layout and synchronization2
// (gpu::computeRequirements); no ray tracing. lavapipe qualifies. Command
// regions carry debug-utils labels ("splat: ...") for GPU captures. No Vulkan
// types in this header.
//
// Threading: one SplatRenderer per thread. Precision: float projection, so a
// splat may land a pixel away from the double-precision software renderer's.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::render {

// Rotate about `centre` by yaw (about +y) then pitch (about +x); camera x is
// right, y up, z towards the viewer. Screen x = offX + (x - loX) * scale,
// screen y = offY + (hiY - y) * scale, depth = (hiZ - z) * invDepthExtent,
// clamped to [0, 1] (0 nearest).
struct SplatCamera {
    glm::vec3 centre{0.0f};
    float cosYaw = 1.0f, sinYaw = 0.0f, cosPitch = 1.0f, sinPitch = 0.0f;
    float loX = 0.0f, hiY = 0.0f, hiZ = 0.0f;
    float scale = 1.0f, offX = 0.0f, offY = 0.0f, invDepthExtent = 1.0f;
};

// Packs a colour as the shader stores it: r in the low byte, alpha 255.
[[nodiscard]] constexpr uint32_t packRgba(uint8_t r, uint8_t g, uint8_t b) {
    return uint32_t(r) | uint32_t(g) << 8 | uint32_t(b) << 16 | 0xff000000u;
}

// Row-major, y down. Pixels no splat covers have depth +inf and rgba 0.
struct SplatFrame {
    int width = 0, height = 0;
    std::vector<float> depth;
    std::vector<uint32_t> rgba;
};

class SplatRenderer {
public:
    // deviceIndex -1 = the best usable device (discrete first). kNoDevice with
    // every rejected device's reasons when none qualifies.
    [[nodiscard]] static Result<std::unique_ptr<SplatRenderer>> create(int deviceIndex = -1,
                                                                       bool validation = false);
    ~SplatRenderer();
    SplatRenderer(const SplatRenderer&) = delete;
    SplatRenderer& operator=(const SplatRenderer&) = delete;

    // rgba has one packed colour per point (packRgba). width, height >= 1;
    // radius > 0 pixels. kInvalidArgument on mismatched sizes, kInternal when
    // a Vulkan call fails, kOutOfMemory when the buffers cannot be allocated.
    [[nodiscard]] Result<SplatFrame> render(std::span<const glm::vec3> points, std::span<const uint32_t> rgba,
                                            const SplatCamera& camera, int width, int height, float radius);

    [[nodiscard]] const std::string& deviceName() const;
    // Messages of the validation layer so far (0 when validation is off).
    [[nodiscard]] uint64_t validationMessageCount() const;

private:
    struct Impl;
    explicit SplatRenderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

}  // namespace rthdist::render
