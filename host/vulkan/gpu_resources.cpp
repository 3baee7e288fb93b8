#include "gpu_resources.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include "run_on_threads.h"
#include "vk_check.h"

namespace lc::vk {

namespace {

// No single buffer is made larger than this even where the device would
// allow it: tiles just get smaller.
constexpr VkDeviceSize kBufferBudget = VkDeviceSize(256) << 20;
// The largest tile when neither the limits nor the tuning say otherwise.
constexpr std::uint32_t kMaxTilePixels = 1u << 20;

// What the kernels declare at each scene binding (shaders/kernel.glsl), in
// binding order: scene_arrays() must hand over exactly these, in this order.
struct SceneBinding {
    std::uint32_t binding;
    const char* array_name;
    std::size_t element_bytes;
};
constexpr SceneBinding kSceneBindings[] = {
    {gpu::kBindingBvhNodes, "bvh_nodes", sizeof(gpu::BvhNode)},
    {gpu::kBindingTriangles, "triangles", sizeof(gpu::Triangle)},
    {gpu::kBindingNormals, "normals", sizeof(gpu::TriangleNormals)},
    {gpu::kBindingUvs, "uvs", sizeof(gpu::TriangleUvs)},
    {gpu::kBindingMaterials, "materials", sizeof(gpu::Material)},
    {gpu::kBindingTextures, "textures", sizeof(gpu::TextureInfo)},
    {gpu::kBindingTexels, "texels", sizeof(std::uint32_t)},
    {gpu::kBindingLights, "lights", sizeof(gpu::Light)},
    {gpu::kBindingLightNodes, "light_tree_nodes", sizeof(gpu::LightNode)},
    {gpu::kBindingEnvironment, "environment", sizeof(float)},
    {gpu::kBindingWideBvhNodes, "wide_bvh_nodes", sizeof(gpu::Bvh4Node) / gpu::kBvh4NodeWords},
    {gpu::kBindingFrame, "frame", sizeof(gpu::FrameParams)},  // appended by RenderSetup
};
constexpr bool scene_bindings_in_order() {
    for (std::uint32_t i = 0; i < std::size(kSceneBindings); ++i)
        if (kSceneBindings[i].binding != gpu::kBindingBvhNodes + i) return false;
    return kSceneBindings[std::size(kSceneBindings) - 1].binding == gpu::kBindingFrame &&
           gpu::kBindingGBuffer == gpu::kBindingFrame + 1;
}
static_assert(scene_bindings_in_order());
static_assert(gpu::kBindingRadiance == gpu::kBindingGBuffer + 1 &&
              gpu::kBindingPixelStats == gpu::kBindingGBuffer + 2 &&
              gpu::kBindingHeapSave == gpu::kBindingGBuffer + 3 &&
              gpu::kBindingCutState == gpu::kBindingGBuffer + 4 &&
              gpu::kBindingChunkTable == gpu::kBindingGBuffer + 5 &&
              gpu::kBindingCount == gpu::kBindingChunkTable + 1,
              "GpuResources::TileIndex follows the per-tile bindings, then the chunk table");
static_assert(gpu::kSceneArrayCount == gpu::kBindingFrame, "every scene array before the frame constants can be split");

// The scene arrays that also have a texel view (RGBA32UI, 16 bytes a
// texel), at the bindings kBindingBvhNodeTexels ...
struct TexelArray {
    std::uint32_t binding;        // the array's storage binding
    std::uint32_t texel_binding;  // its view's binding
};
constexpr TexelArray kTexelArrays[] = {
    {gpu::kBindingBvhNodes, gpu::kBindingBvhNodeTexels},
    {gpu::kBindingTriangles, gpu::kBindingTriangleTexels},
    {gpu::kBindingLights, gpu::kBindingLightTexels},
    {gpu::kBindingLightNodes, gpu::kBindingLightNodeTexels},
    {gpu::kBindingWideBvhNodes, gpu::kBindingWideBvhNodeTexels},
};
constexpr VkDeviceSize kTexelBytes = 16;
static_assert(std::size(kTexelArrays) == gpu::kTexelBindingCount &&
              gpu::kBindingBvhNodeTexels == gpu::kBindingCount &&
              gpu::kBindingWideBvhNodeTexels == gpu::kBindingCount + gpu::kTexelBindingCount - 1);
static_assert(sizeof(gpu::BvhNode) == 2 * kTexelBytes && sizeof(gpu::Triangle) == 3 * kTexelBytes &&
              sizeof(gpu::Light) == 3 * kTexelBytes && sizeof(gpu::LightNode) == 4 * kTexelBytes &&
              sizeof(gpu::Bvh4Node) == gpu::kBvh4NodeWords * kTexelBytes,
              "shaders/kernel.glsl unpacks these structs from whole texels");

bool has_texel_view(std::uint32_t binding) {
    for (const TexelArray& a : kTexelArrays)
        if (a.binding == binding) return true;
    return false;
}

void check_scene_order(const std::vector<SceneArray>& scene) {
    bool ok = scene.size() == std::size(kSceneBindings);
    for (std::size_t i = 0; ok && i < scene.size(); ++i)
        ok = std::strcmp(scene[i].name, kSceneBindings[i].array_name) == 0 &&
             scene[i].element_bytes == kSceneBindings[i].element_bytes;
    if (!ok)
        throw std::logic_error(
            "scene_arrays() and the frame constants no longer list the arrays in the order of the "
            "bindings kBindingBvhNodes .. kBindingFrame (shaders/bindings.glsl)");
}

std::string mib(VkDeviceSize bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / double(1 << 20));
    return text;
}

}  // namespace

