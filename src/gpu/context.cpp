#include "gpu/context.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "gpu/barriers.hpp"

namespace rthdist::gpu {

const char* vkResultName(VkResult r) {
    switch (r) {
#define RTHDIST_CASE(x) \
    case x: return #x;
        RTHDIST_CASE(VK_SUCCESS)
        RTHDIST_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        RTHDIST_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        RTHDIST_CASE(VK_ERROR_INITIALIZATION_FAILED)
        RTHDIST_CASE(VK_ERROR_DEVICE_LOST)
        RTHDIST_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        RTHDIST_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        RTHDIST_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        RTHDIST_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        RTHDIST_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        RTHDIST_CASE(VK_ERROR_UNKNOWN)
#undef RTHDIST_CASE
        default: return "VkResult";
    }
}

void throwVulkanError(VkResult result, const char* expr, const char* file, int line) {
    std::ostringstream os;
    os << "Vulkan call failed: " << vkResultName(result) << " (" << int(result) << ") in " << expr << " at "
       << file << ":" << line;
    throw VulkanError(result, os.str());
}

namespace {

// What a device must offer, as data.
const char* const kCommonExtensions[] = {
    VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
};

struct Probe {
    DeviceInfo info;
    uint32_t queueFamily = ~0u;
    bool common = false;  // everything both paths need is there
};

bool hasExtension(const std::vector<VkExtensionProperties>& exts, const char* name) {
    for (const auto& e : exts)
        if (std::strcmp(e.extensionName, name) == 0) return true;
    return false;
}

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice pd) {
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
    return exts;
}

// RTHDIST_HOST_IMPORT=1 turns the in-place reads of host arrays on. Off by
// default: on the H200 (driver 580) importing cost more than the copy it
// saves (docs/bench/prepared: the pages are pinned on every call; 5M x 5M
// points: 10.9 ms imported against 6.0 ms copied).
bool wantsHostImport() {
    const char* env = std::getenv("RTHDIST_HOST_IMPORT");
    return env != nullptr && std::string(env) == "1";
}

const char* typeName(VkPhysicalDeviceType t) {
    switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
        default: return "other";
    }
}

