// Engines of the backend under test created and destroyed one after another
// in one process: each one works (issue 33's session 6: on the lent H200
// the 29th Vulkan instance of a process failed with
// VK_ERROR_INCOMPATIBLE_DRIVER, file descriptors constant; README "Known
// limitations"). Past that count here, each engine computing a small pair.
#include <gtest/gtest.h>

#include <vector>

#include "engine_test_support.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::test {
namespace {

TEST(EngineLife, FortyEnginesInTurnInOneProcess) {
    const std::vector<glm::vec3> a = randomCloud(200, 1), b = randomCloud(150, 2);
    double first = -1.0;
    for (int i = 0; i < 40; ++i) {
        EngineOptions o = engineUnderTest();
        o.validation = false;  // the layer's own state is not what is tested
        Result<Engine> engine = Engine::create(o);
        ASSERT_TRUE(engine) << "engine " << i << ": " << engine.error().message;
        Result<HausdorffResult> r = engine->compute(a, b);
        ASSERT_TRUE(r) << "engine " << i << ": " << r.error().message;
        if (first < 0.0) first = r->hausdorff;
        EXPECT_EQ(r->hausdorff, first) << "engine " << i;
    }
}

}  // namespace
}  // namespace rthdist::test
