#include "vk_context.h"

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "bindings.glsl"
#include "vk_check.h"
#include "vulkan_renderer.h"

namespace lc::vk {

namespace {

std::atomic<std::uint64_t> g_message_total{0};

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_debug_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT /*types*/,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    std::string text = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error: "
                                                                                 : "warning: ";
    if (data->pMessageIdName) text += std::string(data->pMessageIdName) + ": ";
    text += data->pMessage ? data->pMessage : "(no text)";
    static_cast<MessageLog*>(user)->add(std::move(text));
    g_message_total.fetch_add(1, std::memory_order_relaxed);
    return VK_FALSE;  // never abort the call that triggered it
}

VkDebugUtilsMessengerCreateInfoEXT messenger_info(MessageLog* log) {
    auto info = vk_struct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = on_debug_message;
    info.pUserData = log;
    return info;
}

bool has_layer(const char* name) {
    std::uint32_t count = 0;
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
    std::vector<VkLayerProperties> layers(count);
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool has_instance_extension(const char* name, const char* layer = nullptr) {
    std::uint32_t count = 0;
    VK_CHECK(vkEnumerateInstanceExtensionProperties(layer, &count, nullptr));
    std::vector<VkExtensionProperties> extensions(count);
    VK_CHECK(vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data()));
    return std::any_of(extensions.begin(), extensions.end(), [&](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
    });
}

// The shared libraries the process has open, by the names the dynamic
// linker knows them by (a path, relative where a relative search path
// found it; the program and the vDSO have none).
std::vector<std::string> loaded_libraries() {
    std::vector<std::string> names;
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* out) {
            if (info->dlpi_name != nullptr && std::strchr(info->dlpi_name, '/') != nullptr)
                static_cast<std::vector<std::string>*>(out)->push_back(info->dlpi_name);
            return 0;
        },
        &names);
    return names;
}

// The libraries opened since `before` (for an instance: its drivers and
// layers), marked never to unload. The NVIDIA driver keeps its thread-local
// variables in glibc's static TLS block, and an unloaded library's share of
// that block is given back only when it sits at the block's end: on an H200
// (driver 580), a process that made and destroyed instances one after
// another (the GPU tests; an application rendering frame after frame) could
// not load the driver after about a dozen instances ("libnvidia-tls.so:
// cannot allocate memory in static TLS block"). Kept loaded, the driver
// takes its share once. dlopen is not called from dl_iterate_phdr's
// callback, which runs under the dynamic linker's lock.
void keep_loaded_since(const std::vector<std::string>& before) {
    for (const std::string& name : loaded_libraries())
        if (std::find(before.begin(), before.end(), name) == before.end())
            if (void* handle = dlopen(name.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE)) dlclose(handle);
}