Probe probeDevice(VkPhysicalDevice pd, int index) {
    Probe p;
    p.info.index = index;
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(pd, &props);
    p.info.name = props.deviceName;
    p.info.type = typeName(props.deviceType);
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
    if (props.apiVersion >= VK_API_VERSION_1_2) {
        vkGetPhysicalDeviceProperties2(pd, &props2);
        p.info.driver = std::string(driver.driverName) + " " + driver.driverInfo;
    }
    auto& missing = p.info.missing;
    if (props.apiVersion < VK_API_VERSION_1_3) {
        missing.push_back("Vulkan 1.3 (device offers " +
                          std::to_string(VK_API_VERSION_MAJOR(props.apiVersion)) + "." +
                          std::to_string(VK_API_VERSION_MINOR(props.apiVersion)) + ")");
        return p;
    }
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());

    bool common = true;
    for (const char* e : kCommonExtensions) {
        if (!hasExtension(exts, e)) {
            missing.push_back(std::string("extension ") + e);
            common = false;
        }
    }
    VkPhysicalDeviceRayQueryFeaturesKHR rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtp{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR, &rq};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rtp};
    VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES, &as};
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &v13};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &v12};
    vkGetPhysicalDeviceFeatures2(pd, &f2);
    auto need = [&](bool have, const char* what) {
        if (!have) {
            missing.push_back(std::string("feature ") + what);
            common = false;
        }
    };
    need(f2.features.shaderInt64, "shaderInt64");
    need(v12.bufferDeviceAddress, "bufferDeviceAddress");
    need(v12.shaderBufferInt64Atomics, "shaderBufferInt64Atomics");
    need(v12.scalarBlockLayout, "scalarBlockLayout");
    need(v13.synchronization2, "synchronization2");
    need(as.accelerationStructure, "accelerationStructure");

    uint32_t qn = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &qn, nullptr);
    std::vector<VkQueueFamilyProperties> qf(qn);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &qn, qf.data());
    for (uint32_t i = 0; i < qn; ++i) {
        if ((qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && qf[i].timestampValidBits > 0) {
            p.queueFamily = i;
            break;
        }
    }
    if (p.queueFamily == ~0u) {
        missing.push_back("a compute queue with timestamps");
        common = false;
    }
    p.common = common;
    p.info.limits = readDeviceLimits(pd).named();
    bool hasRq = hasExtension(exts, VK_KHR_RAY_QUERY_EXTENSION_NAME) && rq.rayQuery;
    bool hasRtp = hasExtension(exts, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) && rtp.rayTracingPipeline;
    if (!hasRq) missing.push_back("ray-query: VK_KHR_ray_query with feature rayQuery");
    if (!hasRtp)
        missing.push_back("rt-pipeline: VK_KHR_ray_tracing_pipeline with feature rayTracingPipeline");
    p.info.rayQuery = common && hasRq;
    p.info.rtPipeline = common && hasRtp;
    return p;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        static_cast<Context*>(user)->countValidationMessage();
        std::fprintf(stderr, "rthdist: validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

struct InstanceHolder {
    VkInstance instance = VK_NULL_HANDLE;
    ~InstanceHolder() {
        if (instance) vkDestroyInstance(instance, nullptr);
    }
};

Result<VkInstance> createInstance(bool validation) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "rthdist";
    app.apiVersion = VK_API_VERSION_1_3;
    std::vector<const char*> layers, exts;
    if (validation) {
        uint32_t n = 0;
        vkEnumerateInstanceLayerProperties(&n, nullptr);
        std::vector<VkLayerProperties> props(n);
        vkEnumerateInstanceLayerProperties(&n, props.data());
        bool found = false;
        for (const auto& l : props) found |= std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0;
        if (!found)
            return Error{ErrorCode::kNoDevice,
                         "validation requested but VK_LAYER_KHRONOS_validation is not installed "
                         "(Debian: vulkan-validationlayers)"};
        layers.push_back("VK_LAYER_KHRONOS_validation");
        exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(exts.size());
    ci.ppEnabledExtensionNames = exts.data();
    VkInstance instance = VK_NULL_HANDLE;
    VkResult r = vkCreateInstance(&ci, nullptr, &instance);
    if (r != VK_SUCCESS)
        return Error{ErrorCode::kNoDevice,
                     std::string("no Vulkan driver could be loaded (vkCreateInstance: ") + vkResultName(r) +
                         "); install a Vulkan ICD, e.g. Mesa lavapipe"};
    return instance;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(instance, &n, pds.data());
    return pds;
}

}  // namespace

}  // namespace rthdist::gpu

namespace rthdist {

Result<std::vector<DeviceInfo>> listDevices() {
    auto inst = gpu::createInstance(false);
    if (!inst) return inst.error();
    gpu::InstanceHolder holder{inst.value()};
    std::vector<DeviceInfo> out;
    int i = 0;
    for (VkPhysicalDevice pd : gpu::physicalDevices(holder.instance))
        out.push_back(gpu::probeDevice(pd, i++).info);
    return out;
}

}  // namespace rthdist

