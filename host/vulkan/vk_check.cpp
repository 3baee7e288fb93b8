#include "vk_check.h"

namespace lc::vk {

const char* result_name(VkResult result) {
    switch (result) {
#define LC_RESULT_NAME(r) \
    case r:               \
        return #r
        LC_RESULT_NAME(VK_SUCCESS);
        LC_RESULT_NAME(VK_NOT_READY);
        LC_RESULT_NAME(VK_TIMEOUT);
        LC_RESULT_NAME(VK_EVENT_SET);
        LC_RESULT_NAME(VK_EVENT_RESET);
        LC_RESULT_NAME(VK_INCOMPLETE);
        LC_RESULT_NAME(VK_ERROR_OUT_OF_HOST_MEMORY);
        LC_RESULT_NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY);
        LC_RESULT_NAME(VK_ERROR_INITIALIZATION_FAILED);
        LC_RESULT_NAME(VK_ERROR_DEVICE_LOST);
        LC_RESULT_NAME(VK_ERROR_MEMORY_MAP_FAILED);
        LC_RESULT_NAME(VK_ERROR_LAYER_NOT_PRESENT);
        LC_RESULT_NAME(VK_ERROR_EXTENSION_NOT_PRESENT);
        LC_RESULT_NAME(VK_ERROR_FEATURE_NOT_PRESENT);
        LC_RESULT_NAME(VK_ERROR_INCOMPATIBLE_DRIVER);
        LC_RESULT_NAME(VK_ERROR_TOO_MANY_OBJECTS);
        LC_RESULT_NAME(VK_ERROR_FORMAT_NOT_SUPPORTED);
        LC_RESULT_NAME(VK_ERROR_FRAGMENTED_POOL);
        LC_RESULT_NAME(VK_ERROR_UNKNOWN);
        LC_RESULT_NAME(VK_ERROR_OUT_OF_POOL_MEMORY);
        LC_RESULT_NAME(VK_ERROR_INVALID_EXTERNAL_HANDLE);
        LC_RESULT_NAME(VK_ERROR_FRAGMENTATION);
        LC_RESULT_NAME(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS);
        LC_RESULT_NAME(VK_PIPELINE_COMPILE_REQUIRED);
        LC_RESULT_NAME(VK_ERROR_SURFACE_LOST_KHR);
        LC_RESULT_NAME(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR);
        LC_RESULT_NAME(VK_SUBOPTIMAL_KHR);
        LC_RESULT_NAME(VK_ERROR_OUT_OF_DATE_KHR);
        LC_RESULT_NAME(VK_ERROR_VALIDATION_FAILED_EXT);
#undef LC_RESULT_NAME
        default:
            return nullptr;
    }
}

namespace {

std::string describe(const char* expression, const char* file, int line, VkResult result) {
    const char* name = result_name(result);
    return std::string(expression) + " failed at " + file + ":" + std::to_string(line) + ": " +
           (name ? name : "VkResult " + std::to_string(static_cast<int>(result)));
}

}  // namespace

VulkanError::VulkanError(const char* expression, const char* file, int line, VkResult result)
    : std::runtime_error(describe(expression, file, line, result)), result_(result) {}

}  // namespace lc::vk
