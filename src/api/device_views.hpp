// Device input at the public boundary (rthdist/vulkan_interop.hpp): the
// checks of a DevicePointView against the contract's limits, the view as
// the device ingest reads it, and the
// embedder's device setup (vulkanDeviceSetup).
#pragma once

#include <optional>

#include "rthdist/vulkan_interop.hpp"

namespace rthdist::gpu_algo {
struct DeviceInput;  // gpu_algo/set_points.hpp
}  // namespace rthdist::gpu_algo

namespace rthdist::api {

// The view's checks against the contract's limits (no device needed):
// kInvalidArgument naming the set (`name`) and the limit it breaks. The
// Engine runs them once per view, before any backend sees it.
[[nodiscard]] std::optional<Error> checkDeviceView(const DevicePointView& view, const char* name);

// The view as the device ingest reads it: its buffer's device address on
// `device`. `view` passed checkDeviceView.
[[nodiscard]] gpu_algo::DeviceInput deviceInputOf(const DevicePointView& view, VkDevice device);

}  // namespace rthdist::api