namespace rthdist::gpu {

namespace {

// Preference among usable devices when none is named: discrete GPUs first,
// then integrated, virtual, other, and software (CPU) devices last.
int typeRank(VkPhysicalDeviceType t) {
    switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return 4;
        default: return 3;
    }
}

struct Choice {
    int index = -1;
    Probe probe;
};

// The device that runs `backend`: the one named (deviceIndex >= 0), else the
// usable one of the best type (lowest index among equals). Appends why each
// examined device that cannot run it was rejected to `reasons`.
std::optional<Choice> chooseDevice(const std::vector<VkPhysicalDevice>& pds, Backend backend, int deviceIndex,
                                   std::string& reasons) {
    std::optional<Choice> best;
    int bestRank = 0;
    for (int i = 0; i < int(pds.size()); ++i) {
        if (deviceIndex >= 0 && i != deviceIndex) continue;
        Probe p = probeDevice(pds[size_t(i)], i);
        const bool usable = backend == Backend::kRayQuery     ? p.info.rayQuery
                            : backend == Backend::kRtPipeline ? p.info.rtPipeline
                                                              : (p.info.rayQuery || p.info.rtPipeline);
        if (!usable) {
            reasons += "\n  device " + std::to_string(i) + " (" + p.info.name + "): lacks ";
            for (size_t m = 0; m < p.info.missing.size(); ++m) reasons += (m ? "; " : "") + p.info.missing[m];
            continue;
        }
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(pds[size_t(i)], &props);
        const int rank = typeRank(props.deviceType);
        if (!best || rank < bestRank) {
            best = Choice{i, p};
            bestRank = rank;
        }
    }
    return best;
}

}  // namespace

Result<std::unique_ptr<Context>> Context::create(Backend backend, int deviceIndex, bool validation) {
    auto inst = createInstance(validation);
    if (!inst) return inst.error();
    std::unique_ptr<Context> ctx(new Context());
    ctx->m_instance = inst.value();
    try {
        if (validation) {
            auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(ctx->m_instance, "vkCreateDebugUtilsMessengerEXT"));
            VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
            mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
            mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                             VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                             VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
            mi.pfnUserCallback = onDebugMessage;
            mi.pUserData = ctx.get();
            RTHDIST_VK_CHECK(createMessenger(ctx->m_instance, &mi, nullptr, &ctx->m_messenger));
            ctx->m_setObjectName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
                vkGetInstanceProcAddr(ctx->m_instance, "vkSetDebugUtilsObjectNameEXT"));
        }
        std::vector<VkPhysicalDevice> pds = physicalDevices(ctx->m_instance);
        if (pds.empty()) return Error{ErrorCode::kNoDevice, "no Vulkan physical device found"};
        std::string reasons;
        const std::optional<Choice> choice = chooseDevice(pds, backend, deviceIndex, reasons);
        const Probe chosen = choice ? choice->probe : Probe{};
        const VkPhysicalDevice chosenPd = choice ? pds[size_t(choice->index)] : VK_NULL_HANDLE;
        if (!chosenPd) {
            if (deviceIndex >= int(pds.size()))
                return Error{ErrorCode::kNoDevice, "device " + std::to_string(deviceIndex) +
                                                       " does not exist (" + std::to_string(pds.size()) +
                                                       " device(s))"};
            return Error{ErrorCode::kNoDevice, std::string("no Vulkan device can run backend ") +
                                                   backendName(backend) + ":" + reasons};
        }
        ctx->m_physical = chosenPd;
        ctx->m_name = chosen.info.name;
        ctx->m_queueFamily = chosen.queueFamily;
        ctx->m_backend = backend == Backend::kAuto
                             ? (chosen.info.rayQuery ? Backend::kRayQuery : Backend::kRtPipeline)
                             : backend;
        const bool useRq = ctx->m_backend == Backend::kRayQuery;

        std::vector<const char*> exts(std::begin(kCommonExtensions), std::end(kCommonExtensions));
        exts.push_back(useRq ? VK_KHR_RAY_QUERY_EXTENSION_NAME : VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
        // Optional: the device reads the caller's arrays in place (gpu/host_import.hpp).
        ctx->m_hostImport = wantsHostImport() && hasExtension(deviceExtensions(chosenPd),
                                                              VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
        if (ctx->m_hostImport) exts.push_back(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);

        VkPhysicalDeviceRayQueryFeaturesKHR rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
        rq.rayQuery = VK_TRUE;
        VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtp{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
        rtp.rayTracingPipeline = VK_TRUE;
        VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
        as.accelerationStructure = VK_TRUE;
        as.pNext = useRq ? static_cast<void*>(&rq) : static_cast<void*>(&rtp);
        VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES, &as};
        v13.synchronization2 = VK_TRUE;  // gpu/barriers.hpp records vkCmdPipelineBarrier2
        VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &v13};
        v12.bufferDeviceAddress = VK_TRUE;
        v12.shaderBufferInt64Atomics = VK_TRUE;
        v12.scalarBlockLayout = VK_TRUE;
        VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &v12};
        f2.features.shaderInt64 = VK_TRUE;

        float priority = 1.0f;
        VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        qci.queueFamilyIndex = ctx->m_queueFamily;
        qci.queueCount = 1;
        qci.pQueuePriorities = &priority;
        VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f2};
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &qci;
        dci.enabledExtensionCount = uint32_t(exts.size());
        dci.ppEnabledExtensionNames = exts.data();
        RTHDIST_VK_CHECK(vkCreateDevice(chosenPd, &dci, nullptr, &ctx->m_device));
        vkGetDeviceQueue(ctx->m_device, ctx->m_queueFamily, 0, &ctx->m_queue);

        VkDevice d = ctx->m_device;
        auto& rt = ctx->m_rt;
