// gpu::Unique, the owner of every Vulkan handle, with a fake handle type and
// a deleter that records what it destroyed: no device needed. Each handle is
// destroyed exactly once, on reset, reassignment, destruction, or when a
// constructor throws after taking it; never after a move or release.
#include <gtest/gtest.h>

#include <stdexcept>
#include <utility>
#include <vector>

#include "gpu/unique_handle.hpp"

namespace rthdist::gpu {
namespace {

struct FakeObject {};
using FakeHandle = FakeObject*;

struct RecordingDeleter {
    std::vector<FakeHandle>* destroyed = nullptr;
    void operator()(FakeHandle h) const noexcept { destroyed->push_back(h); }
};
using UniqueFake = Unique<FakeHandle, RecordingDeleter>;

FakeObject a, b, c;

TEST(UniqueHandle, EmptyDestroysNothing) {
    std::vector<FakeHandle> destroyed;
    {
        UniqueFake empty;
        EXPECT_FALSE(empty);
        UniqueFake nullHandle(nullptr, {&destroyed});
        nullHandle.reset();
    }
    EXPECT_TRUE(destroyed.empty());
}

TEST(UniqueHandle, DestroyedOnceWhenTheOwnerGoes) {
    std::vector<FakeHandle> destroyed;
    {
        UniqueFake owner(&a, {&destroyed});
        EXPECT_TRUE(owner);
        EXPECT_EQ(owner.get(), &a);
    }
    EXPECT_EQ(destroyed, std::vector<FakeHandle>{&a});
}

TEST(UniqueHandle, ResetDestroysNowAndOnlyOnce) {
    std::vector<FakeHandle> destroyed;
    {
        UniqueFake owner(&a, {&destroyed});
        owner.reset();
        EXPECT_FALSE(owner);
        owner.reset();
    }
    EXPECT_EQ(destroyed, std::vector<FakeHandle>{&a});
}

TEST(UniqueHandle, MoveTransfersOwnership) {
    std::vector<FakeHandle> destroyed;
    {
        UniqueFake first(&a, {&destroyed});
        UniqueFake second(std::move(first));
        EXPECT_FALSE(first);  // NOLINT(bugprone-use-after-move): the moved-from state is the contract
        EXPECT_EQ(second.get(), &a);
        EXPECT_TRUE(destroyed.empty());
    }
    EXPECT_EQ(destroyed, std::vector<FakeHandle>{&a});
}

TEST(UniqueHandle, MoveAssignmentDestroysTheOldHandleFirst) {
    std::vector<FakeHandle> destroyed;
    {
        UniqueFake target(&a, {&destroyed});
        UniqueFake source(&b, {&destroyed});
        target = std::move(source);
        EXPECT_EQ(destroyed, std::vector<FakeHandle>{&a});
        EXPECT_EQ(target.get(), &b);
        EXPECT_FALSE(source);  // NOLINT(bugprone-use-after-move)
        target = UniqueFake(&c, {&destroyed});
        EXPECT_EQ(destroyed, (std::vector<FakeHandle>{&a, &b}));
    }
    EXPECT_EQ(destroyed, (std::vector<FakeHandle>{&a, &b, &c}));
}

TEST(UniqueHandle, SelfMoveAssignmentKeepsTheHandle) {
    std::vector<FakeHandle> destroyed;
    UniqueFake owner(&a, {&destroyed});
    UniqueFake& alias = owner;
    owner = std::move(alias);
    EXPECT_EQ(owner.get(), &a);
    EXPECT_TRUE(destroyed.empty());
}

TEST(UniqueHandle, ReleaseGivesUpWithoutDestroying) {
    std::vector<FakeHandle> destroyed;
    {
        UniqueFake owner(&a, {&destroyed});
        EXPECT_EQ(owner.release(), &a);
        EXPECT_FALSE(owner);
    }
    EXPECT_TRUE(destroyed.empty());
}

// The pattern of Pipelines, Context and the renderer: members assigned step
// by step; a throw in a later step releases the earlier steps' handles, in
// reverse order of declaration.
struct BuiltInSteps {
    UniqueFake first, second, third;
    BuiltInSteps(std::vector<FakeHandle>& destroyed, bool failAtThird) {
        first = UniqueFake(&a, {&destroyed});
        second = UniqueFake(&b, {&destroyed});
        if (failAtThird) throw std::runtime_error("step 3 failed");
        third = UniqueFake(&c, {&destroyed});
    }
};

TEST(UniqueHandle, AThrowingConstructorReleasesWhatItHadCreated) {
    std::vector<FakeHandle> destroyed;
    EXPECT_THROW(BuiltInSteps(destroyed, true), std::runtime_error);
    EXPECT_EQ(destroyed, (std::vector<FakeHandle>{&b, &a}));
}

TEST(UniqueHandle, ABuiltObjectReleasesInReverseOrder) {
    std::vector<FakeHandle> destroyed;
    { BuiltInSteps built(destroyed, false); }
    EXPECT_EQ(destroyed, (std::vector<FakeHandle>{&c, &b, &a}));
}

TEST(UniqueHandle, DeviceChildOwnersAreOneHandleAndOneDevice) {
    // No call is made: an empty owner of a device child destroys nothing.
    UniquePipeline pipeline;
    EXPECT_FALSE(pipeline);
    static_assert(sizeof(UniquePipeline) == sizeof(VkPipeline) + sizeof(VkDevice));
    static_assert(!std::is_copy_constructible_v<UniquePipeline>);
    static_assert(std::is_nothrow_move_constructible_v<UniquePipeline>);
    static_assert(std::is_nothrow_move_assignable_v<UniqueBuffer>);
}

}  // namespace
}  // namespace rthdist::gpu
