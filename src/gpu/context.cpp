#include "gpu/context.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "gpu/barriers.hpp"
#include "gpu/process_instance.hpp"
#include "gpu/vk_struct.hpp"

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

const char* typeName(VkPhysicalDeviceType t) {
    switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
        default: return "other";
    }
}

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

// `into` followed by the entries of `more` it does not have yet.
void appendNew(std::vector<std::string>& into, const std::vector<std::string>& more,
               const std::string& prefix) {
    for (const std::string& m : more)
        if (std::find(into.begin(), into.end(), prefix + m) == into.end()) into.push_back(prefix + m);
}

// What --list-devices shows: both backends' requirements probed; what both
// lack is listed once, what one lacks with the backend's name.
DeviceInfo describeDevice(VkPhysicalDevice pd, int index) {
    DeviceInfo info;
    info.index = index;
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(pd, &props);
    info.name = props.deviceName;
    info.type = typeName(props.deviceType);
    if (props.apiVersion >= VK_API_VERSION_1_2) {
        VkPhysicalDeviceDriverProperties driver =
            vkStruct<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
        VkPhysicalDeviceProperties2 props2 =
            vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver);
        vkGetPhysicalDeviceProperties2(pd, &props2);
        info.driver = std::string(driver.driverName) + " " + driver.driverInfo;
        info.limits = readDeviceLimits(pd).named();
    }
    const std::vector<std::string> rq = unmetRequirements(pd, backendRequirements(Backend::kRayQuery));
    const std::vector<std::string> rtp = unmetRequirements(pd, backendRequirements(Backend::kRtPipeline));
    info.rayQuery = rq.empty();
    info.rtPipeline = rtp.empty();
    for (const std::string& m : rq) {
        const bool both = std::find(rtp.begin(), rtp.end(), m) != rtp.end();
        info.missing.push_back(both ? m : "ray-query: " + m);
    }
    for (const std::string& m : rtp)
        if (std::find(rq.begin(), rq.end(), m) == rq.end()) info.missing.push_back("rt-pipeline: " + m);
    return info;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(instance, &n, pds.data());
    return pds;
}

struct Choice {
    size_t index = 0;        // of the device
    size_t alternative = 0;  // the requirements it meets
};

// The device that meets one of `alternatives`: the one named (deviceIndex >=
// 0), else the usable one of the best type (lowest index among equals).
// Appends why each examined device that meets none was rejected to `reasons`.
std::optional<Choice> chooseDevice(const std::vector<VkPhysicalDevice>& pds,
                                   std::span<const DeviceRequirements> alternatives, int deviceIndex,
                                   std::string& reasons) {
    std::optional<Choice> best;
    int bestRank = 0;
    for (size_t i = 0; i < pds.size(); ++i) {
        if (deviceIndex >= 0 && i != size_t(deviceIndex)) continue;
        std::optional<size_t> met;
        std::vector<std::string> lacks;
        for (size_t a = 0; a < alternatives.size() && !met; ++a) {
            const std::vector<std::string> unmet = unmetRequirements(pds[i], alternatives[a]);
            if (unmet.empty()) met = a;
            appendNew(lacks, unmet, "");
        }
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(pds[i], &props);
        if (!met) {
            reasons += "\n  device " + std::to_string(i) + " (" + props.deviceName + "): lacks ";
            for (size_t m = 0; m < lacks.size(); ++m) reasons += (m ? "; " : "") + lacks[m];
            continue;
        }
        const int rank = typeRank(props.deviceType);
        if (!best || rank < bestRank) {
            best = Choice{i, *met};
            bestRank = rank;
        }
    }
    return best;
}

}  // namespace

Result<std::vector<DeviceInfo>> describeDevices() {
    Result<ProcessInstance*> instance = instanceFor(false, false);
    if (!instance) return instance.error();
    std::vector<DeviceInfo> out;
    int i = 0;
    for (VkPhysicalDevice pd : physicalDevices((*instance)->handle)) out.push_back(describeDevice(pd, i++));
    return out;
}

