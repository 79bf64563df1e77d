#include "cli/point_render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "render/splat_renderer.hpp"

namespace rthdist::cli {
namespace {

constexpr Rgb kBackground{255, 255, 255}, kBlack{0, 0, 0}, kSegment{255, 0, 255}, kGrey{150, 150, 150};
constexpr double kFar = std::numeric_limits<double>::infinity();

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.5g", v);
    return buf;
}

struct View {
    glm::dvec3 centre{0.0};
    double cy = 1, sy = 0, cp = 1, sp = 0;
    // Camera coordinates: x right, y up, z towards the viewer.
    [[nodiscard]] glm::dvec3 apply(const glm::vec3& p) const {
        const glm::dvec3 q = glm::dvec3(p) - centre;
        const double x = cy * q.x + sy * q.z, z = -sy * q.x + cy * q.z;  // yaw about y
        const double y = cp * q.y - sp * z, z2 = sp * q.y + cp * z;      // pitch about x
        return {x, y, z2};
    }
};

// The Vulkan splat (src/render); fills depth and colour as the software splat
// does, and leaves them untouched on an Error (no device, the pass failed).
Result<bool> splatOnVulkan(const RenderScene& scene, const render::SplatCamera& camera,
                           const RenderOptions& options, double radius, int width, int height,
                           std::vector<double>& depth, std::vector<Rgb>& colour, RenderInfo& info) {
    auto renderer = render::SplatRenderer::create(options.deviceIndex, options.validation);
    if (!renderer) return renderer.error();
    std::vector<glm::vec3> points;
    std::vector<uint32_t> rgba;
    points.reserve(scene.a.size() + scene.b.size());
    rgba.reserve(points.capacity());
    for (auto [set, distance] : {std::pair{scene.a, scene.aDistance}, std::pair{scene.b, scene.bDistance}}) {
        for (size_t i = 0; i < set.size(); ++i) {
            const Rgb c = distance.size() == set.size() ? distanceColour(distance[i], scene.range) : kGrey;
            points.push_back(set[i]);
            rgba.push_back(render::packRgba(c.r, c.g, c.b));
        }
    }
    auto frame = (*renderer)->render(points, rgba, camera, width, height, float(radius));
    if (!frame) return frame.error();
    for (size_t at = 0; at < depth.size(); ++at) {
        if (frame->depth[at] == std::numeric_limits<float>::infinity()) continue;
        depth[at] = frame->depth[at];
        const uint32_t c = frame->rgba[at];
        colour[at] = Rgb{uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)};
    }
    info.vulkan = true;
    info.device = (*renderer)->deviceName();
    info.validationMessages = (*renderer)->validationMessageCount();
    return true;
}

// Where the picture's parts sit: the plot area left of the legend, under the title.
struct Frame {
    static constexpr int kLegendW = 190, kTop = 90, kMargin = 30;
    int width = 0, height = 0;
    int plotX = kMargin, plotY = kTop, plotW = 0, plotH = 0;
};

Frame frameOf(const RenderOptions& options) {
    Frame f;
    f.width = options.width;
    f.height = options.height;
    f.plotW = f.width - Frame::kLegendW - 2 * Frame::kMargin;
    f.plotH = f.height - Frame::kTop - Frame::kMargin - 40;
    return f;
}

// The camera and how rotated points land on the screen: the union's rotated
// box (vlo, vhi) fitted into the plot area, depth 0 near .. 1 far.
struct Projection {
    View view;
    glm::dvec3 vlo{kFar}, vhi{-kFar};
    double scale = 1.0, offX = 0.0, offY = 0.0, depthExtent = 1.0;

    void toScreen(const glm::dvec3& v, double& sx, double& sy) const {
        sx = offX + (v.x - vlo.x) * scale;
        sy = offY + (vhi.y - v.y) * scale;
    }
    [[nodiscard]] double depthOf(const glm::dvec3& v) const { return (vhi.z - v.z) / depthExtent; }
};

// The view around the centre of the union's box, rotated by the options'
// yaw and pitch, its rotated box fitted into the plot area.
Projection projectionOf(const RenderScene& scene, const RenderOptions& options, const Frame& f) {
    Projection pr;
    glm::dvec3 lo(kFar), hi(-kFar);
    for (auto set : {scene.a, scene.b}) {
        for (const glm::vec3& p : set) {
            lo = glm::min(lo, glm::dvec3(p));
            hi = glm::max(hi, glm::dvec3(p));
        }
    }
    View& view = pr.view;
    view.centre = (lo + hi) * 0.5;
    const double yaw = options.yawDegrees * M_PI / 180.0, pitch = options.pitchDegrees * M_PI / 180.0;
    view.cy = std::cos(yaw);
    view.sy = std::sin(yaw);
    view.cp = std::cos(pitch);
    view.sp = std::sin(pitch);

    // Fit the rotated points into the plot area.
    for (auto set : {scene.a, scene.b}) {
        for (const glm::vec3& p : set) {
            const glm::dvec3 v = view.apply(p);
            pr.vlo = glm::min(pr.vlo, v);
            pr.vhi = glm::max(pr.vhi, v);
        }
    }
    const double extentX = std::max(pr.vhi.x - pr.vlo.x, 1e-30),
                 extentY = std::max(pr.vhi.y - pr.vlo.y, 1e-30);
    pr.scale = std::min(f.plotW / extentX, f.plotH / extentY);
    pr.offX = f.plotX + (f.plotW - extentX * pr.scale) * 0.5;
    pr.offY = f.plotY + (f.plotH - extentY * pr.scale) * 0.5;
    pr.depthExtent = std::max(pr.vhi.z - pr.vlo.z, 1e-30);
    return pr;
}

