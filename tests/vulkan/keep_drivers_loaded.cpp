// Linked into every test executable that renders through Vulkan.
#include <gtest/gtest.h>
#include <volk.h>

namespace {

// Sanitizer builds: LeakSanitizer checks for leaks at exit, and a library
// unloaded by then leaves frames in unknown modules that no suppression can
// name. The renderer keeps the drivers and layers an instance loaded
// (host/vulkan/vk_context.cpp), but only those of an instance it made; one
// instance created at start and kept (reachable from a global, so not
// itself a leak) loads them first, before any test, so that
// tests/vulkan/lsan.supp can name the driver's modules whatever runs.
#ifdef __SANITIZE_ADDRESS__
struct KeepVulkanDriversLoaded : ::testing::Environment {
    void SetUp() override {
        if (volkInitialize() != VK_SUCCESS) return;
        const char* layer = "VK_LAYER_KHRONOS_validation";
        VkInstanceCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &layer;
        if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) instance = VK_NULL_HANDLE;
    }
    static inline VkInstance instance = VK_NULL_HANDLE;
};
const auto* const keep_vulkan_drivers_loaded =
    ::testing::AddGlobalTestEnvironment(new KeepVulkanDriversLoaded);
#endif

}  // namespace
