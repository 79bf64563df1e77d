#include "api/device_views.hpp"

#include <string>

#include "api/out_of_core.hpp"
#include "gpu/device_requirements.hpp"
#include "gpu/vk_struct.hpp"
#include "gpu_algo/set_points.hpp"

namespace rthdist {

VkPhysicalDeviceFeatures2* VulkanDeviceSetup::chain(void* next) {
    features2.pNext = &vulkan12;
    vulkan12.pNext = &vulkan13;
    vulkan13.pNext = &accel;
    void* last =
        backend == Backend::kRayQuery ? static_cast<void*>(&rayQuery) : static_cast<void*>(&rtPipeline);
    accel.pNext = last;
    rayQuery.pNext = rtPipeline.pNext = next;
    return &features2;
}

Result<VulkanDeviceSetup> vulkanDeviceSetup(VkPhysicalDevice pd, Backend backend) {
    if (pd == VK_NULL_HANDLE)
        return Error{ErrorCode::kInvalidArgument, "vulkanDeviceSetup: no physical device"};
    if (backend == Backend::kCpu)
        return Error{ErrorCode::kInvalidArgument, "the cpu backend needs no Vulkan device"};
    if (backend == Backend::kAuto)
        backend = gpu::unmetRequirements(pd, gpu::backendRequirements(Backend::kRayQuery)).empty()
                      ? Backend::kRayQuery
                      : Backend::kRtPipeline;
    gpu::DeviceRequirements req = gpu::backendRequirements(backend);
    const std::vector<std::string> unmet = gpu::unmetRequirements(pd, req);
    if (!unmet.empty()) {
        std::string lacks;
        for (size_t m = 0; m < unmet.size(); ++m) lacks += (m ? "; " : "") + unmet[m];
        return Error{ErrorCode::kNoDevice, std::string("the device cannot run backend ") +
                                               backendName(backend) + ": lacks " + lacks};
    }
    VulkanDeviceSetup setup;
    setup.backend = backend;
    setup.shaderFloat64 = gpu::deviceHasFeature(pd, gpu::DeviceFeature::kShaderFloat64);
    if (setup.shaderFloat64) req.features.push_back(gpu::DeviceFeature::kShaderFloat64);
    gpu::describeForEmbedder(req, setup);
    setup.queueFamily = gpu::computeQueueFamily(pd);
    return setup;  // unlinked: chain() links the caller's copy
}

namespace api {

std::optional<Error> checkDeviceView(const DevicePointView& view, const char* name) {
    const std::string set = std::string("device view ") + name + ": ";
    const VkDeviceSize scalar = scalarBytes(view.scalar);
    const auto refuse = [&](const std::string& why) { return Error{ErrorCode::kInvalidArgument, set + why}; };
    if (view.buffer == VK_NULL_HANDLE) return refuse("no buffer (VK_NULL_HANDLE)");
    if (view.count == 0) return refuse("the set is empty (H is undefined)");
    if (view.count > kMaxCallPoints)
        return refuse(
            std::to_string(view.count) +
            " points: device input holds at most 2^31 - 1 points per set (it is not split into pieces)");
    if (view.strideBytes < 3 * scalar || view.strideBytes % scalar != 0 || view.strideBytes > UINT32_MAX)
        return refuse("strideBytes " + std::to_string(view.strideBytes) + " must be at least " +
                      std::to_string(3 * scalar) + " and a multiple of " + std::to_string(scalar));
    if (view.offset % scalar != 0)
        return refuse("offset " + std::to_string(view.offset) + " is not a multiple of " +
                      std::to_string(scalar));
    // Compared without overflow: offset first, then what follows it.
    const VkDeviceSize span = VkDeviceSize(view.count - 1) * view.strideBytes + 3 * scalar;
    if (view.offset > view.bufferBytes || view.bufferBytes - view.offset < span)
        return refuse("offset " + std::to_string(view.offset) + " + (count - 1) * strideBytes + 3 scalars (" +
                      std::to_string(span) + " bytes) is past bufferBytes " +
                      std::to_string(view.bufferBytes));
    return std::nullopt;
}

gpu_algo::DeviceInput deviceInputOf(const DevicePointView& view, VkDevice device) {
    VkBufferDeviceAddressInfo info =
        gpu::vkStruct<VkBufferDeviceAddressInfo>(VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO);
    info.buffer = view.buffer;
    gpu_algo::DeviceInput in;
    in.buffer = view.buffer;
    in.address = vkGetBufferDeviceAddress(device, &info) + view.offset;
    in.offset = view.offset;
    in.n = uint32_t(view.count);
    in.stride = uint32_t(view.strideBytes);
    in.scalar = view.scalar;
    return in;
}

}  // namespace api
}  // namespace rthdist
