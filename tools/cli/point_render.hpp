// --png: a picture of both point sets coloured by their per-point distance,
// with the Hausdorff segment between the realizing pair, a colour bar and a
// caption.
//
// Orthographic camera rotated by yaw (about +y) then pitch (about +x) around
// the centre of the union's box; every point splatted as a disc into a depth
// buffer, by default headless on Vulkan (src/render, issue 5; lavapipe works),
// else in software; then, in software, eye-dome lighting (Boucheny 2009, as
// in CloudCompare) darkens depth discontinuities so shapes read without
// normals, and the annotation is drawn: the segment over the points (never
// hidden) with its endpoints, its label, title, caption and colour bar.
// Cost of the software splat: O(points * splat area) on one thread, about a
// second for 10^6 points; the Vulkan one is one compute dispatch.
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cli/colour_ramp.hpp"
#include "cli/image.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cli {

struct RenderScene {
    std::span<const glm::vec3> a, b;
    std::span<const double> aDistance, bDistance;  // per point; empty = grey
    ColourRange range;
    glm::vec3 segmentFrom{0.0f}, segmentTo{0.0f};  // the realizing pair of H
    double hausdorff = 0.0;
    std::vector<std::string> caption;  // lines under the title
    std::string title = "rthdist: per-point nearest distance";
};

struct RenderOptions {
    int width = 1600;
    int height = 1000;
    double yawDegrees = 25.0;
    double pitchDegrees = 15.0;
    double pointRadius = 0.0;  // pixels; 0 = from the point density
    double edlStrength = 150.0;
    bool vulkan = true;    // splat on a Vulkan device; false = software
    int deviceIndex = -1;  // Vulkan device, -1 = the first usable
    bool validation = false;
};

// How the picture's points were splatted.
struct RenderInfo {
    bool vulkan = false;
    std::string device;          // the Vulkan device's name when vulkan
    std::string fallbackReason;  // why software was used though Vulkan was asked for
    uint64_t validationMessages = 0;
};

// Never fails: when the Vulkan splat cannot run, the software one does and
// info->fallbackReason says why.
[[nodiscard]] Image renderPicture(const RenderScene& scene, const RenderOptions& options = {},
                                  RenderInfo* info = nullptr);

}  // namespace rthdist::cli