Result<std::unique_ptr<Context>> Context::create(Backend backend, int deviceIndex, bool validation,
                                                 const Tuning& tuning) {
    std::vector<DeviceRequirements> alternatives;
    if (backend != Backend::kRtPipeline) alternatives.push_back(backendRequirements(Backend::kRayQuery));
    if (backend != Backend::kRayQuery) alternatives.push_back(backendRequirements(Backend::kRtPipeline));
    return create(alternatives, std::string("backend ") + backendName(backend), deviceIndex, validation,
                  tuning);
}

Result<std::unique_ptr<Context>> Context::create(std::span<const DeviceRequirements> alternatives,
                                                 const std::string& purpose, int deviceIndex, bool validation,
                                                 const Tuning& tuning) {
    std::unique_ptr<Context> ctx(new Context());
    ctx->m_tuning = tuning;
    try {
        const auto t0 = std::chrono::steady_clock::now();
        if (std::optional<Error> err = ctx->createInstance(validation)) return *err;
        const auto t1 = std::chrono::steady_clock::now();
        const std::vector<VkPhysicalDevice> pds = physicalDevices(ctx->m_instanceHandle);
        if (pds.empty()) return Error{ErrorCode::kNoDevice, "no Vulkan physical device found"};
        std::string reasons;
        const std::optional<Choice> choice = chooseDevice(pds, alternatives, deviceIndex, reasons);
        if (!choice) {
            if (deviceIndex >= int(pds.size()))
                return Error{ErrorCode::kNoDevice, "device " + std::to_string(deviceIndex) +
                                                       " does not exist (" + std::to_string(pds.size()) +
                                                       " device(s))"};
            return Error{ErrorCode::kNoDevice, "no Vulkan device can run " + purpose + ":" + reasons};
        }
        const DeviceRequirements& req = alternatives[choice->alternative];
        ctx->m_physical = pds[choice->index];
        ctx->m_backend = req.backend;
        const auto t2 = std::chrono::steady_clock::now();
        ctx->createDevice(req);
        const auto t3 = std::chrono::steady_clock::now();
        if (std::optional<Error> err = ctx->loadRtFunctions(req)) return *err;
        ctx->readProperties(req);
        ctx->createCommandObjects();
        if (ctx->m_traceSubmits) {
            const auto ms = [](auto from, auto to) {
                return std::chrono::duration<double, std::milli>(to - from).count();
            };
            std::fprintf(stderr,
                         "rthdist setup: instance %.1f ms, choosing device %d %.1f ms, its VkDevice %.1f ms, "
                         "properties and command objects %.1f ms\n",
                         ms(t0, t1), int(choice->index), ms(t1, t2), ms(t2, t3),
                         ms(t3, std::chrono::steady_clock::now()));
        }
    } catch (const VulkanError& e) {
        return Error{ErrorCode::kNoDevice, e.what()};
    }
    return ctx;
}

std::optional<Error> Context::createInstance(bool validation) {
    Result<ProcessInstance*> instance = instanceFor(validation, m_tuning.debugLabels);
    if (!instance) return instance.error();
    m_process = *instance;
    m_processMessagesBefore = m_process->messages.load();
    m_instanceHandle = m_process->handle;
    // Null where the instance has no VK_EXT_debug_utils: the helpers then do nothing.
    if (m_process->debugUtils)
        m_setObjectName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
            vkGetInstanceProcAddr(m_instanceHandle, "vkSetDebugUtilsObjectNameEXT"));
    return std::nullopt;
}

std::optional<Error> Context::createMessenger() {
    const VkInstance inst = m_instanceHandle;
    auto createFn = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(inst, "vkCreateDebugUtilsMessengerEXT"));
    auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(inst, "vkDestroyDebugUtilsMessengerEXT"));
    if (!createFn || !destroyMessenger)
        return Error{ErrorCode::kNoDevice, "validation requested but VK_EXT_debug_utils has no messenger"};
    const VkDebugUtilsMessengerCreateInfoEXT mi = validationMessengerInfo(&m_validationMessages);
    VkDebugUtilsMessengerEXT messenger;
    RTHDIST_VK_CHECK(createFn(inst, &mi, nullptr, &messenger));
    m_messenger = UniqueMessenger(messenger, {inst, destroyMessenger});
    return std::nullopt;
}

