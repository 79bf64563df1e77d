// The device limits that bound the size of a problem (design.md §9), read once
// per device. Every buffer, dispatch and trace of an Engine is checked
// against them before it is recorded: a size past a limit is refused with
// the limit named, never truncated. Tests shrink them (Context::setLimits)
// to cross every split boundary with small inputs.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rthdist::gpu {

struct DeviceLimits {
    // maxBufferSize (maintenance4; unbounded where the device does not
    // report it): no VkBuffer may be larger, so larger ones are refused.
    uint64_t maxBufferBytes = UINT64_MAX;
    // maxMemoryAllocationSize (maintenance3): allocations above it "may
    // fail" (some drivers grant them), so they are tried, and a failure
    // names this limit.
    uint64_t maxAllocationBytes = UINT64_MAX;
    uint64_t deviceHeapBytes = UINT64_MAX;  // the largest DEVICE_LOCAL heap
    // VK_EXT_memory_budget's heapBudget of that heap when the device has the
    // extension (what this process may use now), else deviceHeapBytes.
    uint64_t deviceBudgetBytes = UINT64_MAX;
    uint64_t hostHeapBytes = UINT64_MAX;  // the largest heap with a HOST_VISIBLE type (staging)
    uint32_t maxGroupsX = 65535;          // maxComputeWorkGroupCount[0]: dispatches are split
    // Ray-tracing pipeline: invocations of one vkCmdTraceRaysKHR
    // (maxRayDispatchInvocationCount, and the width limit
    // maxComputeWorkGroupCount[0] * maxComputeWorkGroupSize[0]): traces are split.
    uint64_t maxRayDispatch = uint64_t(1) << 30;
    uint64_t maxPrimitives = UINT64_MAX;  // maxPrimitiveCount of one BLAS

    // Name/value pairs for --list-devices.
    [[nodiscard]] std::vector<std::pair<std::string, uint64_t>> named() const;
};

// A size past a device limit, found while recording: the public entry turns
// it into ErrorCode::kOutOfMemory with this message (the limit named).
class LimitError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Throws LimitError unless value <= limit ("<what> needs <value>, the device's <limitName> is <limit>").
void requireWithin(uint64_t value, uint64_t limit, const char* what, const char* limitName);

// Reads the limits of a physical device (Vulkan 1.2 or later).
[[nodiscard]] DeviceLimits readDeviceLimits(VkPhysicalDevice pd);

}  // namespace rthdist::gpu
