#include "gpu/device_requirements.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <iterator>

#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

namespace {

// The feature structures of FeatureChain, in chain order.
enum class Holder { kCore, kVulkan12, kVulkan13, kAccel, kRayQuery, kRtPipeline };

struct FeatureEntry {
    const char* name;
    Holder holder;
    size_t offset;          // of its VkBool32 in the holder
    const char* extension;  // that provides the holder; nullptr for core
};

// In DeviceFeature order.
const FeatureEntry kFeatures[] = {
    {"shaderInt64", Holder::kCore,
     offsetof(VkPhysicalDeviceFeatures2, features) + offsetof(VkPhysicalDeviceFeatures, shaderInt64),
     nullptr},
    {"bufferDeviceAddress", Holder::kVulkan12,
     offsetof(VkPhysicalDeviceVulkan12Features, bufferDeviceAddress), nullptr},
    {"shaderBufferInt64Atomics", Holder::kVulkan12,
     offsetof(VkPhysicalDeviceVulkan12Features, shaderBufferInt64Atomics), nullptr},
    {"scalarBlockLayout", Holder::kVulkan12, offsetof(VkPhysicalDeviceVulkan12Features, scalarBlockLayout),
     nullptr},
    {"synchronization2", Holder::kVulkan13, offsetof(VkPhysicalDeviceVulkan13Features, synchronization2),
     nullptr},
    {"accelerationStructure", Holder::kAccel,
     offsetof(VkPhysicalDeviceAccelerationStructureFeaturesKHR, accelerationStructure),
     VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME},
    {"rayQuery", Holder::kRayQuery, offsetof(VkPhysicalDeviceRayQueryFeaturesKHR, rayQuery),
     VK_KHR_RAY_QUERY_EXTENSION_NAME},
    {"rayTracingPipeline", Holder::kRtPipeline,
     offsetof(VkPhysicalDeviceRayTracingPipelineFeaturesKHR, rayTracingPipeline),
     VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME},
    {"shaderFloat64", Holder::kCore,
     offsetof(VkPhysicalDeviceFeatures2, features) + offsetof(VkPhysicalDeviceFeatures, shaderFloat64),
     nullptr},
    {"rayTracingPipelineTraceRaysIndirect", Holder::kRtPipeline,
     offsetof(VkPhysicalDeviceRayTracingPipelineFeaturesKHR, rayTracingPipelineTraceRaysIndirect),
     VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME},
};
static_assert(std::size(kFeatures) == size_t(DeviceFeature::kCount));

const FeatureEntry& entry(DeviceFeature f) { return kFeatures[size_t(f)]; }

// The feature structures of a device, chained behind a
// VkPhysicalDeviceFeatures2: only the linked ones are seen by Vulkan.
class FeatureChain {
public:
    FeatureChain() {
        m_features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
        m_vulkan12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
        m_vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
        m_accel.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
        m_rayQuery.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
        m_rtPipeline.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR;
    }
    FeatureChain(const FeatureChain&) = delete;
    FeatureChain& operator=(const FeatureChain&) = delete;

    [[nodiscard]] VkPhysicalDeviceFeatures2* head() { return &m_features2; }
    [[nodiscard]] VkBool32& flag(DeviceFeature feature) {
        return *reinterpret_cast<VkBool32*>(reinterpret_cast<char*>(holder(feature)) + entry(feature).offset);
    }
    // Chains the structure that holds `feature` (once).
    void link(DeviceFeature feature) {
        VkBaseOutStructure* s = holder(feature);
        auto* head = reinterpret_cast<VkBaseOutStructure*>(&m_features2);
        for (VkBaseOutStructure* p = head; p != nullptr; p = p->pNext)
            if (p == s) return;
        s->pNext = head->pNext;
        head->pNext = s;
    }

private:
    VkBaseOutStructure* holder(DeviceFeature feature) {
        void* s = nullptr;
        switch (entry(feature).holder) {
            case Holder::kCore: s = &m_features2; break;
            case Holder::kVulkan12: s = &m_vulkan12; break;
            case Holder::kVulkan13: s = &m_vulkan13; break;
            case Holder::kAccel: s = &m_accel; break;
            case Holder::kRayQuery: s = &m_rayQuery; break;
            case Holder::kRtPipeline: s = &m_rtPipeline; break;
        }
        return static_cast<VkBaseOutStructure*>(s);
    }

    VkPhysicalDeviceFeatures2 m_features2{};
    VkPhysicalDeviceVulkan12Features m_vulkan12{};
    VkPhysicalDeviceVulkan13Features m_vulkan13{};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR m_accel{};
    VkPhysicalDeviceRayQueryFeaturesKHR m_rayQuery{};
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR m_rtPipeline{};
};

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice pd) {
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
    exts.resize(n);
    return exts;
}

bool hasExtension(const std::vector<VkExtensionProperties>& exts, const char* name) {
    return std::any_of(exts.begin(), exts.end(), [&](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
    });
}

