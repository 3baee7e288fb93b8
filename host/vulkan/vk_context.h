// Headless Vulkan 1.2 setup: loader, instance, validation messages, choice
// of the physical device, logical device with one compute queue.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "lightcuts/render.h"
#include "vk_objects.h"

namespace lc::vk {

// Validation and loader messages of warning or error severity, collected by
// the debug messenger (called from any driver thread).
class MessageLog {
public:
    void add(std::string message);
    std::vector<std::string> messages() const;
    std::size_t count() const;
    // The messages so far, and an empty log.
    std::vector<std::string> take();

private:
    mutable std::mutex mutex_;
    std::vector<std::string> messages_;
};

// One physical device as the loader reports it.
struct PhysicalDeviceInfo {
    VkPhysicalDevice handle = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    std::uint32_t compute_family = UINT32_MAX;  // a queue family with compute
    std::string refusal;                        // why it cannot run the kernels ("" if it can)
};

// The format of the kernels' texel views (16-byte texels, bindings.glsl).
inline constexpr VkFormat kTexelFormat = VK_FORMAT_R32G32B32A32_UINT;

// Why a device whose limits are `limits` and whose kTexelFormat buffer
// features are `texel_features` cannot hold the kernels' descriptor set
// (bindings.glsl: kBindingCount storage buffers and kTexelBindingCount
// storage texel buffers, which count as storage images, in one set for
// the compute stage); "" if it can. Vulkan's minimum limits allow four of
// each.
std::string descriptor_refusal(const VkPhysicalDeviceLimits& limits, VkFormatFeatureFlags texel_features);

// Loads the loader once per process. Throws "no Vulkan device: ..." if
// libvulkan cannot be loaded.
void load_vulkan_loader();

class Context {
public:
    // Picks the device per options.gpu (see VulkanOptions) and creates it.
    // Throws std::runtime_error starting "no Vulkan device" when there is no
    // loader, no device, or none that fits; the message lists the devices
    // present and why each was refused.
    Context(const VulkanOptions& options, MessageLog* log);

    const Device& device() const { return device_; }
    const VolkDeviceTable& fn() const { return device_.fn(); }
    VkPhysicalDevice physical() const { return physical_.handle; }
    const VkPhysicalDeviceProperties& properties() const { return physical_.properties; }
    const VkPhysicalDeviceMemoryProperties& memory() const { return memory_; }
    VkDeviceSize max_allocation_size() const { return max_allocation_size_; }
    // Alignment of host memory the device can use in place
    // (VK_EXT_external_memory_host, enabled on CPU devices); 0: none.
    VkDeviceSize host_import_alignment() const { return host_import_alignment_; }
    VkQueue queue() const { return queue_; }
    // The pipelines' cache, kept as long as the context: a renderer that
    // keeps its context (lc::VulkanRenderer) gives the driver the
    // pipelines of its earlier renders to reuse, where the driver keeps
    // them (lavapipe in Mesa 22.3 does not).
    VkPipelineCache pipeline_cache() const { return pipeline_cache_.get(); }
    std::uint32_t queue_family() const { return physical_.compute_family; }
    // Nanoseconds per timestamp tick, and the valid bits (0: no timestamps).
    double timestamp_period() const { return physical_.properties.limits.timestampPeriod; }
    std::uint32_t timestamp_valid_bits() const { return timestamp_valid_bits_; }
    std::string device_name() const { return physical_.properties.deviceName; }

private:
    // Member order is destruction order, reversed: pipeline cache, device,
    // messenger, instance.
    Instance instance_;
    DebugMessenger messenger_;
    Device device_;
    PipelineCache pipeline_cache_;
    PhysicalDeviceInfo physical_;
    VkPhysicalDeviceMemoryProperties memory_{};
    VkDeviceSize max_allocation_size_ = 0;
    VkDeviceSize host_import_alignment_ = 0;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t timestamp_valid_bits_ = 0;
};

const char* device_type_name(VkPhysicalDeviceType type);

}  // namespace lc::vk