#define RTHDIST_LOAD(member, name) rt.member = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(d, #name))
        RTHDIST_LOAD(getBuildSizes, vkGetAccelerationStructureBuildSizesKHR);
        RTHDIST_LOAD(createAccel, vkCreateAccelerationStructureKHR);
        RTHDIST_LOAD(destroyAccel, vkDestroyAccelerationStructureKHR);
        RTHDIST_LOAD(cmdBuildAccel, vkCmdBuildAccelerationStructuresKHR);
        RTHDIST_LOAD(getAccelAddress, vkGetAccelerationStructureDeviceAddressKHR);
        if (!useRq) {
            RTHDIST_LOAD(createRtPipelines, vkCreateRayTracingPipelinesKHR);
            RTHDIST_LOAD(getGroupHandles, vkGetRayTracingShaderGroupHandlesKHR);
            RTHDIST_LOAD(cmdTraceRays, vkCmdTraceRaysKHR);
        }
#undef RTHDIST_LOAD
        if (!rt.getBuildSizes || !rt.createAccel || !rt.cmdBuildAccel || (!useRq && !rt.cmdTraceRays))
            return Error{ErrorCode::kNoDevice,
                         "the driver does not expose the acceleration-structure entry points"};

        ctx->m_rtProps.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR;
        ctx->m_asProps.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
        ctx->m_asProps.pNext = &ctx->m_rtProps;
        VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &ctx->m_asProps};
        vkGetPhysicalDeviceProperties2(chosenPd, &p2);
        ctx->m_timestampPeriod = p2.properties.limits.timestampPeriod;
        if (ctx->m_hostImport) {
            VkPhysicalDeviceExternalMemoryHostPropertiesEXT hp{
                VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT};
            VkPhysicalDeviceProperties2 hp2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &hp};
            vkGetPhysicalDeviceProperties2(chosenPd, &hp2);
            ctx->m_importAlignment = hp.minImportedHostPointerAlignment;
            ctx->m_getHostPointerProperties = reinterpret_cast<PFN_vkGetMemoryHostPointerPropertiesEXT>(
                vkGetDeviceProcAddr(d, "vkGetMemoryHostPointerPropertiesEXT"));
            ctx->m_hostImport = ctx->m_getHostPointerProperties != nullptr && ctx->m_importAlignment > 0;
        }
        vkGetPhysicalDeviceMemoryProperties(chosenPd, &ctx->m_memProps);
        ctx->m_limits = readDeviceLimits(chosenPd);

        VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pci.queueFamilyIndex = ctx->m_queueFamily;
        RTHDIST_VK_CHECK(vkCreateCommandPool(d, &pci, nullptr, &ctx->m_pool));
        VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        ai.commandPool = ctx->m_pool;
        ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        ai.commandBufferCount = 1;
        RTHDIST_VK_CHECK(vkAllocateCommandBuffers(d, &ai, &ctx->m_cmd));
        VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        RTHDIST_VK_CHECK(vkCreateFence(d, &fci, nullptr, &ctx->m_fence));
        VkQueryPoolCreateInfo qpi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        qpi.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qpi.queryCount = kTimestampSlots;
        RTHDIST_VK_CHECK(vkCreateQueryPool(d, &qpi, nullptr, &ctx->m_timestamps));
        uint32_t qn = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(chosenPd, &qn, nullptr);
        std::vector<VkQueueFamilyProperties> qf(qn);
        vkGetPhysicalDeviceQueueFamilyProperties(chosenPd, &qn, qf.data());
        ctx->m_timestampBits = qf[ctx->m_queueFamily].timestampValidBits;
    } catch (const VulkanError& e) {
        return Error{ErrorCode::kNoDevice, e.what()};
    }
    return ctx;
}