GpuResources::GpuResources(const Context& ctx, Submitter& submitter,
                           const std::vector<SceneArray>& scene, const ShadingMethod& method,
                           std::uint64_t image_pixels, std::uint32_t max_tile_pixels,
                           std::uint64_t split_bytes, bool texel_reads, bool chunk_buffers,
                           bool host_import)
    : ctx_(ctx),
      submitter_(submitter),
      split_bytes_(split_bytes),
      chunk_buffers_(chunk_buffers),
      host_import_(host_import) {
    const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
    max_buffer_ = std::min<VkDeviceSize>(limits.maxStorageBufferRange, ctx.max_allocation_size());
    upload_scene(scene);
    texel_reads_ = texel_reads && texel_views_fit();
    create_texel_views();
    const std::vector<TileBuffer> buffers = tile_buffers(method);
    fit_tiles(buffers, image_pixels, max_tile_pixels);
    create_tile_buffers(buffers);
    create_descriptors();
    create_pipeline_layout();
}

void GpuResources::check_fits(const std::string& name, VkDeviceSize bytes) const {
    const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
    const char* limit_name = nullptr;
    VkDeviceSize limit = 0;
    if (bytes > limits.maxStorageBufferRange) {
        limit_name = "maxStorageBufferRange";
        limit = limits.maxStorageBufferRange;
    } else if (bytes > ctx_.max_allocation_size()) {
        limit_name = "maxMemoryAllocationSize";
        limit = ctx_.max_allocation_size();
    }
    if (limit_name)
        throw std::runtime_error("scene does not fit the Vulkan device " + ctx_.device_name() +
                                 ": buffer '" + name + "' needs " + std::to_string(bytes) +
                                 " bytes (" + mib(bytes) + "), more than its " + limit_name +
                                 " of " + std::to_string(limit) + " bytes (" + mib(limit) + ")");
}

Buffer GpuResources::storage_buffer(const std::string& name, VkDeviceSize bytes, MemoryUse use,
                                    VkBufferUsageFlags extra_usage) {
    check_fits(name, bytes);
    VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | extra_usage;
    Buffer buffer(ctx_.device(), ctx_.memory(), bytes, usage, use, name);
    buffer_bytes_.emplace_back(name, bytes);
    return buffer;
}