std::string versionName(uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v));
}

}  // namespace

const char* featureName(DeviceFeature feature) { return entry(feature).name; }

bool DeviceRequirements::needs(DeviceFeature feature) const {
    return std::find(features.begin(), features.end(), feature) != features.end();
}

bool DeviceRequirements::needs(const char* extension) const {
    return std::any_of(extensions.begin(), extensions.end(),
                       [&](const char* e) { return std::strcmp(e, extension) == 0; });
}

DeviceRequirements computeRequirements() {
    DeviceRequirements r;
    r.features = {DeviceFeature::kShaderInt64, DeviceFeature::kBufferDeviceAddress,
                  DeviceFeature::kShaderBufferInt64Atomics, DeviceFeature::kScalarBlockLayout,
                  DeviceFeature::kSynchronization2};
    return r;
}

DeviceRequirements backendRequirements(Backend backend) {
    DeviceRequirements r = computeRequirements();
    r.backend = backend;
    r.extensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    r.features.push_back(DeviceFeature::kAccelerationStructure);
    if (backend == Backend::kRayQuery) {
        r.extensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
        r.features.push_back(DeviceFeature::kRayQuery);
    } else if (backend == Backend::kRtPipeline) {
        r.extensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
        r.features.push_back(DeviceFeature::kRayTracingPipeline);
    }
    return r;
}

void describeForEmbedder(const DeviceRequirements& req, VulkanDeviceSetup& setup) {
    setup.apiVersion = req.apiVersion;
    setup.extensions = req.extensions;
    for (DeviceFeature f : req.features) {
        void* holder = nullptr;
        switch (entry(f).holder) {
            case Holder::kCore: holder = &setup.features2; break;
            case Holder::kVulkan12: holder = &setup.vulkan12; break;
            case Holder::kVulkan13: holder = &setup.vulkan13; break;
            case Holder::kAccel: holder = &setup.accel; break;
            case Holder::kRayQuery: holder = &setup.rayQuery; break;
            case Holder::kRtPipeline: holder = &setup.rtPipeline; break;
        }
        *reinterpret_cast<VkBool32*>(static_cast<char*>(holder) + entry(f).offset) = VK_TRUE;
        setup.features.emplace_back(featureName(f));
    }
}

bool deviceHasExtension(VkPhysicalDevice pd, const char* name) {
    return hasExtension(deviceExtensions(pd), name);
}

uint32_t computeQueueFamily(VkPhysicalDevice pd) {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
    for (uint32_t i = 0; i < n; ++i)
        if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && families[i].timestampValidBits > 0) return i;
    return ~0u;
}

std::vector<std::string> unmetRequirements(VkPhysicalDevice pd, const DeviceRequirements& req) {
    std::vector<std::string> unmet;
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(pd, &props);
    if (props.apiVersion < req.apiVersion) {
        unmet.push_back("Vulkan " + versionName(req.apiVersion) + " (device offers " +
                        versionName(props.apiVersion) + ")");
        return unmet;  // the feature structures of a newer version cannot be queried
    }
    const std::vector<VkExtensionProperties> exts = deviceExtensions(pd);
    for (const char* e : req.extensions)
        if (!hasExtension(exts, e)) unmet.push_back(std::string("extension ") + e);

    // Query the structures of every listed feature the device can report on.
    FeatureChain have;
    for (DeviceFeature f : req.features) {
        const FeatureEntry& e = entry(f);
        if (e.extension == nullptr || hasExtension(exts, e.extension)) have.link(f);
    }
    vkGetPhysicalDeviceFeatures2(pd, have.head());
    for (DeviceFeature f : req.features)
        if (!have.flag(f)) unmet.push_back(std::string("feature ") + featureName(f));

    if (computeQueueFamily(pd) == ~0u) unmet.push_back("a compute queue with timestamps");
    return unmet;
}

bool deviceHasFeature(VkPhysicalDevice pd, DeviceFeature feature) {
    DeviceRequirements one;
    one.apiVersion = VK_API_VERSION_1_0;
    one.features = {feature};
    return unmetRequirements(pd, one).empty();
}

VkResult createDeviceFor(VkPhysicalDevice pd, const DeviceRequirements& req,
                         std::span<const char* const> extraExtensions, uint32_t queueFamily,
                         VkDevice* device) {
    std::vector<const char*> exts = req.extensions;
    exts.insert(exts.end(), extraExtensions.begin(), extraExtensions.end());
    FeatureChain features;
    for (DeviceFeature f : req.features) {
        features.flag(f) = VK_TRUE;
        features.link(f);
    }
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci =
        vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    qci.queueFamilyIndex = queueFamily;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci =
        vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, features.head());
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = uint32_t(exts.size());
    dci.ppEnabledExtensionNames = exts.data();
    return vkCreateDevice(pd, &dci, nullptr, device);
}

}  // namespace rthdist::gpu
