// rthdist — device-resident input: an embedding Vulkan application lends the
// Engine its own instance, device and queue, and passes point sets that lie
// in its own VkBuffers. The points are never copied through the host. The
// only public header that includes vulkan.h (include it only where you use
// Vulkan; the consumer finds the Vulkan headers itself, e.g.
// find_package(Vulkan)).
//
// Setup
//   1. Pick a VkPhysicalDevice and call vulkanDeviceSetup(pd, backend): it says
//      whether the device can run the backend (kNoDevice naming every unmet
//      requirement otherwise) and returns the Vulkan version, the device
//      extensions and a chain of feature structures with exactly the flags the
//      backend needs set (plus shaderFloat64 where the device has it: double
//      views need it). Enable them when you create your VkDevice (merge them
//      with your own: every flag set there must stay set) with one queue of
//      setup.queueFamily (or any family with compute and timestamps).
//   2. Engine::create(VulkanDevice{...}, engineOptions) wraps your handles.
//      The Engine never destroys them; destroy the Engine (and every
//      PreparedSet it made) before the device. It creates its own command
//      pool, fence, query pool, pipelines, pipeline cache and buffers on your
//      device, and destroys them with itself.
//   3. engine.compute(DevicePointView, DevicePointView[, CallOptions]) and
//      engine.prepare(DevicePointView) read your buffers on the device.
//
// Handles come from the Vulkan loader rthdist links (libvulkan.so.1): the
// library calls the loader's exported entry points, not a dispatch table of
// yours.
//
// Synchronisation contract (who waits for what)
//   - Before the call: your writes of the buffers must have been SUBMITTED to
//     VulkanDevice::queue before the call (in submission order; the engine's
//     first command buffer begins with a barrier from all commands' memory
//     writes to its shader and transfer reads), or have COMPLETED (you waited
//     for their fence or semaphore on the host) if they ran on another queue.
//     Host writes to host-visible memory must be complete (and flushed if the
//     memory is not coherent) before the call. The engine waits on no
//     semaphore of yours.
//   - During the call: the engine submits its own command buffers to
//     VulkanDevice::queue and waits for each on a fence of its own. The queue
//     is externally synchronised (Vulkan's rule): do not submit to it from
//     another thread while a call runs. Other queues of yours may run; do not
//     write the buffers the call reads until it returns.
//   - After the call: every access of the engine to your buffers has
//     completed (its fence was waited on) and it keeps no reference to them;
//     you may write or destroy them. The engine does not wait for your other
//     work on the queue beyond what its own barriers imply.
//
// Buffers: created on VulkanDevice::device with usage
//   VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT (the ingest shader reads the
//   points through the buffer's device address) and
//   VK_BUFFER_USAGE_TRANSFER_SRC_BIT (the host reads the few points it needs by
//   vkCmdCopyBuffer, below), memory bound with
//   VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT. Any memory type.
//
// Precision: as rthdist.hpp and point_view.hpp. Float views whose origin is 0
//   run through the same device ingest as packed host arrays. Double views (or
//   a float view that meets a double one) take two device passes: the first
//   reduces each set's box in double and whether every coordinate is a
//   float32 value; the host reads those 56 bytes per set, picks the origin
//   with core's rule (centre of the union box, or 0) and the second pass
//   stores float(p - origin) computed in double on the device (round to
//   nearest, as the host path; the self-check of rthdist.hpp compares sampled
//   records with the host's rounding of your coordinates bit for bit, so a
//   driver that rounds otherwise fails loudly with kInternal). Double views need the device
//   feature shaderFloat64 enabled (VulkanDevice::shaderFloat64); without it the
//   call returns kNoDevice naming the feature. Results (H, both directed
//   values, witness indices and points) equal those of the host-array call on
//   the same coordinates, except that a directed distance of 0 (every query
//   has a copy in the other set) may name another of its queries: each is a
//   witness, and which one is the GPU's pick.
//
// What the host reads (small transfers only; the set never comes back whole):
//   - the bounds of each set (the ingest summary, 32 or 56 bytes);
//   - the bit count's sample: every sampleStride-th ingested record (about
//     32k records of 16 bytes per set), as chooseBits reads host arrays;
//   - the self-check's and the witnesses' points: at most a few dozen points
//     per direction, copied from your buffer (vkCmdCopyBuffer) in their
//     original scalar type; witness points and distances are computed from
//     them in double.
//   - with CallOptions::perPointDistances: the per-point result itself needs
//     every point, so both sets' float records (16 bytes per point) are read
//     back, as the host path reads the query records. Distances are recomputed
//     in double from those float records: identical to the host path for float
//     input (and double input of float values); for double input that is not,
//     each per-point distance is within 2 eps (rthdist.hpp) of the double
//     truth, while H and the witnesses stay exact in double.
//
// Limits (kInvalidArgument naming the limit unless said otherwise):
//   - a view: buffer not VK_NULL_HANDLE; 1 .. 2^31 - 1 points (device input is
//     not split into out-of-core pieces; a pair past the memory budget is
//     kOutOfMemory); strideBytes >= 3 scalars, a multiple of the scalar
//     size and below 2^32; offset a multiple of the scalar size; offset + (count - 1) *
//     strideBytes + 3 scalars <= bufferBytes (the size you created the buffer
//     with: Vulkan cannot report it). A NaN or infinite coordinate is
//     kInvalidArgument naming the set and the point, as for host arrays.
//   - coordinates that need core's exact power-of-two scale (searched
//     magnitudes past 2^40 or all below 2^-40) are refused: the host path
//     applies that scale.
//   - the CPU backend and Engines that own their device take no device views
//     (kInvalidArgument). Several Engines may borrow one device; calls that
//     share a queue must not overlap (the queue rule above).
//   - a prepared set from a device view keeps a device copy of the view's
//     bytes ((count - 1) * strideBytes + 3 scalars, in deviceBytes()), where
//     its self-checks and witnesses read later, and no host copy: two
//     prepared sets that do not share a frame (PrepareOptions::origin), or a
//     device set beside a host double set that is not float-exact, cannot be
//     re-indexed in their union's frame; that call is kInvalidArgument.
//
// Validation: the validation layer is yours to enable on your instance. With
//   EngineOptions::validation and VulkanDevice::debugUtils the Engine adds a
//   messenger of its own and counts warnings and errors in
//   HausdorffResult::validationMessages.
//
// Threading: as Engine (rthdist.hpp): not thread-safe; plus the queue rule
//   above.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist {

