// SplatRenderer: a splat lands where the camera projects its point, with its
// colour and depth; the nearer of two overlapping splats wins whatever their
// order; degenerate input. Every case runs with the validation layer and
// fails on any message it emits.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "render/splat_renderer.hpp"

namespace rthdist::render {
namespace {

constexpr int kW = 64, kH = 48;
constexpr float kEmpty = std::numeric_limits<float>::infinity();

// Identity rotation, 1 world unit = 4 pixels, world origin at pixel (32, 24),
// depth 0 at z = 1 (nearest) .. 1 at z = -1.
SplatCamera frontCamera() {
    SplatCamera c;
    c.scale = 4.0f;
    c.offX = 32.0f;
    c.offY = 24.0f;
    c.hiZ = 1.0f;
    c.invDepthExtent = 0.5f;
    return c;
}

struct Renderer {
    std::unique_ptr<SplatRenderer> r;
    std::string whyNot;
};

Renderer makeRenderer() {
    auto r = SplatRenderer::create(-1, true);
    if (!r) return {nullptr, r.error().message};
    return {std::move(r.value()), ""};
}

#define RTHDIST_REQUIRE_RENDERER(name)                                                \
    Renderer name = makeRenderer();                                                   \
    if (!name.r) GTEST_SKIP() << "no device for the splat renderer: " << name.whyNot; \
    static_assert(true)

size_t at(int x, int y) { return size_t(y) * kW + size_t(x); }

TEST(RenderSplat, ColourAndDepthAtTheProjectedPosition) {
    RTHDIST_REQUIRE_RENDERER(gpu);
    // (2, 1, 0) -> screen (32 + 8, 24 - 4) = (40, 20); pixel centres within
    // 2.5 px of that are covered.
    const std::vector<glm::vec3> points{{2.0f, 1.0f, 0.0f}};
    const std::vector<uint32_t> colours{packRgba(10, 200, 30)};
    auto frame = gpu.r->render(points, colours, frontCamera(), kW, kH, 2.5f);
    ASSERT_TRUE(frame) << frame.error().message;
    ASSERT_EQ(frame->width, kW);
    ASSERT_EQ(frame->rgba.size(), size_t(kW * kH));
    EXPECT_EQ(frame->rgba[at(40, 20)], packRgba(10, 200, 30));
    EXPECT_FLOAT_EQ(frame->depth[at(40, 20)], 0.5f);
    EXPECT_EQ(frame->rgba[at(38, 19)], packRgba(10, 200, 30));  // (38.5, 19.5): 1.58 px off
    EXPECT_EQ(frame->rgba[at(37, 20)], 0u);                     // (37.5, 20.5): 2.55 px off
    EXPECT_EQ(frame->depth[at(37, 20)], kEmpty);
    int covered = 0;
    for (uint32_t c : frame->rgba) covered += c != 0u;
    EXPECT_EQ(covered, 16);  // pixel centres within 2.5 px of a pixel corner
    EXPECT_EQ(gpu.r->validationMessageCount(), 0u);
}

TEST(RenderSplat, RotatedCameraMatchesTheSoftwareFormula) {
    RTHDIST_REQUIRE_RENDERER(gpu);
    // Yaw 90 degrees: x' = cos*x + sin*z = z, z' = -sin*x + cos*z = -x.
    SplatCamera c = frontCamera();
    c.cosYaw = 0.0f;
    c.sinYaw = 1.0f;
    const std::vector<glm::vec3> points{{-0.5f, 0.0f, 3.0f}};  // -> x' = 3, z' = 0.5
    const std::vector<uint32_t> colours{packRgba(1, 2, 3)};
    auto frame = gpu.r->render(points, colours, c, kW, kH, 1.0f);
    ASSERT_TRUE(frame) << frame.error().message;
    EXPECT_EQ(frame->rgba[at(44, 23)], packRgba(1, 2, 3));  // screen (44, 24)
    EXPECT_NEAR(frame->depth[at(44, 23)], 0.25f, 1e-6f);
    EXPECT_EQ(gpu.r->validationMessageCount(), 0u);
}

TEST(RenderSplat, NearerSplatWinsInEitherOrder) {
    RTHDIST_REQUIRE_RENDERER(gpu);
    // The near splat gets the larger colour word, so a pass that compared
    // colours instead of depths would pick the far one.
    const uint32_t nearColour = packRgba(0, 0, 255), farColour = packRgba(255, 0, 0);
    ASSERT_GT(nearColour, farColour);
    // Same screen position; z = 0.8 (depth 0.1) is nearer the viewer than
    // z = -0.6 (depth 0.8).
    const glm::vec3 nearP{0.0f, 0.0f, 0.8f}, farP{0.0f, 0.0f, -0.6f};
    for (bool nearFirst : {true, false}) {
        const std::vector<glm::vec3> points =
            nearFirst ? std::vector<glm::vec3>{nearP, farP} : std::vector<glm::vec3>{farP, nearP};
        const std::vector<uint32_t> colours = nearFirst ? std::vector<uint32_t>{nearColour, farColour}
                                                        : std::vector<uint32_t>{farColour, nearColour};
        auto frame = gpu.r->render(points, colours, frontCamera(), kW, kH, 3.0f);
        ASSERT_TRUE(frame) << frame.error().message;
        EXPECT_EQ(frame->rgba[at(32, 24)], nearColour) << "near first: " << nearFirst;
        EXPECT_NEAR(frame->depth[at(32, 24)], 0.1f, 1e-6f);
    }
    // Far splat moved right to screen x = 36: the overlap goes to the near
    // one, the rest of the far disc shows.
    const std::vector<glm::vec3> points{{1.0f, 0.0f, -0.6f}, nearP};
    const std::vector<uint32_t> colours{farColour, nearColour};
    auto frame = gpu.r->render(points, colours, frontCamera(), kW, kH, 3.0f);
    ASSERT_TRUE(frame) << frame.error().message;
    EXPECT_EQ(frame->rgba[at(31, 24)], nearColour);  // near only
    EXPECT_EQ(frame->rgba[at(34, 24)], nearColour);  // (34.5, 24.5): 2.55 px from near, 1.58 from far
    EXPECT_NEAR(frame->depth[at(34, 24)], 0.1f, 1e-6f);
    EXPECT_EQ(frame->rgba[at(37, 24)], farColour);  // far only
    EXPECT_NEAR(frame->depth[at(37, 24)], 0.8f, 1e-6f);
    EXPECT_EQ(gpu.r->validationMessageCount(), 0u);
}

TEST(RenderSplat, SplatsClippedAtTheImageEdges) {
    RTHDIST_REQUIRE_RENDERER(gpu);
    // Discs centred on two image corners and one point far outside: only
    // the inside parts of the discs are drawn, nothing lands out of bounds.
    const std::vector<glm::vec3> points{{-8.0f, 6.0f, 0.0f}, {8.0f, -6.0f, 0.0f}, {1e6f, 1e6f, 0.0f}};
    const std::vector<uint32_t> colours{packRgba(9, 9, 9), packRgba(8, 8, 8), packRgba(7, 7, 7)};
    auto frame = gpu.r->render(points, colours, frontCamera(), kW, kH, 2.0f);
    ASSERT_TRUE(frame) << frame.error().message;
    EXPECT_EQ(frame->rgba[at(0, 0)], packRgba(9, 9, 9));
    EXPECT_EQ(frame->rgba[at(kW - 1, kH - 1)], packRgba(8, 8, 8));  // disc centred on the corner
    EXPECT_EQ(frame->rgba[at(kW - 3, kH - 1)], 0u);                 // (61.5, 47.5): 2.55 px off
    EXPECT_EQ(gpu.r->validationMessageCount(), 0u);
}

TEST(RenderSplat, NoPointsGivesAnEmptyFrame) {
    RTHDIST_REQUIRE_RENDERER(gpu);
    auto frame = gpu.r->render({}, {}, frontCamera(), kW, kH, 2.0f);
    ASSERT_TRUE(frame) << frame.error().message;
    for (size_t i = 0; i < frame->rgba.size(); ++i) {
        ASSERT_EQ(frame->rgba[i], 0u);
        ASSERT_EQ(frame->depth[i], kEmpty);
    }
    EXPECT_EQ(gpu.r->validationMessageCount(), 0u);
}

TEST(RenderSplat, MismatchedColoursAreAnError) {
    RTHDIST_REQUIRE_RENDERER(gpu);
    const std::vector<glm::vec3> points{{0.0f, 0.0f, 0.0f}};
    auto frame = gpu.r->render(points, {}, frontCamera(), kW, kH, 2.0f);
    ASSERT_FALSE(frame);
    EXPECT_EQ(frame.error().code, ErrorCode::kInvalidArgument);
    auto zero = gpu.r->render(points, std::vector<uint32_t>{0u}, frontCamera(), 0, kH, 2.0f);
    ASSERT_FALSE(zero);
    EXPECT_EQ(zero.error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace rthdist::render
