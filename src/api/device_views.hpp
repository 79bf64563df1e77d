// Device input at the public boundary (rthdist/vulkan_interop.hpp): the
// checks of a DevicePointView against the contract's limits, and the
// embedder's device setup (vulkanDeviceSetup).
#pragma once

#include "gpu_algo/set_points.hpp"
#include "rthdist/vulkan_interop.hpp"

namespace rthdist::api {

// The view as the device ingest reads it (its buffer's device address on
// `device`), or kInvalidArgument naming the set and the limit it breaks.
[[nodiscard]] Result<gpu_algo::DeviceInput> checkDeviceView(const DevicePointView& view, const char* name,
                                                            VkDevice device);

}  // namespace rthdist::api
