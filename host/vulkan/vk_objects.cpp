#include "vk_objects.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "vk_check.h"

namespace lc::vk {

Device::Device(VkDevice device, bool debug_utils)
    : device_(device), table_(std::make_unique<VolkDeviceTable>()), debug_utils_(debug_utils) {
    volkLoadDeviceTable(table_.get(), device_);
}

Device::Device(Device&& other) noexcept
    : device_(std::exchange(other.device_, VK_NULL_HANDLE)),
      table_(std::move(other.table_)),
      debug_utils_(other.debug_utils_) {}

Device& Device::operator=(Device&& other) noexcept {
    if (this != &other) {
        reset();
        device_ = std::exchange(other.device_, VK_NULL_HANDLE);
        table_ = std::move(other.table_);
        debug_utils_ = other.debug_utils_;
    }
    return *this;
}

void Device::reset() {
    if (device_ != VK_NULL_HANDLE) table_->vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
}

void Device::set_name(VkObjectType type, std::uint64_t handle, const std::string& name) const {
    if (!debug_utils_ || vkSetDebugUtilsObjectNameEXT == nullptr) return;
    auto info = vk_struct<VkDebugUtilsObjectNameInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT);
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name.c_str();
    VK_CHECK(vkSetDebugUtilsObjectNameEXT(device_, &info));
}

namespace {

// First memory type allowed by `type_bits` with all `required` flags,
// preferring one that also has all `preferred` flags.
std::uint32_t find_memory_type(const VkPhysicalDeviceMemoryProperties& memory,
                               std::uint32_t type_bits, VkMemoryPropertyFlags required,
                               VkMemoryPropertyFlags preferred) {
    std::uint32_t fallback = UINT32_MAX;
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
        if ((type_bits & (1u << i)) == 0) continue;
        VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (fallback == UINT32_MAX) fallback = i;
    }
    return fallback;
}

// A buffer of `size` bytes (`next`: the create info's chain), and what
// memory it needs.
VkBufferHandle create_buffer(const Device& device, VkDeviceSize size, VkBufferUsageFlags usage, const void* next,
                             const std::string& name, VkMemoryRequirements& requirements) {
    auto buffer_info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    buffer_info.pNext = next;
    buffer_info.size = size;
    buffer_info.usage = usage;
    buffer_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    VK_CHECK(device.fn().vkCreateBuffer(device.get(), &buffer_info, nullptr, &buffer));
    VkBufferHandle handle = own<VkBufferHandle>(device, buffer, name);
    device.fn().vkGetBufferMemoryRequirements(device.get(), buffer, &requirements);
    return handle;
}

// vkAllocateMemory, where running out of memory says which buffer and how
// large, and what would need less (VK_CHECK's message named only the call).
VkDeviceMemory allocate_memory(const Device& device, const VkMemoryAllocateInfo& info, const std::string& name) {
    VkDeviceMemory allocation = VK_NULL_HANDLE;
    const VkResult result = device.fn().vkAllocateMemory(device.get(), &info, nullptr, &allocation);
    if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY) {
        char size[32];
        std::snprintf(size, sizeof size, "%.1f MiB", double(info.allocationSize) / double(1 << 20));
        throw std::runtime_error(
            std::string("the Vulkan device ran out of ") +
            (result == VK_ERROR_OUT_OF_DEVICE_MEMORY ? "device" : "host") + " memory for buffer '" + name + "' (" +
            size + "); the image's size, the lights and area-light samples, --cut-heap and the tiles' size "
            "(LC_VK_MAX_TILE_PIXELS) set what the buffers take, and --device cpu renders without them");
    }
    VK_CHECK(result);
    return allocation;
}

}  // namespace

Buffer::Buffer(const Device& device, const VkPhysicalDeviceMemoryProperties& memory,
               VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, const std::string& name)
    : size_(size), name_(name) {
    const VolkDeviceTable& vkd = device.fn();
    VkMemoryRequirements requirements;
    buffer_ = create_buffer(device, size, usage, nullptr, name, requirements);
    const VkBuffer buffer = buffer_.get();
    VkMemoryPropertyFlags required = 0, preferred = 0;
    switch (use) {
        case MemoryUse::kDevice:
            preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
            break;
        case MemoryUse::kUpload:
            required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            break;
        case MemoryUse::kReadback:
            required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
            break;
    }
    std::uint32_t type = find_memory_type(memory, requirements.memoryTypeBits, required, preferred);
    if (type == UINT32_MAX)
        throw std::runtime_error("no Vulkan memory type fits buffer '" + name + "'");

    auto alloc_info = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc_info.allocationSize = requirements.size;
    alloc_info.memoryTypeIndex = type;
    // A buffer read through its device address needs memory allocated for it.
    auto flags_info = vk_struct<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
    flags_info.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    if ((usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0) alloc_info.pNext = &flags_info;
    const VkDeviceMemory allocation = allocate_memory(device, alloc_info, name);
    memory_ = own<DeviceMemory>(device, allocation, name + " memory");
    VK_CHECK(vkd.vkBindBufferMemory(device.get(), buffer, allocation, 0));

    constexpr VkMemoryPropertyFlags kMappable =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    if ((memory.memoryTypes[type].propertyFlags & kMappable) == kMappable)
        VK_CHECK(vkd.vkMapMemory(device.get(), allocation, 0, VK_WHOLE_SIZE, 0, &mapped_));
}

Buffer::Buffer(const Device& device, const VkPhysicalDeviceMemoryProperties& memory, const void* host,
               VkDeviceSize size, VkDeviceSize host_bytes, VkDeviceSize alignment, VkBufferUsageFlags usage,
               const std::string& name)
    : size_(size), name_(name) {
    const VolkDeviceTable& vkd = device.fn();
    constexpr auto kHandle = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    auto external = vk_struct<VkExternalMemoryBufferCreateInfo>(VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO);
    external.handleTypes = kHandle;
    VkMemoryRequirements requirements;
    buffer_ = create_buffer(device, size, usage, &external, name, requirements);
    const VkBuffer buffer = buffer_.get();
    auto host_properties =
        vk_struct<VkMemoryHostPointerPropertiesEXT>(VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT);
    VK_CHECK(vkd.vkGetMemoryHostPointerPropertiesEXT(device.get(), kHandle, host, &host_properties));
    const std::uint32_t type =
        find_memory_type(memory, requirements.memoryTypeBits & host_properties.memoryTypeBits, 0, 0);
    const VkDeviceSize bytes = (std::max(size, requirements.size) + alignment - 1) / alignment * alignment;
    if (type == UINT32_MAX || bytes > host_bytes)
        throw std::runtime_error("host memory of '" + name + "' cannot back a Vulkan buffer");

    auto import = vk_struct<VkImportMemoryHostPointerInfoEXT>(VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT);
    import.handleType = kHandle;
    import.pHostPointer = const_cast<void*>(host);  // read only: the kernels never write scene arrays
    auto flags_info = vk_struct<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
    flags_info.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    if ((usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0) import.pNext = &flags_info;
    auto alloc_info = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc_info.pNext = &import;
    alloc_info.allocationSize = bytes;
    alloc_info.memoryTypeIndex = type;
    const VkDeviceMemory allocation = allocate_memory(device, alloc_info, name);
    memory_ = own<DeviceMemory>(device, allocation, name + " memory");
    VK_CHECK(vkd.vkBindBufferMemory(device.get(), buffer, allocation, 0));
}

}  // namespace lc::vk