// The device with exactly the extensions and features of `req` (plus the
// optional host import, and shaderFloat64 where the device has it: the
// automatic bit count's probe on the device), and its one compute queue.
void Context::createDevice(const DeviceRequirements& required) {
    m_queueFamily = computeQueueFamily(m_physical);
    DeviceRequirements req = required;
    m_shaderFloat64 = deviceHasFeature(m_physical, DeviceFeature::kShaderFloat64);
    if (m_shaderFloat64 && !req.needs(DeviceFeature::kShaderFloat64))
        req.features.push_back(DeviceFeature::kShaderFloat64);
    // Optional too: ray traces sized by the device (the candidate search's
    // radii of one submission launch only the queries still searched).
    if (req.needs(DeviceFeature::kRayTracingPipeline) &&
        deviceHasFeature(m_physical, DeviceFeature::kTraceRaysIndirect))
        req.features.push_back(DeviceFeature::kTraceRaysIndirect);
    // Optional: the device reads the caller's arrays in place (gpu/host_import.hpp).
    // Off by default (Tuning::hostImport): on the H200 (driver 580) importing
    // cost more than the copy it saves (docs/bench/prepared: the pages are
    // pinned on every call; 5M x 5M points: 10.9 ms imported, 6.0 ms copied).
    m_hostImport =
        m_tuning.hostImport && deviceHasExtension(m_physical, VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
    std::vector<const char*> optional;
    if (m_hostImport) optional.push_back(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
    VkDevice device;
    RTHDIST_VK_CHECK(createDeviceFor(m_physical, req, optional, m_queueFamily, &device));
    m_device = UniqueDevice(device, {});
    m_deviceHandle = device;
    if (req.needs(DeviceFeature::kTraceRaysIndirect))
        m_rt.cmdTraceRaysIndirect = reinterpret_cast<PFN_vkCmdTraceRaysIndirectKHR>(
            vkGetDeviceProcAddr(device, "vkCmdTraceRaysIndirectKHR"));
    vkGetDeviceQueue(device, m_queueFamily, 0, &m_queue);
    loadLabelFunctions();
}

void Context::loadLabelFunctions() {
    if (!m_setObjectName) return;  // the instance has no VK_EXT_debug_utils
    m_cmdBeginLabel = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
        vkGetDeviceProcAddr(m_deviceHandle, "vkCmdBeginDebugUtilsLabelEXT"));
    m_cmdEndLabel = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
        vkGetDeviceProcAddr(m_deviceHandle, "vkCmdEndDebugUtilsLabelEXT"));
    if (!m_cmdBeginLabel || !m_cmdEndLabel) {  // labels come in pairs or not at all
        m_cmdBeginLabel = nullptr;
        m_cmdEndLabel = nullptr;
    }
}

Result<std::unique_ptr<Context>> Context::borrow(const VulkanDevice& handles, Backend backend,
                                                 bool validation, const Tuning& tuning) {
    if (!handles.instance || !handles.physicalDevice || !handles.device || !handles.queue)
        return Error{ErrorCode::kInvalidArgument,
                     "VulkanDevice: instance, physicalDevice, device and queue must all be set"};
    if (backend == Backend::kCpu)
        return Error{ErrorCode::kInvalidArgument, "the cpu backend takes no Vulkan device"};
    if (backend == Backend::kAuto)
        backend = unmetRequirements(handles.physicalDevice, backendRequirements(Backend::kRayQuery)).empty()
                      ? Backend::kRayQuery
                      : Backend::kRtPipeline;
    const DeviceRequirements req = backendRequirements(backend);
    std::unique_ptr<Context> ctx(new Context());
    ctx->m_tuning = tuning;
    try {
        if (std::optional<Error> err = ctx->adopt(handles, req, validation)) return *err;
        if (std::optional<Error> err = ctx->loadRtFunctions(req))
            return Error{err->code, err->message +
                                        " on the VkDevice given: was it created with vulkanDeviceSetup(pd, " +
                                        backendName(backend) + ")?"};
        ctx->readProperties(req);
        ctx->createCommandObjects();
    } catch (const VulkanError& e) {
        return Error{ErrorCode::kNoDevice, e.what()};
    }
    return ctx;
}

