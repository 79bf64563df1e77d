#include "gpu/process_instance.hpp"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "gpu/vk_check.hpp"
#include "gpu/vk_struct.hpp"

namespace rthdist::gpu {

namespace {

bool instanceHasExtension(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateInstanceExtensionProperties(nullptr, &n, exts.data());
    for (uint32_t i = 0; i < n; ++i)
        if (std::strcmp(exts[i].extensionName, name) == 0) return true;
    return false;
}

bool hasValidationLayer() {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> props(n);
    vkEnumerateInstanceLayerProperties(&n, props.data());
    for (uint32_t i = 0; i < n; ++i)
        if (std::strcmp(props[i].layerName, "VK_LAYER_KHRONOS_validation") == 0) return true;
    return false;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* count) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        ++*static_cast<std::atomic<uint64_t>*>(count);
        std::fprintf(stderr, "rthdist: validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

// The messenger that counts `instance`'s validation messages; it lives as
// long as the instance.
std::optional<Error> addMessenger(ProcessInstance& instance) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance.handle, "vkCreateDebugUtilsMessengerEXT"));
    if (!create)
        return Error{ErrorCode::kNoDevice, "validation requested but VK_EXT_debug_utils has no messenger"};
    const VkDebugUtilsMessengerCreateInfoEXT mi = validationMessengerInfo(&instance.messages);
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    const VkResult r = create(instance.handle, &mi, nullptr, &messenger);
    if (r != VK_SUCCESS)
        return Error{ErrorCode::kNoDevice,
                     std::string("validation messenger could not be created (") + vkResultName(r) + ")"};
    return std::nullopt;
}

// A new instance of the configuration; nothing is kept on failure.
Result<ProcessInstance*> makeInstance(bool validation, bool debugUtils) {
    VkApplicationInfo app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "rthdist";
    app.apiVersion = VK_API_VERSION_1_3;
    std::vector<const char*> layers, exts;
    if (validation) layers.push_back("VK_LAYER_KHRONOS_validation");
    if (debugUtils) exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    VkInstanceCreateInfo ci = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(exts.size());
    ci.ppEnabledExtensionNames = exts.data();
    VkInstance handle = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&ci, nullptr, &handle);
    if (r != VK_SUCCESS)
        return Error{ErrorCode::kNoDevice,
                     std::string("no Vulkan driver could be loaded (vkCreateInstance: ") + vkResultName(r) +
                         "); install a Vulkan ICD, e.g. Mesa lavapipe"};
    auto* made = new ProcessInstance;  // kept for the process (the header says why)
    made->handle = handle;
    made->debugUtils = debugUtils;
    made->validation = validation;
    if (validation) {
        if (std::optional<Error> err = addMessenger(*made)) {
            vkDestroyInstance(handle, nullptr);
            delete made;
            return *err;
        }
    }
    return made;
}

}  // namespace

VkDebugUtilsMessengerCreateInfoEXT validationMessengerInfo(std::atomic<uint64_t>* count) {
    VkDebugUtilsMessengerCreateInfoEXT mi =
        vkStruct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
    mi.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi.pfnUserCallback = onDebugMessage;
    mi.pUserData = count;
    return mi;
}

Result<ProcessInstance*> instanceFor(bool validation, bool debugLabels) {
    static std::mutex mutex;
    // [validation][debug utils], and the process that made them.
    static std::array<std::array<ProcessInstance*, 2>, 2> made{};
    static pid_t owner = 0;
    const std::lock_guard<std::mutex> lock(mutex);
    if (owner != getpid()) {  // first use, or a forked child: the parent's are not ours
        made = {};
        owner = getpid();
    }
    if (validation && !hasValidationLayer())
        return Error{ErrorCode::kNoDevice,
                     "validation requested but VK_LAYER_KHRONOS_validation is not installed "
                     "(Debian: vulkan-validationlayers)"};
    const bool debugUtils =
        validation || (debugLabels && instanceHasExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME));
    ProcessInstance*& slot = made[validation][debugUtils];
    if (slot == nullptr) {
        Result<ProcessInstance*> created = makeInstance(validation, debugUtils);
        if (!created) return created.error();
        slot = *created;
    }
    return slot;
}

}  // namespace rthdist::gpu