// Fills a device-local buffer with `bytes` bytes from `data`: through the
// mapping where the device memory is host-visible (lavapipe, integrated
// GPUs), through a staging buffer and a copy otherwise.
void GpuResources::upload(const std::string& name, const void* data, VkDeviceSize bytes, Buffer& buffer,
                          VkDeviceSize offset) {
    if (buffer.mapped()) {
        // Large arrays (the lights and nodes of millions of lights) are
        // fresh memory to fault in as much as bytes to copy: every core
        // takes a share.
        const auto* from = static_cast<const unsigned char*>(data);
        auto* to = static_cast<unsigned char*>(buffer.mapped()) + offset;
        const unsigned threads = bytes < (VkDeviceSize(64) << 20) ? 1u : std::max(1u, std::thread::hardware_concurrency());
        const VkDeviceSize share = (bytes + threads - 1) / threads;
        run_on_threads(threads, [&](unsigned t) {
            const VkDeviceSize begin = std::min(bytes, t * share), end = std::min(bytes, begin + share);
            std::memcpy(to + begin, from + begin, end - begin);
        });
        return;
    }
    Buffer staging(ctx_.device(), ctx_.memory(), bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                   MemoryUse::kUpload, name + " staging");
    std::memcpy(staging.mapped(), data, bytes);
    VkCommandBuffer cmd = submitter_.begin();
    VkBufferCopy region{0, offset, bytes};
    ctx_.fn().vkCmdCopyBuffer(cmd, staging.get(), buffer.get(), 1, &region);
    // The kernels read what the copy wrote.
    auto barrier = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    ctx_.fn().vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0,
                                   nullptr, 0, nullptr);
    submitter_.submit_and_wait();  // the staging buffer dies at the end of this function
}

// The array in one device-local buffer if it fits one (maxStorageBufferRange,
// maxMemoryAllocationSize and the forced split size), else in chunks of the
// largest power of two of elements that does, read by the kernels through
// their device addresses. The chunks are windows of one buffer where the
// whole array fits one allocation (a texel view can then still cover it),
// else each its own buffer (and always with `chunk_buffers_`). An empty
// array gets one zeroed element so that every binding has a buffer.
std::vector<Buffer> GpuResources::upload_chunks(const SceneArray& array, std::uint32_t binding) {
    const std::vector<unsigned char> zero_element(array.count == 0 ? array.element_bytes : 0);
    const auto* source = static_cast<const unsigned char*>(array.count == 0 ? zero_element.data() : array.data);
    const std::uint64_t count = std::max<std::uint64_t>(array.count, 1);
    const VkDeviceSize element = array.element_bytes;
    const VkDeviceSize bytes = count * element;
    // The array's own name, so that the report lists each array once.
    const std::string name = array.name;

    VkDeviceSize limit = max_buffer_;
    if (split_bytes_ > 0) limit = std::min(limit, split_bytes_);
    std::uint32_t shift = 31;
    // An element larger than the limit (only a forced split's can be) gets
    // a chunk of its own.
    if (binding < gpu::kSceneArrayCount && bytes > limit) {
        shift = 0;
        while (shift < 30 && (VkDeviceSize(2) << shift) * element <= limit) ++shift;
    }
    const std::uint64_t per_chunk = std::uint64_t(1) << shift;
    const std::uint64_t chunk_count = (count + per_chunk - 1) / per_chunk;
    if (binding < gpu::kSceneArrayCount) chunks_.shift[binding] = shift;
    if (chunk_count > 1) chunks_.split = true;
    chunk_counts_.push_back(chunk_count);
    first_chunk_bytes_.push_back(std::min(per_chunk, count) * element);
    buffer_bytes_.emplace_back(name, bytes);

    const VkBufferUsageFlags usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
        VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
        (has_texel_view(binding) ? VkBufferUsageFlags(VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT) : VkBufferUsageFlags(0));
    std::vector<Buffer> buffers;
    // The allocation may round the buffer's size up to its alignment: keep
    // a margin below maxMemoryAllocationSize.
    constexpr VkDeviceSize kAllocationMargin = VkDeviceSize(1) << 16;
    const bool one_allocation = bytes + kAllocationMargin <= ctx_.max_allocation_size();
    // Where the device can use the array's host memory in place (a CPU
    // device; an array that owns whole pages), it does: no copy.
    const VkDeviceSize align = host_import_ ? ctx_.host_import_alignment() : 0;
    imported_.push_back(align > 0 && array.count > 0 && array.page_bytes > 0 &&
                        reinterpret_cast<std::uintptr_t>(array.data) % align == 0 &&
                        (bytes + align - 1) / align * align <= array.page_bytes &&
                        one_allocation && !(chunk_count > 1 && chunk_buffers_));
    if (imported_.back()) {
        buffers.emplace_back(ctx_.device(), ctx_.memory(), array.data, bytes, array.page_bytes, align, usage, name);
        return buffers;
    }
    if (chunk_count > 1 && !chunk_buffers_ && one_allocation) {
        Buffer buffer(ctx_.device(), ctx_.memory(), bytes, usage, MemoryUse::kDevice, name);
        // Chunk by chunk, so that a staging buffer holds one chunk at a time.
        for (std::uint64_t first = 0; first < count; first += per_chunk) {
            const VkDeviceSize chunk_bytes = std::min(per_chunk, count - first) * element;
            upload(name, source + first * element, chunk_bytes, buffer, first * element);
        }
        buffers.push_back(std::move(buffer));
        return buffers;
    }
    for (std::uint64_t first = 0; first < count; first += per_chunk) {
        const VkDeviceSize chunk_bytes = std::min(per_chunk, count - first) * element;
        const std::string chunk_name = chunk_count == 1 ? name : name + " chunk " + std::to_string(buffers.size());
        // Still refuses an array that cannot be split (the frame constants)
        // or whose single element is larger than a buffer may be.
        check_fits(chunk_name, chunk_bytes);
        Buffer buffer(ctx_.device(), ctx_.memory(), chunk_bytes, usage, MemoryUse::kDevice, chunk_name);
        upload(chunk_name, source + first * element, chunk_bytes, buffer);
        buffers.push_back(std::move(buffer));
    }
    return buffers;
}

