// Shared between C++ (src/render) and GLSL (shaders/render/splat.comp): the
// push constants of the point-splat pass. Buffers are reached through their
// device addresses, so the pass needs no descriptor sets.
#ifndef RTHDIST_RENDER_SPLAT_SHARED_H
#define RTHDIST_RENDER_SPLAT_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace rthdist::render::shared {
using uint = uint32_t;
#endif

// Workgroup size of the splat dispatch (one invocation per point).
#define RTHDIST_SPLAT_WG 64

// Orthographic camera, the same one the software renderer uses: rotate the
// point about `centre` by yaw (about +y) then pitch (about +x); camera x is
// right, y up, z towards the viewer. Screen x = offX + (x - loX) * scale,
// screen y = offY + (hiY - y) * scale (y down), depth = (hiZ - z) *
// invDepthExtent in [0, 1] (0 nearest).
struct SplatPush {
    uint64_t points;   // float[3 n]: xyz of each point, tightly packed
    uint64_t colours;  // uint[n]: RGBA8 of each point (r in the low byte)
    uint64_t pixels;   // uint64_t[width * height]: (depth bits << 32) | RGBA8, ~0 = empty
    float centreX, centreY, centreZ;
    float cosYaw, sinYaw, cosPitch, sinPitch;
    float loX, hiY, hiZ;
    float scale, offX, offY, invDepthExtent;
    float radius;  // disc radius in pixels
    uint count;
    uint width, height;
};

#ifdef __cplusplus
}  // namespace rthdist::render::shared
#endif

#endif
