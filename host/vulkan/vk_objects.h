// Move-only owners of the Vulkan objects the renderer creates. Renderer code
// never calls vkDestroy*/vkFree* itself: an object dies with its owner, and
// a struct's member order gives the destruction order (last member first).
//
// Not thread-safe: one thread owns a device and everything created from it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include <volk.h>

namespace lc::vk {

// A zeroed Vulkan struct with its sType set (a braced initialiser naming
// only sType trips -Wmissing-field-initializers).
template <typename T>
T vk_struct(VkStructureType type) {
    T s{};
    s.sType = type;
    return s;
}

// One owned handle plus what it takes to destroy it.
template <typename Handle, typename Deleter>
class UniqueHandle {
public:
    UniqueHandle() = default;
    UniqueHandle(Handle handle, Deleter deleter) : handle_(handle), deleter_(deleter) {}
    ~UniqueHandle() { reset(); }

    UniqueHandle(UniqueHandle&& other) noexcept
        : handle_(std::exchange(other.handle_, Handle{})), deleter_(other.deleter_) {}
    UniqueHandle& operator=(UniqueHandle&& other) noexcept {
        if (this != &other) {
            reset();
            handle_ = std::exchange(other.handle_, Handle{});
            deleter_ = other.deleter_;
        }
        return *this;
    }
    UniqueHandle(const UniqueHandle&) = delete;
    UniqueHandle& operator=(const UniqueHandle&) = delete;

    Handle get() const { return handle_; }
    explicit operator bool() const { return handle_ != Handle{}; }

    void reset() {
        if (handle_ != Handle{}) deleter_(handle_);
        handle_ = Handle{};
    }

private:
    Handle handle_{};
    Deleter deleter_{};
};

struct InstanceDeleter {
    void operator()(VkInstance instance) const { vkDestroyInstance(instance, nullptr); }
};

struct DebugMessengerDeleter {
    VkInstance instance = VK_NULL_HANDLE;
    void operator()(VkDebugUtilsMessengerEXT messenger) const {
        vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
    }
};

using Instance = UniqueHandle<VkInstance, InstanceDeleter>;
using DebugMessenger = UniqueHandle<VkDebugUtilsMessengerEXT, DebugMessengerDeleter>;

// The logical device and its function table (volk: device functions are
// called through the table, never through global pointers).
class Device {
public:
    Device() = default;
    // Takes ownership of `device`; loads its function table.
    Device(VkDevice device, bool debug_utils);
    ~Device() { reset(); }
    Device(Device&& other) noexcept;
    Device& operator=(Device&& other) noexcept;
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;

    VkDevice get() const { return device_; }
    const VolkDeviceTable& fn() const { return *table_; }

    // Debug name shown by validation messages and capture tools; a no-op
    // without VK_EXT_debug_utils.
    void set_name(VkObjectType type, std::uint64_t handle, const std::string& name) const;
    template <typename Handle>
    void set_name(Handle handle, const std::string& name) const;

private:
    void reset();