void GpuResources::upload_scene(const std::vector<SceneArray>& scene) {
    check_scene_order(scene);
    for (std::uint32_t b = 0; b < scene.size(); ++b) scene_.push_back(upload_chunks(scene[b], b));
    create_chunk_table();
}

// ChunkTable (shaders/bindings.glsl): for each scene array, the index of its
// chunk 0 in the address list, then the device address of every chunk.
void GpuResources::create_chunk_table() {
    std::vector<std::uint32_t> words(gpu::kChunkTableFirstWords);
    const auto address_of = [&](const Buffer& buffer) {
        auto info = vk_struct<VkBufferDeviceAddressInfo>(VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO);
        info.buffer = buffer.get();
        return ctx_.fn().vkGetBufferDeviceAddress(ctx_.device().get(), &info);
    };
    for (std::uint32_t b = 0; b < gpu::kSceneArrayCount; ++b) {
        words[b] = std::uint32_t((words.size() - gpu::kChunkTableFirstWords) / 2);
        for (std::uint64_t c = 0; c < chunk_counts_[b]; ++c) {
            // Chunk c: buffer c, or the window c of the array's one buffer.
            const bool windows = scene_[b].size() == 1;
            const VkDeviceAddress address =
                windows ? address_of(scene_[b][0]) + c * first_chunk_bytes_[b] : address_of(scene_[b][c]);
            words.push_back(std::uint32_t(address));
            words.push_back(std::uint32_t(address >> 32));
        }
    }
    static_assert(gpu::kChunkTableHeaderBytes % 8 == 0, "the uvec2 addresses follow the header unpadded");
    const VkDeviceSize bytes = words.size() * sizeof(std::uint32_t);
    chunk_table_ = storage_buffer("chunk addresses", bytes, MemoryUse::kDevice, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    upload("chunk addresses", words.data(), bytes, chunk_table_);
}

// Texel views can cover the five arrays: each is in one buffer (a view sees
// one buffer; chunks that are windows of one buffer are fine) and within
// maxTexelBufferElements. (RGBA32UI storage texel buffers themselves are
// there on every device the context takes: descriptor_refusal.)
bool GpuResources::texel_views_fit() const {
    for (const TexelArray& a : kTexelArrays)
        if (scene_[a.binding].size() > 1) return false;
    const VkDeviceSize max_texels = ctx_.properties().limits.maxTexelBufferElements;
    for (const TexelArray& a : kTexelArrays)
        if (scene_[a.binding][0].size() / kTexelBytes > max_texels) return false;
    return true;
}

void GpuResources::create_texel_views() {
    for (const TexelArray& a : kTexelArrays) {
        const Buffer& buffer = scene_[a.binding][0];
        auto info = vk_struct<VkBufferViewCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO);
        info.buffer = buffer.get();
        info.format = kTexelFormat;
        info.offset = 0;
        info.range = texel_reads_ ? buffer.size() / kTexelBytes * kTexelBytes : kTexelBytes;
        VkBufferView view = VK_NULL_HANDLE;
        VK_CHECK(ctx_.fn().vkCreateBufferView(ctx_.device().get(), &info, nullptr, &view));
        texel_views_.push_back(own<BufferView>(ctx_.device(), view, std::string(kSceneBindings[a.binding].array_name) + " texels"));
    }
}

