// A bare Vulkan context of the backend under test (RTHDIST_TEST_BACKEND,
// validation on), for the tests that drive gpu_algo below the Engine.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>

#include "gpu/context.hpp"
#include "gpu_test_support.hpp"

namespace rthdist::test {

// The context, or null with the reason in whyNot.
inline std::unique_ptr<gpu::Context> makeTestContext(std::string& whyNot) {
    auto ctx = gpu::Context::create(backendUnderTest(), -1, true);
    if (!ctx) {
        whyNot = ctx.error().message;
        return nullptr;
    }
    return std::move(ctx.value());
}

}  // namespace rthdist::test

// A context of the backend under test named `ctx` (a skip, which CI fails,
// when the device is missing).
#define RTHDIST_REQUIRE_CONTEXT(ctx)                           \
    std::string rthdist_why_;                                  \
    auto ctx = ::rthdist::test::makeTestContext(rthdist_why_); \
    if (!ctx) GTEST_SKIP() << "no device for this backend: " << rthdist_why_