// The instance, with validation and the messenger's create-info chained so
// that messages from vkCreateInstance/vkDestroyInstance are caught too.
Instance create_instance(bool validation, MessageLog* log, bool& debug_utils) {
    load_vulkan_loader();
    auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "lightcuts";
    app.pEngineName = "lightcuts";
    app.apiVersion = VK_API_VERSION_1_2;

    std::vector<const char*> extensions;
    std::vector<const char*> layers;
    auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    debug_utils = has_instance_extension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (debug_utils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    // Lets the loader report devices that are not fully conformant (MoltenVK).
    if (has_instance_extension(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME)) {
        extensions.push_back(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
        info.flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
    }

    VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info(log);
    VkValidationFeatureEnableEXT enables[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    auto features = vk_struct<VkValidationFeaturesEXT>(VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT);
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    if (validation) {
        if (!has_layer(kValidationLayer))
            throw std::runtime_error(std::string("Vulkan validation requested but ") +
                                     kValidationLayer + " is not installed");
        if (!debug_utils)
            throw std::runtime_error("Vulkan validation requested but " +
                                     std::string(VK_EXT_DEBUG_UTILS_EXTENSION_NAME) +
                                     " is missing, so its messages cannot be collected");
        layers.push_back(kValidationLayer);
        info.pNext = &messenger;
        if (has_instance_extension(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME, kValidationLayer)) {
            extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
            messenger.pNext = &features;
        }
    }
    info.pApplicationInfo = &app;
    info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();

    const std::vector<std::string> before = loaded_libraries();
    VkInstance instance = VK_NULL_HANDLE;
    VkResult result = vkCreateInstance(&info, nullptr, &instance);
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
        throw NoVulkanDevice(
            "no Vulkan device: the Vulkan loader found no driver (vkCreateInstance returned "
            "VK_ERROR_INCOMPATIBLE_DRIVER)");
    VK_CHECK(result);
    volkLoadInstanceOnly(instance);
    keep_loaded_since(before);
    return Instance(instance, {});
}

// Vulkan 1.2's bufferDeviceAddress: the kernels read the chunks of a scene
// array split over several buffers through their addresses.
bool has_buffer_device_address(VkPhysicalDevice handle) {
    auto v12 = vk_struct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    auto features = vk_struct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
    features.pNext = &v12;
    vkGetPhysicalDeviceFeatures2(handle, &features);
    return v12.bufferDeviceAddress == VK_TRUE;
}

std::vector<PhysicalDeviceInfo> physical_devices(VkInstance instance) {
    std::uint32_t count = 0;
    VkResult first = vkEnumeratePhysicalDevices(instance, &count, nullptr);
    // The loader's answer where drivers are installed but none of them
    // finds its device (Intel's or AMD's on a machine without that GPU).
    if (first == VK_ERROR_INITIALIZATION_FAILED)
        throw NoVulkanDevice(
            "no Vulkan device: no installed Vulkan driver found a device (vkEnumeratePhysicalDevices returned "
            "VK_ERROR_INITIALIZATION_FAILED)");
    VK_CHECK(first);
    std::vector<VkPhysicalDevice> handles(count);
    VkResult result = vkEnumeratePhysicalDevices(instance, &count, handles.data());
    if (result != VK_INCOMPLETE) VK_CHECK(result);
    handles.resize(count);

    std::vector<PhysicalDeviceInfo> devices;
    for (VkPhysicalDevice handle : handles) {
        PhysicalDeviceInfo d;
        d.handle = handle;
        vkGetPhysicalDeviceProperties(handle, &d.properties);
        std::uint32_t family_count = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(handle, &family_count, nullptr);
        std::vector<VkQueueFamilyProperties> families(family_count);
        vkGetPhysicalDeviceQueueFamilyProperties(handle, &family_count, families.data());
        // Prefer a compute family with timestamps, so stage timings exist.
        for (std::uint32_t f = 0; f < family_count; ++f) {
            if ((families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) continue;
            if (d.compute_family == UINT32_MAX ||
                (families[d.compute_family].timestampValidBits == 0 &&
                 families[f].timestampValidBits > 0))
                d.compute_family = f;
        }
        std::uint32_t api = d.properties.apiVersion;
        if (VK_API_VERSION_MAJOR(api) == 1 && VK_API_VERSION_MINOR(api) < 2)
            d.refusal = "supports Vulkan 1." + std::to_string(VK_API_VERSION_MINOR(api)) +
                        ", needs 1.2";
        else if (d.compute_family == UINT32_MAX)
            d.refusal = "has no compute queue";
        else if (!has_buffer_device_address(handle))
            d.refusal = "has no bufferDeviceAddress (a Vulkan 1.2 feature, needed for scene arrays "
                        "larger than one buffer)";
        if (d.refusal.empty()) {
            VkFormatProperties texel{};
            vkGetPhysicalDeviceFormatProperties(handle, kTexelFormat, &texel);
            d.refusal = descriptor_refusal(d.properties.limits, texel.bufferFeatures);
        }
        devices.push_back(std::move(d));
    }
    return devices;
}

// Lower is preferred: discrete, integrated, virtual, CPU, other.
int type_rank(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
        default: return 4;
    }
}

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

bool is_index(const std::string& s) {
    return !s.empty() && s.size() < 9 &&
           std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Applies the user's choice (index or name substring) on top of the
// capability refusals, then takes the best-ranked device left.
PhysicalDeviceInfo choose_device(std::vector<PhysicalDeviceInfo> devices, const std::string& gpu) {
    if (devices.empty())
        throw NoVulkanDevice(
            "no Vulkan device: the Vulkan loader reports no physical device (is a Vulkan driver "
            "installed? VK_DRIVER_FILES / VK_ICD_FILENAMES select driver manifests)");
    const bool by_index = is_index(gpu);
    const std::string wanted = lower(gpu);
    int best = -1;
    for (std::size_t i = 0; i < devices.size(); ++i) {
        PhysicalDeviceInfo& d = devices[i];
        if (d.refusal.empty() && by_index && std::stoul(gpu) != i)
            d.refusal = "is not device " + gpu;
        else if (d.refusal.empty() && !by_index && !gpu.empty() &&
                 lower(d.properties.deviceName).find(wanted) == std::string::npos)
            d.refusal = "name does not contain '" + gpu + "'";
        if (!d.refusal.empty()) continue;
        if (best < 0 || type_rank(d.properties.deviceType) <
                            type_rank(devices[static_cast<std::size_t>(best)].properties.deviceType))
            best = static_cast<int>(i);
    }
    if (best >= 0) return devices[static_cast<std::size_t>(best)];

    std::string message = gpu.empty() ? "no Vulkan device: none of the devices present is usable:"
                                      : "no Vulkan device matches '" + gpu + "':";
    for (std::size_t i = 0; i < devices.size(); ++i) {
        const VkPhysicalDeviceProperties& p = devices[i].properties;
        message += "\n  " + std::to_string(i) + ": " + p.deviceName + " (" +
                   device_type_name(p.deviceType) + ", Vulkan " +
                   std::to_string(VK_API_VERSION_MAJOR(p.apiVersion)) + "." +
                   std::to_string(VK_API_VERSION_MINOR(p.apiVersion)) + "): " + devices[i].refusal;
    }
    // Nothing usable at all is "no device"; a --gpu that matches nothing is
    // the user's mistake and must not silently fall back to the CPU.
    if (gpu.empty()) throw NoVulkanDevice(message);
    throw std::runtime_error(message);
}

}  // namespace

std::string descriptor_refusal(const VkPhysicalDeviceLimits& limits, VkFormatFeatureFlags texel_features) {
    const auto lacks = [](std::uint32_t offered, std::uint32_t needed, const char* what) {
        return "allows " + std::to_string(offered) + " " + what + ", the kernels bind " + std::to_string(needed);
    };
    const std::uint32_t buffers = gpu::kBindingCount, images = gpu::kTexelBindingCount;
    if (limits.maxPerStageDescriptorStorageBuffers < buffers)
        return lacks(limits.maxPerStageDescriptorStorageBuffers, buffers, "storage buffers per shader stage");
    if (limits.maxDescriptorSetStorageBuffers < buffers)
        return lacks(limits.maxDescriptorSetStorageBuffers, buffers, "storage buffers per descriptor set");
    if (limits.maxPerStageDescriptorStorageImages < images)
        return lacks(limits.maxPerStageDescriptorStorageImages, images,
                     "storage images (storage texel buffers among them) per shader stage");
    if (limits.maxDescriptorSetStorageImages < images)
        return lacks(limits.maxDescriptorSetStorageImages, images,
                     "storage images (storage texel buffers among them) per descriptor set");
    if (limits.maxPerStageResources < buffers + images)
        return lacks(limits.maxPerStageResources, buffers + images, "resources per shader stage");
    if ((texel_features & VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_BIT) == 0)
        return "has no storage texel buffers of format R32G32B32A32_UINT";
    return "";
}

void MessageLog::add(std::string message) {
    std::lock_guard lock(mutex_);
    messages_.push_back(std::move(message));
}

std::vector<std::string> MessageLog::messages() const {
    std::lock_guard lock(mutex_);
    return messages_;
}

std::size_t MessageLog::count() const {
    std::lock_guard lock(mutex_);
    return messages_.size();
}

std::vector<std::string> MessageLog::take() {
    std::lock_guard lock(mutex_);
    std::vector<std::string> taken;
    taken.swap(messages_);
    return taken;
}

std::uint64_t validation_message_total() { return g_message_total.load(); }

void load_vulkan_loader() {
    // volk keeps the loader's entry points in globals; load them once.
    static const VkResult result = volkInitialize();
    if (result != VK_SUCCESS)
        throw NoVulkanDevice(
            "no Vulkan device: the Vulkan loader (libvulkan.so.1) could not be loaded");
}

const char* device_type_name(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
        default: return "other";
    }
}

Context::Context(const VulkanOptions& options, MessageLog* log) {
    bool debug_utils = false;
    instance_ = create_instance(options.validation, log, debug_utils);
    if (options.validation) {
        VkDebugUtilsMessengerCreateInfoEXT info = messenger_info(log);
        VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
        VK_CHECK(vkCreateDebugUtilsMessengerEXT(instance_.get(), &info, nullptr, &messenger));
        messenger_ = DebugMessenger(messenger, {instance_.get()});
    }

    physical_ = choose_device(physical_devices(instance_.get()), options.gpu);

    // A CPU device (lavapipe) reads host memory as fast as its own: where
    // it can import it, the large scene arrays need no copy.
    std::uint32_t extension_count = 0;
    VK_CHECK(vkEnumerateDeviceExtensionProperties(physical_.handle, nullptr, &extension_count, nullptr));
    std::vector<VkExtensionProperties> extensions(extension_count);
    VK_CHECK(vkEnumerateDeviceExtensionProperties(physical_.handle, nullptr, &extension_count, extensions.data()));
    const bool host_import =
        physical_.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU &&
        std::any_of(extensions.begin(), extensions.end(), [](const VkExtensionProperties& e) {
            return std::strcmp(e.extensionName, VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME) == 0;
        });

    auto maintenance3 = vk_struct<VkPhysicalDeviceMaintenance3Properties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES);
    auto host_memory = vk_struct<VkPhysicalDeviceExternalMemoryHostPropertiesEXT>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT);
    if (host_import) maintenance3.pNext = &host_memory;
    auto properties2 =
        vk_struct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    properties2.pNext = &maintenance3;
    vkGetPhysicalDeviceProperties2(physical_.handle, &properties2);
    max_allocation_size_ = maintenance3.maxMemoryAllocationSize;
    if (host_import) host_import_alignment_ = host_memory.minImportedHostPointerAlignment;
    vkGetPhysicalDeviceMemoryProperties(physical_.handle, &memory_);

    std::uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_.handle, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_.handle, &family_count, families.data());
    timestamp_valid_bits_ = families[physical_.compute_family].timestampValidBits;

    // One compute queue, one feature, Vulkan 1.2's bufferDeviceAddress
    // (scene arrays split into chunks), and on CPU devices that have it
    // VK_EXT_external_memory_host.
    const float priority = 1.0f;
    auto queue_info = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue_info.queueFamilyIndex = physical_.compute_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    auto device_info = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    auto v12 = vk_struct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    v12.bufferDeviceAddress = VK_TRUE;
    device_info.pNext = &v12;
    const char* host_memory_extension = VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME;
    if (host_import) {
        device_info.enabledExtensionCount = 1;
        device_info.ppEnabledExtensionNames = &host_memory_extension;
    }
    VkDevice device = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDevice(physical_.handle, &device_info, nullptr, &device));
    device_ = Device(device, debug_utils);
    device_.set_name(device, std::string("lightcuts device: ") + physical_.properties.deviceName);

    device_.fn().vkGetDeviceQueue(device, physical_.compute_family, 0, &queue_);
    device_.set_name(queue_, "compute queue");

    auto cache_info = vk_struct<VkPipelineCacheCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO);
    VkPipelineCache cache = VK_NULL_HANDLE;
    VK_CHECK(device_.fn().vkCreatePipelineCache(device, &cache_info, nullptr, &cache));
    pipeline_cache_ = own<PipelineCache>(device_, cache, "pipeline cache");
}

}  // namespace lc::vk