std::optional<Error> Context::adopt(const VulkanDevice& handles, const DeviceRequirements& req,
                                    bool validation) {
    const std::vector<std::string> unmet = unmetRequirements(handles.physicalDevice, req);
    if (!unmet.empty()) {
        std::string lacks;
        for (size_t m = 0; m < unmet.size(); ++m) lacks += (m ? "; " : "") + unmet[m];
        return Error{ErrorCode::kNoDevice, std::string("the VkPhysicalDevice given cannot run backend ") +
                                               backendName(req.backend) + ": lacks " + lacks};
    }
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(handles.physicalDevice, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(handles.physicalDevice, &n, families.data());
    if (handles.queueFamily >= n || !(families[handles.queueFamily].queueFlags & VK_QUEUE_COMPUTE_BIT) ||
        families[handles.queueFamily].timestampValidBits == 0)
        return Error{ErrorCode::kInvalidArgument, "VulkanDevice::queueFamily " +
                                                      std::to_string(handles.queueFamily) +
                                                      " is not a queue family with compute and timestamps"};
    m_instanceHandle = handles.instance;
    m_physical = handles.physicalDevice;
    m_deviceHandle = handles.device;
    m_queue = handles.queue;
    m_queueFamily = handles.queueFamily;
    m_backend = req.backend;
    m_borrowed = true;
    m_shaderFloat64 = handles.shaderFloat64;
    if (!handles.debugUtils) return std::nullopt;  // no names, labels or message count
    m_setObjectName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(m_instanceHandle, "vkSetDebugUtilsObjectNameEXT"));
    loadLabelFunctions();
    return validation ? createMessenger() : std::nullopt;
}

// Device-level entry points of the ray-tracing extensions `req` enables.
std::optional<Error> Context::loadRtFunctions(const DeviceRequirements& req) {
    const VkDevice d = m_deviceHandle;
    auto& rt = m_rt;
#define RTHDIST_LOAD(member, name) rt.member = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(d, #name))
    if (req.needs(DeviceFeature::kAccelerationStructure)) {
        RTHDIST_LOAD(getBuildSizes, vkGetAccelerationStructureBuildSizesKHR);
        RTHDIST_LOAD(createAccel, vkCreateAccelerationStructureKHR);
        RTHDIST_LOAD(destroyAccel, vkDestroyAccelerationStructureKHR);
        RTHDIST_LOAD(cmdBuildAccel, vkCmdBuildAccelerationStructuresKHR);
        RTHDIST_LOAD(getAccelAddress, vkGetAccelerationStructureDeviceAddressKHR);
        if (!rt.getBuildSizes || !rt.createAccel || !rt.destroyAccel || !rt.cmdBuildAccel ||
            !rt.getAccelAddress)
            return Error{ErrorCode::kNoDevice,
                         "the driver does not expose the acceleration-structure entry points"};
    }
    if (req.needs(DeviceFeature::kRayTracingPipeline)) {
        RTHDIST_LOAD(createRtPipelines, vkCreateRayTracingPipelinesKHR);
        RTHDIST_LOAD(getGroupHandles, vkGetRayTracingShaderGroupHandlesKHR);
        RTHDIST_LOAD(cmdTraceRays, vkCmdTraceRaysKHR);
        if (!rt.createRtPipelines || !rt.getGroupHandles || !rt.cmdTraceRays)
            return Error{ErrorCode::kNoDevice,
                         "the driver does not expose the ray-tracing pipeline entry points"};
    }
#undef RTHDIST_LOAD
    return std::nullopt;
}

