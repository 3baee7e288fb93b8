// VK_CHECK: every Vulkan call whose VkResult matters goes through it.
#pragma once

#include <stdexcept>
#include <string>

#include <volk.h>

namespace lc::vk {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.; nullptr for codes it does not know.
const char* result_name(VkResult result);

// Thrown for a failed Vulkan call; what() names the call, file, line and result.
class VulkanError : public std::runtime_error {
public:
    VulkanError(const char* expression, const char* file, int line, VkResult result);
    VkResult result() const { return result_; }

private:
    VkResult result_;
};

}  // namespace lc::vk

// Throws lc::vk::VulkanError unless the call returned VK_SUCCESS. Active in
// every build type: a failed call is never silently ignored.
#define VK_CHECK(expr)                                                           \
    do {                                                                         \
        const VkResult lc_vk_check_result_ = (expr);                             \
        if (lc_vk_check_result_ != VK_SUCCESS)                                   \
            throw ::lc::vk::VulkanError(#expr, __FILE__, __LINE__, lc_vk_check_result_); \
    } while (false)