Context::~Context() {
    if (m_device) {
        vkDeviceWaitIdle(m_device);
        if (m_fence) vkDestroyFence(m_device, m_fence, nullptr);
        if (m_timestamps) vkDestroyQueryPool(m_device, m_timestamps, nullptr);
        if (m_pool) vkDestroyCommandPool(m_device, m_pool, nullptr);
        vkDestroyDevice(m_device, nullptr);
    }
    if (m_messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(m_instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(m_instance, m_messenger, nullptr);
    }
    if (m_instance) vkDestroyInstance(m_instance, nullptr);
}

void Context::setDebugName(VkObjectType type, uint64_t handle, const char* name) const {
    if (!m_setObjectName || !handle) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name;
    m_setObjectName(m_device, &info);
}

uint32_t Context::memoryTypeIndex(uint32_t typeBits, VkMemoryPropertyFlags wanted) const {
    for (uint32_t i = 0; i < m_memProps.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (m_memProps.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    return ~0u;
}

VkCommandBuffer Context::begin() {
    RTHDIST_VK_CHECK(vkResetCommandBuffer(m_cmd, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    RTHDIST_VK_CHECK(vkBeginCommandBuffer(m_cmd, &bi));
    vkCmdResetQueryPool(m_cmd, m_timestamps, 0, kTimestampSlots);
    vkCmdWriteTimestamp(m_cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, m_timestamps, 0);
    m_marks = 1;
    return m_cmd;
}

uint32_t Context::cmdMark(VkCommandBuffer cmd) {
    if (m_marks + 1 >= kTimestampSlots)
        throw std::logic_error("Context::cmdMark: too many marks in one submission");
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m_timestamps, m_marks);
    return m_marks++;
}

double Context::gpuMsBetween(uint32_t from, uint32_t to) const {
    const uint64_t mask = m_timestampBits >= 64 ? ~uint64_t(0) : ((uint64_t(1) << m_timestampBits) - 1);
    return double((m_stamps[to] - m_stamps[from]) & mask) * double(m_timestampPeriod) * 1e-6;
}

void Context::submitAndWait(VkCommandBuffer cmd) {
    // Every write of the submission made available to the host before the
    // fence signals: the caller reads counters and read-backs right after.
    cmdHostReadBarrier(cmd);
    const uint32_t last = m_marks;
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m_timestamps, last);
    RTHDIST_VK_CHECK(vkEndCommandBuffer(cmd));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    RTHDIST_VK_CHECK(vkQueueSubmit(m_queue, 1, &si, m_fence));
    VkResult r;
    do {
        r = vkWaitForFences(m_device, 1, &m_fence, VK_TRUE, 10'000'000'000ull);
    } while (r == VK_TIMEOUT);
    RTHDIST_VK_CHECK(r);
    RTHDIST_VK_CHECK(vkResetFences(m_device, 1, &m_fence));
    r = vkGetQueryPoolResults(m_device, m_timestamps, 0, last + 1, sizeof(m_stamps), m_stamps.data(),
                              sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    RTHDIST_VK_CHECK(r);
    m_lastGpuMs = gpuMsBetween(0, last);
}

}  // namespace rthdist::gpu
