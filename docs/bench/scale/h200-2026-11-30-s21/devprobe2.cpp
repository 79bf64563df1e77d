// Which part of rthdist's device set makes the first vkCreateDevice of a
// process slow: argv[1] picks the first device's set (bare; v12: the
// Vulkan 1.2/1.3 features alone; accel: + acceleration structures; full:
// + the ray-tracing pipeline), then the full set is created once more.
#include <rthdist/vulkan_interop.hpp>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>
using Clock = std::chrono::steady_clock;
static double ms(Clock::time_point a) { return std::chrono::duration<double, std::milli>(Clock::now() - a).count(); }
int main(int argc, char** argv) {
    const char* first = argc > 1 ? argv[1] : "bare";
    auto t0 = Clock::now();
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    VkInstance inst;
    if (vkCreateInstance(&ici, nullptr, &inst) != VK_SUCCESS) return 1;
    const double instMs = ms(t0);
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(inst, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(inst, &n, pds.data());
    VkPhysicalDevice pd = pds[0];
    const float prio = 1.0f;
    auto make = [&](const char* what) {
        auto setup = rthdist::vulkanDeviceSetup(pd, rthdist::Backend::kRtPipeline);
        VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        q.queueFamilyIndex = setup->queueFamily;
        q.queueCount = 1;
        q.pQueuePriorities = &prio;
        VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &q;
        std::vector<const char*> ext;
        if (!std::strcmp(what, "v12")) {
            setup->features2.pNext = &setup->vulkan12;
            setup->vulkan12.pNext = &setup->vulkan13;
            setup->vulkan13.pNext = nullptr;
            dci.pNext = &setup->features2;
        } else if (!std::strcmp(what, "accel")) {
            setup->features2.pNext = &setup->vulkan12;
            setup->vulkan12.pNext = &setup->vulkan13;
            setup->vulkan13.pNext = &setup->accel;
            setup->accel.pNext = nullptr;
            dci.pNext = &setup->features2;
            for (const char* e : setup->extensions)
                if (std::strcmp(e, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME)) ext.push_back(e);
        } else if (!std::strcmp(what, "full")) {
            dci.pNext = setup->chain();
            ext = setup->extensions;
        }
        dci.enabledExtensionCount = uint32_t(ext.size());
        dci.ppEnabledExtensionNames = ext.data();
        VkDevice d;
        auto t = Clock::now();
        VkResult res = vkCreateDevice(pd, &dci, nullptr, &d);
        const double c = ms(t);
        if (res == VK_SUCCESS) vkDestroyDevice(d, nullptr);
        return std::make_pair(c, int(res));
    };
    auto a = make(first);
    auto b = make("full");
    std::printf("instance %.1f ms; first device (%s) %.1f ms rc %d; then full %.1f ms rc %d\n", instMs, first, a.first, a.second, b.first, b.second);
    vkDestroyInstance(inst, nullptr);
}
