// The process's Vulkan instances (gpu/process_instance.hpp): one per
// configuration for the life of the process, many devices in turn on it, and
// a forked child that makes its own.
#include "gpu/process_instance.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <memory>

#include "gpu/context.hpp"

namespace rthdist::gpu {
namespace {

TEST(ProcessInstance, IsMadeOncePerConfiguration) {
    Result<ProcessInstance*> first = instanceFor(false, false);
    ASSERT_TRUE(first) << first.error().message;
    Result<ProcessInstance*> again = instanceFor(false, false);
    ASSERT_TRUE(again);
    EXPECT_EQ(*first, *again);
    EXPECT_NE((*first)->handle, VkInstance(VK_NULL_HANDLE));
    EXPECT_FALSE((*first)->validation);
    Result<ProcessInstance*> labelled = instanceFor(false, true);
    ASSERT_TRUE(labelled);
    // Debug labels take their own instance where the loader has debug utils.
    EXPECT_EQ(*labelled == *first, !(*labelled)->debugUtils);
}

// NVIDIA's driver refused the 29th instance of a process; devices made in
// turn on the process's instance go on past that.
TEST(ProcessInstance, SixtyContextsInTurnShareIt) {
    Result<ProcessInstance*> shared = instanceFor(false, false);
    ASSERT_TRUE(shared);
    for (int i = 0; i < 60; ++i) {
        Result<std::unique_ptr<Context>> ctx = Context::create(Backend::kAuto, -1, false);
        ASSERT_TRUE(ctx) << "context " << i << ": " << ctx.error().message;
        EXPECT_EQ((*ctx)->instance(), (*shared)->handle);
    }
}

// A forked child never uses its parent's instance. Where the driver lets a
// child make one (lavapipe), it makes its own and a device on it; NVIDIA's
// driver 580 refuses Vulkan in the child of a process that used it (status
// 2 or 3 there: the error is clean, not a crash).
TEST(ProcessInstance, AForkedChildMakesItsOwn) {
    Result<ProcessInstance*> parent = instanceFor(false, false);
    ASSERT_TRUE(parent);
    Result<std::unique_ptr<Context>> parentCtx = Context::create(Backend::kAuto, -1, false);
    ASSERT_TRUE(parentCtx) << parentCtx.error().message;
    const bool softwareDevice = (*parentCtx)->cpuDevice();
    const VkInstance parentHandle = (*parent)->handle;
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        // 0: its own instance and a device on it; 1: the parent's instance;
        // 2: no instance; 3: an instance but no device.
        Result<ProcessInstance*> own = instanceFor(false, false);
        if (!own) _exit(2);
        if ((*own)->handle == parentHandle) _exit(1);
        Result<std::unique_ptr<Context>> ctx = Context::create(Backend::kAuto, -1, false);
        _exit(ctx ? 0 : 3);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    std::printf("  the forked child's status: %d\n", WEXITSTATUS(status));
    EXPECT_NE(WEXITSTATUS(status), 1) << "the child used its parent's instance";
    if (softwareDevice) EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
}  // namespace rthdist::gpu