    VkDevice device_ = VK_NULL_HANDLE;
    std::unique_ptr<VolkDeviceTable> table_;  // stable address: deleters point to it
    bool debug_utils_ = false;
};

// Destroys a device-level object with the table entry `Destroy`
// (e.g. &VolkDeviceTable::vkDestroyPipeline).
template <typename Handle, auto Destroy>
struct DeviceDeleter {
    const VolkDeviceTable* table = nullptr;
    VkDevice device = VK_NULL_HANDLE;
    void operator()(Handle handle) const { (table->*Destroy)(device, handle, nullptr); }
};

template <typename Handle, auto Destroy>
using DeviceHandle = UniqueHandle<Handle, DeviceDeleter<Handle, Destroy>>;

using ShaderModule = DeviceHandle<VkShaderModule, &VolkDeviceTable::vkDestroyShaderModule>;
using PipelineLayout = DeviceHandle<VkPipelineLayout, &VolkDeviceTable::vkDestroyPipelineLayout>;
using Pipeline = DeviceHandle<VkPipeline, &VolkDeviceTable::vkDestroyPipeline>;
using PipelineCache = DeviceHandle<VkPipelineCache, &VolkDeviceTable::vkDestroyPipelineCache>;
using BufferView = DeviceHandle<VkBufferView, &VolkDeviceTable::vkDestroyBufferView>;
using DescriptorSetLayout =
    DeviceHandle<VkDescriptorSetLayout, &VolkDeviceTable::vkDestroyDescriptorSetLayout>;
using DescriptorPool = DeviceHandle<VkDescriptorPool, &VolkDeviceTable::vkDestroyDescriptorPool>;
using CommandPool = DeviceHandle<VkCommandPool, &VolkDeviceTable::vkDestroyCommandPool>;
using Fence = DeviceHandle<VkFence, &VolkDeviceTable::vkDestroyFence>;
using QueryPool = DeviceHandle<VkQueryPool, &VolkDeviceTable::vkDestroyQueryPool>;
using VkBufferHandle = DeviceHandle<VkBuffer, &VolkDeviceTable::vkDestroyBuffer>;
using DeviceMemory = DeviceHandle<VkDeviceMemory, &VolkDeviceTable::vkFreeMemory>;

// Creates `handle`'s owner for `device` and names the object.
template <typename Owner, typename Handle>
Owner own(const Device& device, Handle handle, const std::string& name) {
    device.set_name(handle, name);
    return Owner(handle, {&device.fn(), device.get()});
}

// Where a buffer's memory lives.
enum class MemoryUse {
    kDevice,     // device-local; also host-visible on unified-memory devices
    kUpload,     // host-visible, coherent: staging for uploads
    kReadback,   // host-visible, cached if possible: copies of results
};

// A buffer with its own memory allocation, persistently mapped when the
// memory is host-visible and coherent (mapped() == nullptr otherwise), or
// over host memory that the device uses in place (never mapped).
class Buffer {
public:
    Buffer() = default;
    Buffer(const Device& device, const VkPhysicalDeviceMemoryProperties& memory,
           VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, const std::string& name);
    // A buffer over `size` bytes of host memory at `host`, used in place
    // (VK_EXT_external_memory_host): `host` is aligned to `alignment`, and
    // the caller owns `host_bytes` (at least size rounded up to alignment)
    // there, which must outlive the buffer.
    Buffer(const Device& device, const VkPhysicalDeviceMemoryProperties& memory, const void* host,
           VkDeviceSize size, VkDeviceSize host_bytes, VkDeviceSize alignment, VkBufferUsageFlags usage,
           const std::string& name);

    VkBuffer get() const { return buffer_.get(); }
    VkDeviceSize size() const { return size_; }
    void* mapped() const { return mapped_; }
    const std::string& name() const { return name_; }

private:
    DeviceMemory memory_;   // freed after the buffer (declared first)
    VkBufferHandle buffer_;
    VkDeviceSize size_ = 0;
    void* mapped_ = nullptr;
    std::string name_;
};

// Object type of each handle kind this code names.
template <typename Handle>
constexpr VkObjectType object_type();
template <> constexpr VkObjectType object_type<VkQueue>() { return VK_OBJECT_TYPE_QUEUE; }
template <> constexpr VkObjectType object_type<VkCommandBuffer>() { return VK_OBJECT_TYPE_COMMAND_BUFFER; }
template <> constexpr VkObjectType object_type<VkBuffer>() { return VK_OBJECT_TYPE_BUFFER; }
template <> constexpr VkObjectType object_type<VkBufferView>() { return VK_OBJECT_TYPE_BUFFER_VIEW; }
template <> constexpr VkObjectType object_type<VkDeviceMemory>() { return VK_OBJECT_TYPE_DEVICE_MEMORY; }
template <> constexpr VkObjectType object_type<VkShaderModule>() { return VK_OBJECT_TYPE_SHADER_MODULE; }
template <> constexpr VkObjectType object_type<VkPipelineLayout>() { return VK_OBJECT_TYPE_PIPELINE_LAYOUT; }
template <> constexpr VkObjectType object_type<VkPipeline>() { return VK_OBJECT_TYPE_PIPELINE; }
template <> constexpr VkObjectType object_type<VkPipelineCache>() { return VK_OBJECT_TYPE_PIPELINE_CACHE; }
template <> constexpr VkObjectType object_type<VkDescriptorSetLayout>() { return VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT; }
template <> constexpr VkObjectType object_type<VkDescriptorPool>() { return VK_OBJECT_TYPE_DESCRIPTOR_POOL; }
template <> constexpr VkObjectType object_type<VkDescriptorSet>() { return VK_OBJECT_TYPE_DESCRIPTOR_SET; }
template <> constexpr VkObjectType object_type<VkCommandPool>() { return VK_OBJECT_TYPE_COMMAND_POOL; }
template <> constexpr VkObjectType object_type<VkFence>() { return VK_OBJECT_TYPE_FENCE; }
template <> constexpr VkObjectType object_type<VkQueryPool>() { return VK_OBJECT_TYPE_QUERY_POOL; }
template <> constexpr VkObjectType object_type<VkDevice>() { return VK_OBJECT_TYPE_DEVICE; }

template <typename Handle>
void Device::set_name(Handle handle, const std::string& name) const {
    set_name(object_type<Handle>(), reinterpret_cast<std::uint64_t>(handle), name);
}

}  // namespace lc::vk
