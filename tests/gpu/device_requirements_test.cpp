// Device requirements as data (src/gpu/device_requirements.hpp): the compute
// family asks for no ray tracing (the splat renderer runs on any Vulkan 1.3
// compute device), the backends add ray tracing to it, and a requirement no
// device meets is named in the rejection of every device.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "gpu/context.hpp"
#include "gpu/device_requirements.hpp"

namespace rthdist::gpu {
namespace {

bool hasAll(const DeviceRequirements& outer, const DeviceRequirements& inner) {
    return std::all_of(inner.features.begin(), inner.features.end(),
                       [&](DeviceFeature f) { return outer.needs(f); }) &&
           std::all_of(inner.extensions.begin(), inner.extensions.end(),
                       [&](const char* e) { return outer.needs(e); });
}

TEST(DeviceRequirements, ComputeAsksForNoRayTracing) {
    const DeviceRequirements compute = computeRequirements();
    EXPECT_EQ(compute.backend, Backend::kAuto);
    EXPECT_TRUE(compute.extensions.empty());
    for (DeviceFeature f : {DeviceFeature::kAccelerationStructure, DeviceFeature::kRayQuery,
                            DeviceFeature::kRayTracingPipeline})
        EXPECT_FALSE(compute.needs(f)) << featureName(f);
    EXPECT_TRUE(compute.needs(DeviceFeature::kSynchronization2));
    EXPECT_TRUE(compute.needs(DeviceFeature::kShaderBufferInt64Atomics));
}

TEST(DeviceRequirements, BackendsAddRayTracingToCompute) {
    const DeviceRequirements rq = backendRequirements(Backend::kRayQuery);
    const DeviceRequirements rtp = backendRequirements(Backend::kRtPipeline);
    EXPECT_TRUE(hasAll(rq, computeRequirements()));
    EXPECT_TRUE(hasAll(rtp, computeRequirements()));
    EXPECT_EQ(rq.backend, Backend::kRayQuery);
    EXPECT_EQ(rtp.backend, Backend::kRtPipeline);
    EXPECT_TRUE(rq.needs(DeviceFeature::kRayQuery) && rq.needs(VK_KHR_RAY_QUERY_EXTENSION_NAME));
    EXPECT_FALSE(rq.needs(DeviceFeature::kRayTracingPipeline));
    EXPECT_TRUE(rtp.needs(DeviceFeature::kRayTracingPipeline) &&
                rtp.needs(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME));
    EXPECT_FALSE(rtp.needs(DeviceFeature::kRayQuery));
}

// The context of the splat renderer: compute only, so no ray-tracing entry
// point is loaded, with the validation layer on.
TEST(DeviceRequirements, ComputeContextLoadsNoRayTracing) {
    const std::array<DeviceRequirements, 1> compute{computeRequirements()};
    auto ctx = Context::create(compute, "a compute test", -1, true);
    ASSERT_TRUE(ctx) << ctx.error().message;
    EXPECT_EQ((*ctx)->backend(), Backend::kAuto);
    EXPECT_EQ((*ctx)->rt().createAccel, nullptr);
    EXPECT_EQ((*ctx)->rt().cmdTraceRays, nullptr);
    EXPECT_EQ((*ctx)->validationMessageCount(), 0u);
}

TEST(DeviceRequirements, UnmetRequirementNamedForEveryDevice) {
    DeviceRequirements impossible = computeRequirements();
    impossible.extensions.push_back("VK_RTHDIST_no_such_extension");
    const std::array<DeviceRequirements, 1> alternatives{impossible};
    auto ctx = Context::create(alternatives, "an impossible test", -1, false);
    ASSERT_FALSE(ctx);
    EXPECT_EQ(ctx.error().code, ErrorCode::kNoDevice);
    EXPECT_NE(ctx.error().message.find("no Vulkan device can run an impossible test:"), std::string::npos)
        << ctx.error().message;
    EXPECT_NE(ctx.error().message.find("device 0 ("), std::string::npos) << ctx.error().message;
    EXPECT_NE(ctx.error().message.find("lacks extension VK_RTHDIST_no_such_extension"), std::string::npos)
        << ctx.error().message;
}

}  // namespace
}  // namespace rthdist::gpu
