// The process's Vulkan instances: created on first use, one per
// configuration (validation layer or not, debug utilities or not), and kept
// for the rest of the process.
//
// Why: NVIDIA's driver (580, H200) refuses the 29th vkCreateInstance of a
// process, with VK_ERROR_INCOMPATIBLE_DRIVER, however many were destroyed
// before (measured: instance-only create/destroy loops fail at the 29th;
// one instance with 200 devices in turn does not). A process that makes an
// Engine per call (a server, a test suite, a Python loop) would stop
// working. Devices are still made and destroyed per Context.
//
// Threading: instanceFor may be called from any thread. A forked child does
// not use its parent's instances (the driver's state does not survive a
// fork): it makes its own on first use.
//
// Validation messages (warnings and errors) are printed to stderr and
// counted per instance; a Context reads how many arrived since it was made
// (Context::validationMessageCount). Engines alive at the same time in one
// process therefore see each other's messages: a count can be too large,
// never too small.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>

#include "rthdist/rthdist.hpp"

namespace rthdist::gpu {

struct ProcessInstance {
    VkInstance handle = VK_NULL_HANDLE;
    bool debugUtils = false;  // VK_EXT_debug_utils is enabled
    bool validation = false;  // the Khronos validation layer is enabled, messages counted
    std::atomic<uint64_t> messages{0};
};

// A messenger's create info that prints validation warnings and errors to
// stderr and counts them in *count (the process's instances', and a
// borrowed instance's when a Context asks for validation on it).
[[nodiscard]] VkDebugUtilsMessengerCreateInfoEXT validationMessengerInfo(std::atomic<uint64_t>* count);

// The process's instance of Vulkan 1.3 with the validation layer when asked
// for (kNoDevice when it is not installed), and VK_EXT_debug_utils with
// validation or `debugLabels` where the loader has it. kNoDevice when no
// driver can be loaded. The returned instance lives until the process ends.
[[nodiscard]] Result<ProcessInstance*> instanceFor(bool validation, bool debugLabels);

}  // namespace rthdist::gpu