void Context::readProperties(const DeviceRequirements& req) {
    VkPhysicalDeviceProperties2 p2 =
        vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    // Only structures of extensions the device has enabled go into the chain.
    m_rtProps.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR;
    m_asProps.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
    VkPhysicalDeviceExternalMemoryHostPropertiesEXT hostProps =
        vkStruct<VkPhysicalDeviceExternalMemoryHostPropertiesEXT>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT);
    const auto chain = [&](auto& s) {
        s.pNext = p2.pNext;
        p2.pNext = &s;
    };
    if (req.needs(DeviceFeature::kRayTracingPipeline)) chain(m_rtProps);
    if (req.needs(DeviceFeature::kAccelerationStructure)) chain(m_asProps);
    if (m_hostImport) chain(hostProps);
    vkGetPhysicalDeviceProperties2(m_physical, &p2);
    m_name = p2.properties.deviceName;
    m_timestampPeriod = p2.properties.limits.timestampPeriod;
    if (m_hostImport) {
        m_importAlignment = hostProps.minImportedHostPointerAlignment;
        m_getHostPointerProperties = reinterpret_cast<PFN_vkGetMemoryHostPointerPropertiesEXT>(
            vkGetDeviceProcAddr(m_deviceHandle, "vkGetMemoryHostPointerPropertiesEXT"));
        m_hostImport = m_getHostPointerProperties != nullptr && m_importAlignment > 0;
    }
    vkGetPhysicalDeviceMemoryProperties(m_physical, &m_memProps);
    m_limits = readDeviceLimits(m_physical);
    uint32_t qn = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(m_physical, &qn, nullptr);
    std::vector<VkQueueFamilyProperties> qf(qn);
    vkGetPhysicalDeviceQueueFamilyProperties(m_physical, &qn, qf.data());
    m_timestampBits = qf[m_queueFamily].timestampValidBits;
}

// The one command buffer, its fence and the timestamp queries.
void Context::createCommandObjects() {
    const VkDevice d = m_deviceHandle;
    VkCommandPoolCreateInfo pci =
        vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = m_queueFamily;
    m_pool = RTHDIST_VK_CREATE(UniqueCommandPool, vkCreateCommandPool, d, pci);
    VkCommandBufferAllocateInfo ai =
        vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    ai.commandPool = m_pool.get();
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    RTHDIST_VK_CHECK(vkAllocateCommandBuffers(d, &ai, &m_cmd));
    const VkFenceCreateInfo fci = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    m_fence = RTHDIST_VK_CREATE(UniqueFence, vkCreateFence, d, fci);
    VkQueryPoolCreateInfo qpi = vkStruct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    qpi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qpi.queryCount = kTimestampSlots;
    m_timestamps = RTHDIST_VK_CREATE(UniqueQueryPool, vkCreateQueryPool, d, qpi);
    m_traceSubmits = m_tuning.traceSubmits;
    // Not on a CPU device (lavapipe): the polling thread would take a core
    // from the device's own threads (2 cores: 39 -> 51 ms per call).
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(m_physical, &props);
    m_cpuDevice = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    m_spinMicros = m_cpuDevice ? 0 : 2000;
    if (m_tuning.fenceSpinMicros) m_spinMicros = *m_tuning.fenceSpinMicros;
}

Context::~Context() {
    // Nothing submitted may still run when the children go. Every submission
    // of a borrowed device has been waited for (submitAndWait): its other
    // queues are the embedder's, not ours to wait on.
    if (m_device) vkDeviceWaitIdle(m_deviceHandle);
}

void Context::setDebugName(VkObjectType type, uint64_t handle, const char* name) const {
    if (!m_setObjectName || !m_deviceHandle || !handle) return;
    VkDebugUtilsObjectNameInfoEXT info =
        vkStruct<VkDebugUtilsObjectNameInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT);
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name;
    m_setObjectName(m_deviceHandle, &info);
}