std::vector<TileBuffer> GpuResources::tile_buffers(const ShadingMethod& method) const {
    std::vector<TileBuffer> buffers(kTileBufferCount);
    buffers[kGBuffer] = {"g-buffer", sizeof(gpu::GBufferTexel), ""};
    buffers[kRadiance] = {"radiance", 3 * sizeof(float), ""};
    buffers[kPixelStats] = {"pixel stats", sizeof(gpu::PixelStats), ""};
    buffers[kHeapSave] = method.heap_save();
    buffers[kCutState] = method.cut_state();
    return buffers;
}

// The largest tile, in whole workgroups, whose per-tile buffers each fit
// the device's limits and kBufferBudget.
void GpuResources::fit_tiles(const std::vector<TileBuffer>& buffers, std::uint64_t image_pixels,
                             std::uint32_t max_tile_pixels) {
    const VkDeviceSize per_buffer = std::min(max_buffer_, kBufferBudget);
    VkDeviceSize fit = kMaxTilePixels;
    const TileBuffer* largest = &buffers[0];
    for (const TileBuffer& b : buffers) {
        if (b.bytes_per_pixel > 0) fit = std::min(fit, per_buffer / b.bytes_per_pixel);
        if (b.bytes_per_pixel > largest->bytes_per_pixel) largest = &b;
    }
    fit = fit / gpu::kWorkgroupSize * gpu::kWorkgroupSize;
    if (fit == 0)
        throw std::runtime_error(
            "scene does not fit the Vulkan device " + ctx_.device_name() + ": buffer '" +
            largest->name + "' needs " +
            std::to_string(largest->bytes_per_pixel * gpu::kWorkgroupSize) +
            " bytes for one workgroup" + (largest->why.empty() ? "" : " (" + largest->why + ")") +
            ", more than the " + std::to_string(per_buffer) + " bytes one buffer may use");

    std::uint64_t max_pixels = std::min<std::uint64_t>(fit, image_pixels);
    if (max_tile_pixels > 0) max_pixels = std::min<std::uint64_t>(max_pixels, max_tile_pixels);
    tiles_.max_pixels = std::uint32_t(std::max<std::uint64_t>(max_pixels, 1));
    tiles_.invocations = (tiles_.max_pixels + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize *
                         gpu::kWorkgroupSize;
}

void GpuResources::create_tile_buffers(const std::vector<TileBuffer>& buffers) {
    // One element where a method does not use a buffer: every binding needs one.
    const VkDeviceSize unused_bytes[kTileBufferCount] = {0, 0, 0, sizeof(gpu::CutEntry),
                                                         sizeof(gpu::CutState)};
    constexpr VkBufferUsageFlags kFillAndCopy =
        VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    for (int i = 0; i < kTileBufferCount; ++i) {
        const TileBuffer& b = buffers[std::size_t(i)];
        const VkDeviceSize bytes =
            b.bytes_per_pixel > 0 ? tiles_.invocations * b.bytes_per_pixel : unused_bytes[i];
        const bool output = i == kRadiance || i == kPixelStats;
        tile_[i] = storage_buffer(b.name, bytes, MemoryUse::kDevice, output ? kFillAndCopy : 0);
    }
    if (!radiance().mapped() || !pixel_stats().mapped()) {
        radiance_readback_ = storage_buffer("radiance read-back", radiance().size(),
                                            MemoryUse::kReadback, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        stats_readback_ = storage_buffer("pixel stats read-back", pixel_stats().size(),
                                         MemoryUse::kReadback, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    }
}

const float* GpuResources::radiance_sums() const {
    const Buffer& b = needs_readback_copies() ? radiance_readback_ : radiance();
    return static_cast<const float*>(b.mapped());
}

const gpu::PixelStats* GpuResources::pixel_stats_sums() const {
    const Buffer& b = needs_readback_copies() ? stats_readback_ : pixel_stats();
    return static_cast<const gpu::PixelStats*>(b.mapped());
}

void GpuResources::create_descriptors() {
    VkDevice device = ctx_.device().get();
    const VolkDeviceTable& vkd = ctx_.fn();
    constexpr std::uint32_t kAllBindings = gpu::kBindingCount + gpu::kTexelBindingCount;
    VkDescriptorSetLayoutBinding bindings[kAllBindings];
    for (std::uint32_t b = 0; b < kAllBindings; ++b)
        bindings[b] = {b,
                       b < gpu::kBindingCount ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                              : VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
                       1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    auto layout_info = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    layout_info.bindingCount = kAllBindings;
    layout_info.pBindings = bindings;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateDescriptorSetLayout(device, &layout_info, nullptr, &set_layout));
    set_layout_ = own<DescriptorSetLayout>(ctx_.device(), set_layout, "kernel buffers layout");

    const VkDescriptorPoolSize pool_sizes[] = {
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, gpu::kBindingCount},
        {VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, gpu::kTexelBindingCount}};
    auto pool_info = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    pool_info.maxSets = 1;
    pool_info.poolSizeCount = std::uint32_t(std::size(pool_sizes));
    pool_info.pPoolSizes = pool_sizes;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateDescriptorPool(device, &pool_info, nullptr, &pool));
    descriptor_pool_ = own<DescriptorPool>(ctx_.device(), pool, "descriptor pool");

    auto alloc_info = vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    alloc_info.descriptorPool = pool;
    alloc_info.descriptorSetCount = 1;
    alloc_info.pSetLayouts = &set_layout;
    VK_CHECK(vkd.vkAllocateDescriptorSets(device, &alloc_info, &descriptor_set_));
    ctx_.device().set_name(descriptor_set_, "kernel buffers");

    const auto write = [&](std::uint32_t binding, VkDescriptorType type) {
        auto w = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
        w.dstSet = descriptor_set_;
        w.dstBinding = binding;
        w.descriptorCount = 1;
        w.descriptorType = type;
        return w;
    };
    VkDescriptorBufferInfo infos[gpu::kBindingCount];
    VkBufferView views[gpu::kTexelBindingCount];
    VkWriteDescriptorSet writes[kAllBindings];
    for (std::uint32_t b = 0; b < gpu::kBindingCount; ++b) {
        const Buffer& buffer = b < gpu::kBindingGBuffer    ? scene_[b][0]
                               : b == gpu::kBindingChunkTable ? chunk_table_
                                                              : tile_[b - gpu::kBindingGBuffer];
        // A scene array's binding sees its chunk 0 (within maxStorageBufferRange).
        infos[b] = {buffer.get(), 0, b < gpu::kSceneArrayCount ? first_chunk_bytes_[b] : VK_WHOLE_SIZE};
        writes[b] = write(b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
        writes[b].pBufferInfo = &infos[b];
    }
    for (std::uint32_t t = 0; t < gpu::kTexelBindingCount; ++t) {
        const std::uint32_t b = kTexelArrays[t].texel_binding;
        views[t] = texel_views_[t].get();
        writes[b] = write(b, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER);
        writes[b].pTexelBufferView = &views[t];
    }
    vkd.vkUpdateDescriptorSets(device, kAllBindings, writes, 0, nullptr);
}

void GpuResources::create_pipeline_layout() {
    VkDescriptorSetLayout set_layout = set_layout_.get();
    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::PushConstants)};
    auto pipeline_layout_info = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    pipeline_layout_info.setLayoutCount = 1;
    pipeline_layout_info.pSetLayouts = &set_layout;
    pipeline_layout_info.pushConstantRangeCount = 1;
    pipeline_layout_info.pPushConstantRanges = &push;
    VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
    VK_CHECK(ctx_.fn().vkCreatePipelineLayout(ctx_.device().get(), &pipeline_layout_info, nullptr,
                                              &pipeline_layout));
    pipeline_layout_ = own<PipelineLayout>(ctx_.device(), pipeline_layout, "kernel layout");
}

}  // namespace lc::vk