// The splat radius in pixels: the options', else from the point density.
double splatRadius(const RenderScene& scene, const RenderOptions& options, const Frame& f) {
    const size_t total = scene.a.size() + scene.b.size();
    double radius = options.pointRadius;
    if (!(radius > 0.0))
        radius = std::clamp(2.0 * std::sqrt(double(f.plotW) * f.plotH / double(std::max<size_t>(total, 1))),
                            1.5, 8.0);
    return radius;
}

// The depth and colour buffers of the splatted points (kFar and the
// background where none lands).
struct Splats {
    std::vector<double> depth;
    std::vector<Rgb> colour;
};

// The Vulkan splat's camera: the projection in float.
render::SplatCamera cameraOf(const Projection& pr) {
    render::SplatCamera camera;
    camera.centre = glm::vec3(pr.view.centre);
    camera.cosYaw = float(pr.view.cy);
    camera.sinYaw = float(pr.view.sy);
    camera.cosPitch = float(pr.view.cp);
    camera.sinPitch = float(pr.view.sp);
    camera.loX = float(pr.vlo.x);
    camera.hiY = float(pr.vhi.y);
    camera.hiZ = float(pr.vhi.z);
    camera.scale = float(pr.scale);
    camera.offX = float(pr.offX);
    camera.offY = float(pr.offY);
    camera.invDepthExtent = float(1.0 / pr.depthExtent);
    return camera;
}

// One set splatted in software: a disc of `radius` pixels per point, the
// nearest depth wins.
void splatInSoftware(std::span<const glm::vec3> set, std::span<const double> distance,
                     const ColourRange& range, const Projection& pr, double radius, const Frame& f,
                     Splats& out) {
    for (size_t i = 0; i < set.size(); ++i) {
        const glm::dvec3 v = pr.view.apply(set[i]);
        double sx = 0, sy = 0;
        pr.toScreen(v, sx, sy);
        const double d = pr.depthOf(v);
        const Rgb c = distance.size() == set.size() ? distanceColour(distance[i], range) : kGrey;
        const int x0 = int(std::floor(sx - radius)), x1 = int(std::ceil(sx + radius));
        const int y0 = int(std::floor(sy - radius)), y1 = int(std::ceil(sy + radius));
        for (int y = std::max(y0, 0); y <= std::min(y1, f.height - 1); ++y) {
            for (int x = std::max(x0, 0); x <= std::min(x1, f.width - 1); ++x) {
                const double dx = x + 0.5 - sx, dy = y + 0.5 - sy;
                if (dx * dx + dy * dy > radius * radius) continue;
                const size_t at = size_t(y) * size_t(f.width) + size_t(x);
                if (d < out.depth[at]) {
                    out.depth[at] = d;
                    out.colour[at] = c;
                }
            }
        }
    }
}

// Both sets splatted: on Vulkan when asked for and it runs (info.vulkan),
// else in software (info.fallbackReason says why when Vulkan was asked for).
Splats splatPoints(const RenderScene& scene, const RenderOptions& options, const Projection& pr,
                   double radius, const Frame& f, RenderInfo& info) {
    Splats s;
    s.depth.assign(size_t(f.width) * size_t(f.height), kFar);
    s.colour.assign(s.depth.size(), kBackground);
    if (options.vulkan) {
        Result<bool> ok =
            splatOnVulkan(scene, cameraOf(pr), options, radius, f.width, f.height, s.depth, s.colour, info);
        if (!ok) info.fallbackReason = ok.error().message;  // buffers untouched: splat in software
    }
    if (!info.vulkan) {
        splatInSoftware(scene.a, scene.aDistance, scene.range, pr, radius, f, s);
        splatInSoftware(scene.b, scene.bDistance, scene.range, pr, radius, f, s);
    }
    return s;
}

// Eye-dome lighting: darken a pixel by how far its neighbours (2 px away)
// are in front of it; background neighbours count as far behind.
void shadeEyeDome(const Splats& s, double strength, const Frame& f, Image& img) {
    const int step = 2;
    const int nx[8] = {step, -step, 0, 0, step, -step, step, -step};
    const int ny[8] = {0, 0, step, -step, step, step, -step, -step};
    const int width = f.width, height = f.height;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const size_t at = size_t(y) * size_t(width) + size_t(x);
            if (s.depth[at] == kFar) continue;
            double sum = 0.0;
            for (int k = 0; k < 8; ++k) {
                const int qx = x + nx[k], qy = y + ny[k];
                double dn = 1.5;
                if (qx >= 0 && qy >= 0 && qx < width && qy < height) {
                    const double q = s.depth[size_t(qy) * size_t(width) + size_t(qx)];
                    if (q != kFar) dn = q;
                }
                sum += std::max(0.0, s.depth[at] - dn) + 0.0;
                if (dn == 1.5) sum += 0.02;  // silhouettes
            }
            const double shade = std::exp(-strength * sum / 8.0) * (1.0 - 0.25 * s.depth[at]);
            const Rgb c = s.colour[at];
            img.set(x, y, {uint8_t(c.r * shade), uint8_t(c.g * shade), uint8_t(c.b * shade)});
        }
    }
}

