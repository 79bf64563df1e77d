// The float search's input limits (core/input_limits.hpp) on the backend
// under test: coordinates past float32's range after the shift, or a whole
// pair within 2^-126 of its origin, are kBadInput naming the set, the point,
// the axis and the limit (one-shot calls, prepared sets of either frame);
// inputs just inside them are exact; a prepared set's origin must be finite.
// (Issue 36: 1e308 beside 0.1 crashed the CPU backend, a pair at 1e-160
// returned half its distance, a NaN origin was accepted.)
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "engine_test_support.hpp"

namespace rthdist::test {
namespace {

using Doubles = std::vector<glm::dvec3>;

// The error of a call that must be refused, with every word of `words` in its message.
void expectRefused(const Result<HausdorffResult>& r, ErrorCode code, const std::vector<std::string>& words) {
    ASSERT_FALSE(r) << "H = " << r->hausdorff;
    EXPECT_EQ(r.error().code, code) << r.error().message;
    for (const std::string& w : words)
        EXPECT_NE(r.error().message.find(w), std::string::npos) << "'" << w << "' in: " << r.error().message;
}

double bruteForce(const Doubles& a, const Doubles& b) {
    auto directed = [](const Doubles& q, const Doubles& t) {
        double worst = 0.0;
        for (const glm::dvec3& p : q) {
            double best = INFINITY;
            for (const glm::dvec3& s : t) best = std::min(best, glm::length(p - s));
            worst = std::max(worst, best);
        }
        return worst;
    };
    return std::max(directed(a, b), directed(b, a));
}

TEST(InputLimits, BeyondFloatRangeAfterTheShiftIsRefused) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const Doubles far = {{1e308, 0.0, 0.0}, {0.1, 0.0, 0.0}};
    const Doubles near = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
    expectRefused(engine->compute(far, near), ErrorCode::kBadInput,
                  {"point set A", "point 0", "x = 1e+308", "3.40282347e+38"});
    // Both ends are 5e307 from the union's centre: the stray at 1e308 is named, not the points near 0.
    expectRefused(engine->compute(near, far), ErrorCode::kBadInput, {"point set B", "point 0", "x = 1e+308"});
    expectRefused(engine->compute(far, far), ErrorCode::kBadInput, {"point set A", "3.40282347e+38"});
    // Both ends of the double range: their centre must not overflow either.
    const Doubles left = {{0.0, -1.7e308, 0.0}}, right = {{0.0, 1.7e308, 0.25}};
    expectRefused(engine->compute(left, right), ErrorCode::kBadInput, {"point set A", "y = -1.7e+308"});
    // Sets far away but small: shifted to their centre, nothing is past the limit.
    const Doubles remote = {{1e300, 0.0, 0.0}, {1e300, 1.0, 0.0}}, beside = {{1e300, 4.0, 0.0}};
    auto alone = engine->compute(remote, beside);
    ASSERT_TRUE(alone) << alone.error().message;
    EXPECT_EQ(alone->hausdorff, 4.0);
}

TEST(InputLimits, JustInsideFloatRangeIsExact) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const Doubles a = {{1e38, 0.0, 0.0}, {0.1, 0.0, 0.0}, {-3e37, 0.5, 0.0}};
    const Doubles b = {{0.1, 0.0, 0.0}, {-1e38, 0.0, 0.3}};
    auto r = engine->compute(a, b);
    ASSERT_TRUE(r) << r.error().message;
    const double want = bruteForce(a, b);
    ASSERT_TRUE(std::isfinite(r->hausdorff));
    EXPECT_NEAR(r->hausdorff, want, 1e-6 * 2e38);
}

TEST(InputLimits, PairWithinTinyExtentIsRefused) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const Doubles a = {{1e-160, 0.0, 0.0}, {0.0, 2e-160, 0.0}};
    const Doubles b = {{0.0, 0.0, 0.0}};
    expectRefused(engine->compute(a, b), ErrorCode::kBadInput,
                  {"point sets A and B", "1e-160", "1.17549435e-38"});
    // Every point the same (the extent is 0): H = 0 exactly.
    const Doubles same = {{1e-200, 3e-300, 0.0}, {1e-200, 3e-300, 0.0}};
    auto zero = engine->compute(same, same);
    ASSERT_TRUE(zero) << zero.error().message;
    EXPECT_EQ(zero->hausdorff, 0.0);
    // Float values are searched as they are, subnormals included: exact.
    const std::vector<glm::vec3> fa = {{1e-40f, 0.0f, 0.0f}, {0.0f, 3e-41f, 0.0f}};
    const std::vector<glm::vec3> fb = {{0.0f, 0.0f, 0.0f}};
    auto tiny = engine->compute(fa, fb);
    ASSERT_TRUE(tiny) << tiny.error().message;
    EXPECT_NEAR(tiny->hausdorff, double(1e-40f), 1e-6 * double(1e-40f));
}

TEST(InputLimits, PreparedSetsCheckTheirFrame) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const Doubles points = {{0.1, 0.2, 0.3}, {1.1, 0.2, 0.3}};
    for (double bad : {std::nan(""), double(INFINITY), -double(INFINITY)}) {
        PrepareOptions o;
        o.origin = glm::dvec3(0.0, bad, 0.0);
        auto p = engine->prepare(points, o);
        ASSERT_FALSE(p) << "origin y = " << bad;
        EXPECT_EQ(p.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(p.error().message.find("PrepareOptions::origin"), std::string::npos) << p.error().message;
        EXPECT_NE(p.error().message.find("coordinate y"), std::string::npos) << p.error().message;
    }
    PrepareOptions far;
    far.origin = glm::dvec3(1e300, 0.0, 0.0);
    auto p = engine->prepare(points, far);
    ASSERT_FALSE(p);
    EXPECT_EQ(p.error().code, ErrorCode::kBadInput);
    EXPECT_NE(p.error().message.find("point set to prepare"), std::string::npos) << p.error().message;
    const Doubles big = {{1e308, 0.0, 0.0}, {0.1, 0.0, 0.0}};
    auto alone = engine->prepare(big);  // its own frame, the centre: 5e307 either way
    ASSERT_FALSE(alone);
    EXPECT_EQ(alone.error().code, ErrorCode::kBadInput);
    // Two sets each fine in its own frame, past the limit in the union's.
    const Doubles here = {{0.1, 0.0, 0.0}, {0.2, 0.0, 0.0}};
    const Doubles there = {{1e300, 0.0, 0.0}, {1e300, 1.0, 0.0}};
    auto ph = engine->prepare(here);
    auto pt = engine->prepare(there);
    ASSERT_TRUE(ph && pt);
    expectRefused(engine->compute(*ph, *pt), ErrorCode::kBadInput, {"point set", "3.40282347e+38"});
}

}  // namespace
}  // namespace rthdist::test