// What a VkDevice needs for one backend (step 1 above). Copyable; the
// feature structures come unlinked (pNext null): call chain() on the copy
// you pass to vkCreateDevice.
struct VulkanDeviceSetup {
    Backend backend = Backend::kRayQuery;  // kRayQuery or kRtPipeline (kAuto resolved)
    uint32_t apiVersion = VK_API_VERSION_1_3;
    std::vector<const char*> extensions;  // VkDeviceCreateInfo::ppEnabledExtensionNames (static strings)
    std::vector<std::string> features;    // the feature flags set below, by name ("rayQuery")
    uint32_t queueFamily = 0;             // a family with compute and timestamps
    bool shaderFloat64 = false;           // set below: the device has it (double views need it)
    // The feature structures (sType set, pNext linked by chain()).
    VkPhysicalDeviceFeatures2 features2{};
    VkPhysicalDeviceVulkan12Features vulkan12{};
    VkPhysicalDeviceVulkan13Features vulkan13{};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accel{};
    VkPhysicalDeviceRayQueryFeaturesKHR rayQuery{};
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtPipeline{};

    VulkanDeviceSetup() {
        features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        vulkan12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
        vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
        accel.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
        rayQuery.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
        rtPipeline.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR;
    }

    // Links features2 -> vulkan12 -> vulkan13 -> accel -> (rayQuery or
    // rtPipeline) -> `next`, and returns &features2 for
    // VkDeviceCreateInfo::pNext (with pEnabledFeatures null).
    [[nodiscard]] RTHDIST_API VkPhysicalDeviceFeatures2* chain(void* next = nullptr);
};

// Whether `pd` can run `backend` (kRayQuery, kRtPipeline, or kAuto: ray query
// where the device has it, else the ray-tracing pipeline) and what its
// VkDevice must enable. kNoDevice names every unmet requirement; kInvalidArgument
// for kCpu.
[[nodiscard]] RTHDIST_API Result<VulkanDeviceSetup> vulkanDeviceSetup(VkPhysicalDevice pd,
                                                                      Backend backend = Backend::kAuto);

// Handles an Engine borrows (never destroys).
struct VulkanDevice {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;  // created with a VulkanDeviceSetup of EngineOptions::backend
    VkQueue queue = VK_NULL_HANDLE;    // of queueFamily: compute and timestamps
    uint32_t queueFamily = 0;
    // The device was created with shaderFloat64 on (double views need it).
    bool shaderFloat64 = false;
    // The instance has VK_EXT_debug_utils enabled: with EngineOptions::validation
    // the Engine adds a messenger of its own and counts the messages
    // (HausdorffResult::validationMessages). The validation layer itself is
    // yours to enable on the instance.
    bool debugUtils = false;
};

// Points in a VkBuffer of the borrowed device: point i's x, y, z are three
// consecutive scalars at byte offset + i * strideBytes (as PointView).
struct DevicePointView {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize bufferBytes = 0;  // the size the buffer was created with
    VkDeviceSize offset = 0;       // of point 0, bytes
    size_t count = 0;
    size_t strideBytes = 12;  // >= 3 scalars, a multiple of the scalar size
    Scalar scalar = Scalar::kFloat32;

    // count points of three floats (or doubles) strideBytes apart (0: packed).
    [[nodiscard]] static DevicePointView floats(VkBuffer buffer, VkDeviceSize bufferBytes, size_t count,
                                                VkDeviceSize offset = 0, size_t strideBytes = 0) {
        return make(buffer, bufferBytes, count, offset, strideBytes, Scalar::kFloat32);
    }
    [[nodiscard]] static DevicePointView doubles(VkBuffer buffer, VkDeviceSize bufferBytes, size_t count,
                                                 VkDeviceSize offset = 0, size_t strideBytes = 0) {
        return make(buffer, bufferBytes, count, offset, strideBytes, Scalar::kFloat64);
    }

private:
    static DevicePointView make(VkBuffer buffer, VkDeviceSize bufferBytes, size_t count, VkDeviceSize offset,
                                size_t strideBytes, Scalar scalar) {
        DevicePointView v;
        v.buffer = buffer;
        v.bufferBytes = bufferBytes;
        v.offset = offset;
        v.count = count;
        v.scalar = scalar;
        v.strideBytes = strideBytes == 0 ? 3 * scalarBytes(scalar) : strideBytes;
        return v;
    }
};

}  // namespace rthdist