namespace lc {

namespace {

// The devices the loader reports, with why each is refused (handles are
// not valid after return: the instance is gone). Empty without a loader or
// a driver.
std::vector<vk::PhysicalDeviceInfo> present_devices() {
    try {
        vk::MessageLog log;
        bool debug_utils = false;
        vk::Instance instance = vk::create_instance(false, &log, debug_utils);
        return vk::physical_devices(instance.get());
    } catch (const std::runtime_error&) {
        return {};
    }
}

}  // namespace

VulkanDevices find_vulkan_devices() {
    VulkanDevices found;
    for (const vk::PhysicalDeviceInfo& d : present_devices()) {
        found.names.emplace_back(d.properties.deviceName);
        if (d.refusal.empty() && d.properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) found.hardware = true;
    }
    return found;
}

std::vector<std::string> gpu_device_files(const std::string& dev) {
    std::vector<std::string> found;
    std::error_code error;
    // The files of dev/`folder` whose names start with one of `prefixes`.
    auto add_matching = [&](const std::string& folder, std::initializer_list<const char*> prefixes) {
        for (std::filesystem::directory_iterator it(std::filesystem::path(dev) / folder, error), end;
             !error && it != end; it.increment(error)) {
            const std::string name = it->path().filename().string();
            for (const char* prefix : prefixes)
                if (name.rfind(prefix, 0) == 0) found.push_back(folder.empty() ? name : folder + "/" + name);
        }
        error.clear();
    };
    add_matching("", {"nvidia", "dxg", "kgsl", "mali"});
    add_matching("dri", {"renderD"});
    std::sort(found.begin(), found.end());
    return found;
}

GpuProbe probe_gpus() {
#ifdef __linux__
    const bool drivers_named = std::getenv("VK_DRIVER_FILES") != nullptr || std::getenv("VK_ICD_FILENAMES") != nullptr;
    if (!drivers_named && gpu_device_files().empty()) return GpuProbe{VulkanDevices{}, true};
#endif
    return GpuProbe{find_vulkan_devices(), false};
}

std::vector<std::string> list_vulkan_devices() { return find_vulkan_devices().names; }

}  // namespace lc