// The Hausdorff segment over everything, its endpoints and its label.
void drawSegment(const RenderScene& scene, const Projection& pr, const Frame& f, Image& img) {
    double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    pr.toScreen(pr.view.apply(scene.segmentFrom), x0, y0);
    pr.toScreen(pr.view.apply(scene.segmentTo), x1, y1);
    img.drawLine(x0, y0, x1, y1, 7.0, kBlack);
    img.drawLine(x0, y0, x1, y1, 4.0, kSegment);
    for (auto [x, y] : {std::pair{x0, y0}, std::pair{x1, y1}}) {
        img.fillDisc(x, y, 9.0, kBlack);
        img.fillDisc(x, y, 6.0, kSegment);
    }
    const std::string hLabel = "H = " + number(scene.hausdorff);
    // The label sits beside the segment's midpoint, off the segment: moved
    // along the segment's normal (the side pointing up), then kept inside.
    const int tw = Image::textWidth(hLabel, 3);
    const double length = std::max(std::hypot(x1 - x0, y1 - y0), 1e-9);
    double ux = -(y1 - y0) / length, uy = (x1 - x0) / length;
    if (uy > 0) {
        ux = -ux;
        uy = -uy;
    }
    const double mx = (x0 + x1) * 0.5 + ux * 30.0, my = (y0 + y1) * 0.5 + uy * 30.0;
    const int lx = std::clamp(int(std::lround(mx - tw * 0.5)), 4, f.width - tw - 8);
    const int ly = std::clamp(int(std::lround(my - 13.0)), Frame::kTop, f.height - 40);
    img.fillRect(lx - 4, ly - 4, lx + tw + 6, ly + 30, kBackground);
    img.drawText(lx, ly, hLabel, kBlack, 3);
}

// Title and caption lines, top left.
void drawTitle(const RenderScene& scene, Image& img) {
    img.drawText(Frame::kMargin, 16, scene.title, kBlack, 3);
    int cy = 52;
    for (const std::string& line : scene.caption) {
        img.drawText(Frame::kMargin, cy, line, kBlack, 2);
        cy += 18;
    }
}

// The colour bar with five ticks over the scene's range, and the segment's key.
void drawColourBar(const ColourRange& range, const Frame& f, Image& img) {
    const int barX = f.width - Frame::kLegendW + 20, barY = Frame::kTop + 40, barW = 34,
              barH = std::max(100, f.plotH - 140);
    img.drawText(barX, barY - 36, "distance", kBlack, 2);
    for (int y = 0; y < barH; ++y) {
        const Rgb c = turbo(1.0 - double(y) / double(barH - 1));
        img.fillRect(barX, barY + y, barX + barW, barY + y + 1, c);
    }
    img.fillRect(barX - 1, barY - 1, barX + barW + 1, barY, kBlack);
    img.fillRect(barX - 1, barY + barH, barX + barW + 1, barY + barH + 1, kBlack);
    img.fillRect(barX - 1, barY, barX, barY + barH, kBlack);
    img.fillRect(barX + barW, barY, barX + barW + 1, barY + barH, kBlack);
    for (int k = 0; k <= 4; ++k) {
        const int y = barY + (barH - 1) * (4 - k) / 4;
        const double v = range.lo + (range.hi - range.lo) * k / 4;
        img.fillRect(barX + barW, y, barX + barW + 8, y + 1, kBlack);
        img.drawText(barX + barW + 12, y - 7, number(v), kBlack, 2);
    }
    img.fillRect(barX, barY + barH + 30, barX + 30, barY + barH + 36, kSegment);
    img.drawText(barX, barY + barH + 44, "Hausdorff", kBlack, 2);
    img.drawText(barX, barY + barH + 62, "segment", kBlack, 2);
}

}  // namespace

Image renderPicture(const RenderScene& scene, const RenderOptions& options, RenderInfo* infoOut) {
    RenderInfo info;
    const Frame f = frameOf(options);
    Image img(f.width, f.height, kBackground);
    const Projection pr = projectionOf(scene, options, f);
    const Splats splats = splatPoints(scene, options, pr, splatRadius(scene, options, f), f, info);
    shadeEyeDome(splats, options.edlStrength, f, img);
    drawSegment(scene, pr, f, img);
    drawTitle(scene, img);
    drawColourBar(scene.range, f, img);
    if (infoOut) *infoOut = std::move(info);
    return img;
}

}  // namespace rthdist::cli