void Context::cmdBeginLabel(VkCommandBuffer cmd, const char* name) const {
    if (!m_cmdBeginLabel) return;
    VkDebugUtilsLabelEXT label = vkStruct<VkDebugUtilsLabelEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT);
    label.pLabelName = name;
    m_cmdBeginLabel(cmd, &label);
}

void Context::cmdEndLabel(VkCommandBuffer cmd) const {
    if (m_cmdEndLabel) m_cmdEndLabel(cmd);
}

uint32_t Context::memoryTypeIndex(uint32_t typeBits, VkMemoryPropertyFlags wanted) const {
    for (uint32_t i = 0; i < m_memProps.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (m_memProps.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    return ~0u;
}

VkCommandBuffer Context::begin() {
    RTHDIST_VK_CHECK(vkResetCommandBuffer(m_cmd, 0));
    VkCommandBufferBeginInfo bi =
        vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    RTHDIST_VK_CHECK(vkBeginCommandBuffer(m_cmd, &bi));
    vkCmdResetQueryPool(m_cmd, m_timestamps.get(), 0, kTimestampSlots);
    vkCmdWriteTimestamp(m_cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, m_timestamps.get(), 0);
    m_marks = 1;
    if (m_traceSubmits) m_begun = std::chrono::steady_clock::now();
    return m_cmd;
}

uint32_t Context::cmdMark(VkCommandBuffer cmd) {
    if (m_marks + 1 >= kTimestampSlots)
        throw std::logic_error("Context::cmdMark: too many marks in one submission");
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m_timestamps.get(), m_marks);
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
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m_timestamps.get(), last);
    RTHDIST_VK_CHECK(vkEndCommandBuffer(cmd));
    VkSubmitInfo si = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    const VkFence fence = m_fence.get();
    if (m_traceSubmits) m_submitted = std::chrono::steady_clock::now();
    RTHDIST_VK_CHECK(vkQueueSubmit(m_queue, 1, &si, fence));
    VkResult r = waitBriefly(fence);
    while (r == VK_NOT_READY || r == VK_TIMEOUT)
        r = vkWaitForFences(m_deviceHandle, 1, &fence, VK_TRUE, 10'000'000'000ull);
    RTHDIST_VK_CHECK(r);
    RTHDIST_VK_CHECK(vkResetFences(m_deviceHandle, 1, &fence));
    r = vkGetQueryPoolResults(m_deviceHandle, m_timestamps.get(), 0, last + 1, sizeof(m_stamps),
                              m_stamps.data(), sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    RTHDIST_VK_CHECK(r);
    m_lastGpuMs = gpuMsBetween(0, last);
    if (m_traceSubmits) traceSubmit(last);
}

VkResult Context::waitBriefly(VkFence fence) const {
    // A submission of this library's usually ends within a millisecond: the
    // host polls the fence that long before it sleeps in vkWaitForFences
    // (whose wake-up costs ~tens of microseconds per submission).
    VkResult r = vkGetFenceStatus(m_deviceHandle, fence);
    if (m_spinMicros == 0) return r;
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(m_spinMicros);
    while (r == VK_NOT_READY && std::chrono::steady_clock::now() < until)
        r = vkGetFenceStatus(m_deviceHandle, fence);
    return r;
}

void Context::traceSubmit(uint32_t last) {
    using Ms = std::chrono::duration<double, std::milli>;
    const auto now = std::chrono::steady_clock::now();
    std::string between;  // the device time between the submission's marks
    for (uint32_t m = 1; last > 1 && m <= last; ++m)
        between += (m == 1 ? ", between marks " : " ") + std::to_string(gpuMsBetween(m - 1, m));
    std::fprintf(
        stderr,
        "rthdist submit: host before %.3f ms, recording %.3f ms, submit+wait %.3f ms, device %.3f ms%s\n",
        Ms(m_begun - m_lastDone).count(), Ms(m_submitted - m_begun).count(), Ms(now - m_submitted).count(),
        m_lastGpuMs, between.c_str());
    m_lastDone = now;
}

}  // namespace rthdist::gpu
