// --png: a picture of both point sets coloured by their per-point distance,
// with the Hausdorff segment between the realizing pair, a colour bar and a
// caption.
//
// This is a SOFTWARE renderer (first step; issue 5 asks for Vulkan headless
// rendering): orthographic camera rotated by yaw (about +y) then pitch (about
// +x) around the centre of the union's box, every point splatted as a disc
// into a depth buffer, then eye-dome lighting (Boucheny 2009, as in
// CloudCompare) darkens depth discontinuities so shapes read without normals.
// The segment is drawn over the points (never hidden), with its endpoints.
// Cost: O(points * splat area) on one thread; about a second for 10^6 points.
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

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
};

[[nodiscard]] Image renderPicture(const RenderScene& scene, const RenderOptions& options = {});

}  // namespace rthdist::cli
