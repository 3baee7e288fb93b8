// render_vulkan: the scene's buffers go to the device once; the image is
// rendered in tiles, each sample of a tile as one submission (camera rays ->
// G-buffer, then brute force or Lightcuts shading added to the tile's sums,
// in one dispatch or split over several); the sums come back after the
// tile's last sample. docs/vulkan.md describes the whole path.
#include "vulkan_renderer.h"

#include <stdint.h>  // the generated SPIR-V headers use ::uint32_t

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "bindings.glsl"
#include "spirv/brute.h"
#include "spirv/lightcuts.h"
#include "spirv/primary.h"
#include "vk_check.h"
#include "progress.h"
#include "vk_context.h"

namespace lc::vk {

namespace {

using Clock = std::chrono::steady_clock;
using gpu::kWorkgroupSize;

// The GLSL push-constant block of shaders/kernel.glsl.
static_assert(sizeof(gpu::PushConstants) == 124);
static_assert(offsetof(gpu::PushConstants, light_first) == gpu::kPushLightFirstOffset);
static_assert(offsetof(gpu::PushConstants, cut_flags) == gpu::kPushCutFlagsOffset);
static_assert(offsetof(gpu::PushConstants, refine_budget) == gpu::kPushRefineBudgetOffset);
static_assert(sizeof(gpu::PixelStats) == 32);
static_assert(sizeof(gpu::CutState) == 48);

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// No single buffer is made larger than this even where the device would
// allow it: tiles just get smaller.
constexpr VkDeviceSize kBufferBudget = VkDeviceSize(256) << 20;
// The largest tile when neither the limits nor the tuning say otherwise.
constexpr std::uint32_t kMaxTilePixels = 1u << 20;
// A submission that takes longer than this is treated as a hung device.
constexpr std::uint64_t kFenceTimeoutNs = 600ull * 1000 * 1000 * 1000;

std::string mib(VkDeviceSize bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / double(1 << 20));
    return text;
}

std::uint32_t round_up(std::uint32_t value, std::uint32_t multiple) {
    return (value + multiple - 1) / multiple * multiple;
}

// Values of the kernels' specialization constants (shaders/bindings.glsl).
struct SpecData {
    std::uint32_t workgroup_size;
    VkBool32 enable_ggx;
    VkBool32 enable_shadows;
    std::uint32_t heap_shared;
    std::uint32_t heap_capacity;
    std::uint32_t spill_stride;
};

// Size of the per-tile buffers.
struct TileLayout {
    std::uint32_t max_pixels = 0;      // largest tile the buffers hold
    std::uint32_t invocations = 0;     // max_pixels rounded up to whole workgroups
};

class Renderer {
public:
    Renderer(const Context& ctx, const PreparedScene& prepared, const RenderOptions& options,
             const Tuning& tuning);
    // Waits for the device, so no submission outlives the buffers it uses
    // when an exception unwinds mid-render.
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;
    RenderResult run();

private:
    Buffer storage_buffer(const std::string& name, VkDeviceSize bytes, MemoryUse use,
                          VkBufferUsageFlags extra_usage = 0);
    template <typename T>
    Buffer upload(const std::string& name, const std::vector<T>& data);
    void check_fits(const std::string& name, VkDeviceSize bytes) const;
    void submit_and_wait(VkCommandBuffer cmd);
    void begin(VkCommandBuffer cmd);
    Pipeline compute_pipeline(const std::uint32_t* code, std::size_t bytes, const SpecData& spec,
                              const std::string& name);
    void choose_heap_and_tiles();
    void create_pipelines();
    void create_descriptors();
    // Renders samples [0, spp) of one tile; returns the slowest dispatch in ms.
    double render_tile(std::uint32_t x0, std::uint32_t y0, std::uint32_t w, std::uint32_t h,
                       RenderResult& result);
    void record_pass(VkCommandBuffer cmd, const gpu::FrameParams& frame, bool first, bool last);
    std::uint32_t shading_dispatches() const;
    void reserve_timestamps(std::uint32_t count);
    void report_progress(bool done);

    const Context& ctx_;
    const VolkDeviceTable& vkd_;
    const PreparedScene& prepared_;
    const RenderOptions& options_;
    const Tuning tuning_;
    const bool lightcuts_;
    gpu::FrameParams frame_{};
    VkDeviceSize max_buffer_ = 0;        // min(maxStorageBufferRange, maxMemoryAllocationSize)
    std::vector<std::pair<std::string, std::uint64_t>> buffer_bytes_;

    std::uint32_t heap_shared_ = 0;      // K
    std::uint32_t heap_capacity_ = 0;    // max(max_cut, 2)
    TileLayout tiles_;
    std::uint32_t light_chunk_ = 1;      // brute force: lights per dispatch
    std::uint32_t refine_budget_ = gpu::kUnlimitedRefinements;  // lightcuts: per dispatch

    // Destroyed in reverse order: pipelines, descriptors, buffers, then the
    // command pool (with its command buffer), fence and queries.
    CommandPool command_pool_;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    Fence fence_;
    QueryPool timestamps_;                // before camera rays, then after every dispatch
    std::uint32_t timestamp_capacity_ = 0;

    Buffer bvh_nodes_, triangles_, normals_, materials_, lights_, light_nodes_;
    Buffer gbuffer_, radiance_, pixel_stats_, heap_spill_, cut_states_;
    Buffer radiance_readback_, stats_readback_;  // only where device memory is not mappable

    DescriptorSetLayout set_layout_;
    DescriptorPool descriptor_pool_;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    PipelineLayout pipeline_layout_;
    Pipeline primary_pipeline_, shade_pipeline_;

    // Progress and timing.
    Clock::time_point start_ = Clock::now();
    Progress progress_{options_.progress};
    std::uint64_t samples_done_ = 0, samples_total_ = 0;
    double seconds_primary_ = 0.0, seconds_shading_ = 0.0;
};

Renderer::Renderer(const Context& ctx, const PreparedScene& prepared, const RenderOptions& options,
                   const Tuning& tuning)
    : ctx_(ctx),
      vkd_(ctx.fn()),
      prepared_(prepared),
      options_(options),
      tuning_(tuning),
      lightcuts_(options.method == "lightcuts") {
    validate_render_options(options);
    frame_ = make_frame_params(prepared, options);
    light_chunk_ = std::max(frame_.light_count, 1u);
    if (tuning.lights_per_dispatch > 0) light_chunk_ = std::min(light_chunk_, tuning.lights_per_dispatch);
    if (tuning.refinements_per_dispatch > 0) refine_budget_ = tuning.refinements_per_dispatch;

    const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
    max_buffer_ = std::min<VkDeviceSize>(limits.maxStorageBufferRange, ctx.max_allocation_size());
    if (limits.maxPushConstantsSize < sizeof(gpu::PushConstants))
        throw std::runtime_error("Vulkan device offers " +
                                 std::to_string(limits.maxPushConstantsSize) +
                                 " bytes of push constants; the kernels need " +
                                 std::to_string(sizeof(gpu::PushConstants)));

    VkDevice device = ctx.device().get();
    auto pool_info = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = ctx.queue_family();
    VkCommandPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateCommandPool(device, &pool_info, nullptr, &pool));
    command_pool_ = own<CommandPool>(ctx.device(), pool, "command pool");

    auto cmd_info = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    cmd_info.commandPool = pool;
    cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmd_info.commandBufferCount = 1;
    VK_CHECK(vkd_.vkAllocateCommandBuffers(device, &cmd_info, &cmd_));
    ctx.device().set_name(cmd_, "render commands");

    auto fence_info = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    VkFence fence = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateFence(device, &fence_info, nullptr, &fence));
    fence_ = own<Fence>(ctx.device(), fence, "submission fence");
}

Renderer::~Renderer() { vkd_.vkDeviceWaitIdle(ctx_.device().get()); }

std::uint32_t Renderer::shading_dispatches() const {
    if (lightcuts_)
        // A cut grows by one cluster per refinement, so max_cut / budget + 1
        // dispatches of `budget` refinements finish every cut.
        return refine_budget_ == gpu::kUnlimitedRefinements ? 1
                                                            : frame_.max_cut / refine_budget_ + 1;
    return std::max(1u, (frame_.light_count + light_chunk_ - 1) / light_chunk_);
}

void Renderer::reserve_timestamps(std::uint32_t count) {
    if (ctx_.timestamp_valid_bits() == 0 || count <= timestamp_capacity_) return;
    auto query_info = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = count;
    VkQueryPool queries = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateQueryPool(ctx_.device().get(), &query_info, nullptr, &queries));
    timestamps_ = own<QueryPool>(ctx_.device(), queries, "dispatch timestamps");
    timestamp_capacity_ = count;
}

void Renderer::check_fits(const std::string& name, VkDeviceSize bytes) const {
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

Buffer Renderer::storage_buffer(const std::string& name, VkDeviceSize bytes, MemoryUse use,
                                VkBufferUsageFlags extra_usage) {
    check_fits(name, bytes);
    VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | extra_usage;
    Buffer buffer(ctx_.device(), ctx_.memory(), bytes, usage, use, name);
    buffer_bytes_.emplace_back(name, bytes);
    return buffer;
}

void Renderer::begin(VkCommandBuffer cmd) {
    auto begin_info = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkd_.vkBeginCommandBuffer(cmd, &begin_info));
}

void Renderer::submit_and_wait(VkCommandBuffer cmd) {
    VK_CHECK(vkd_.vkEndCommandBuffer(cmd));
    auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    VkFence fence = fence_.get();
    VK_CHECK(vkd_.vkQueueSubmit(ctx_.queue(), 1, &submit, fence));
    VK_CHECK(vkd_.vkWaitForFences(ctx_.device().get(), 1, &fence, VK_TRUE, kFenceTimeoutNs));
    VK_CHECK(vkd_.vkResetFences(ctx_.device().get(), 1, &fence));
}

// Device-local buffer holding `data`: written through the mapping where the
// device memory is host-visible (lavapipe, integrated GPUs), through a
// staging buffer and a copy otherwise. Empty arrays get one zeroed element
// so every binding has a buffer.
template <typename T>
Buffer Renderer::upload(const std::string& name, const std::vector<T>& data) {
    const std::vector<T> one_element(data.empty() ? 1 : 0);
    const std::vector<T>& source = data.empty() ? one_element : data;
    const VkDeviceSize bytes = source.size() * sizeof(T);
    Buffer buffer = storage_buffer(name, bytes, MemoryUse::kDevice, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    if (buffer.mapped()) {
        std::memcpy(buffer.mapped(), source.data(), bytes);
        return buffer;
    }
    Buffer staging(ctx_.device(), ctx_.memory(), bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                   MemoryUse::kUpload, name + " staging");
    std::memcpy(staging.mapped(), source.data(), bytes);
    begin(cmd_);
    VkBufferCopy region{0, 0, bytes};
    vkd_.vkCmdCopyBuffer(cmd_, staging.get(), buffer.get(), 1, &region);
    // The kernels read what the copy wrote.
    auto barrier = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkd_.vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0,
                              nullptr);
    submit_and_wait(cmd_);  // the staging buffer dies at the end of this function
    return buffer;
}

// Walter 2005 §4 needs a max-heap of up to max(max_cut, 2) clusters per
// shaded point. The first K slots live in workgroup shared memory (as many
// as the device's shared memory holds for a whole workgroup), the rest in a
// global buffer with one region per invocation of the tile. The tile's
// largest size then follows from the per-pixel bytes and the buffer limits.
void Renderer::choose_heap_and_tiles() {
    const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
    if (lightcuts_) {
        heap_capacity_ = std::max(frame_.max_cut, 2u);
        const std::uint32_t k_max = limits.maxComputeSharedMemorySize /
                                    (kWorkgroupSize * std::uint32_t(sizeof(gpu::CutEntry)));
        if (k_max == 0)
            throw std::runtime_error("Vulkan device has too little shared memory (" +
                                     std::to_string(limits.maxComputeSharedMemorySize) +
                                     " bytes) for the cut heap");
        heap_shared_ = std::min(k_max, heap_capacity_);
    } else {
        heap_shared_ = 1;
        heap_capacity_ = 1;
    }

    // Bytes per tile pixel of each per-tile buffer (brute force needs no heap).
    const VkDeviceSize heap_bytes =
        lightcuts_ ? VkDeviceSize(heap_capacity_) * sizeof(gpu::CutEntry) : 0;
    const std::pair<const char*, VkDeviceSize> per_pixel[] = {
        {"g-buffer", sizeof(gpu::GBufferTexel)},
        {"radiance", 3 * sizeof(float)},
        {"pixel stats", sizeof(gpu::PixelStats)},
        {"heap spill", heap_bytes},
        {"cut state", lightcuts_ ? sizeof(gpu::CutState) : 0},
    };
    const VkDeviceSize per_buffer = std::min(max_buffer_, kBufferBudget);
    VkDeviceSize fit = kMaxTilePixels;
    for (const auto& [name, bytes] : per_pixel)
        if (bytes > 0) fit = std::min(fit, per_buffer / bytes);
    fit = fit / kWorkgroupSize * kWorkgroupSize;
    if (fit == 0)
        throw std::runtime_error(
            "scene does not fit the Vulkan device " + ctx_.device_name() +
            ": buffer 'heap spill' needs " + std::to_string(heap_bytes * kWorkgroupSize) +
            " bytes for one workgroup (" + std::to_string(heap_capacity_) +
            " heap slots per pixel for max_cut " + std::to_string(frame_.max_cut) +
            "), more than the " + std::to_string(per_buffer) + " bytes one buffer may use");

    const std::uint64_t image_pixels = std::uint64_t(frame_.width) * frame_.height;
    std::uint64_t max_pixels = std::min<std::uint64_t>(fit, image_pixels);
    if (tuning_.max_tile_pixels > 0)
        max_pixels = std::min<std::uint64_t>(max_pixels, tuning_.max_tile_pixels);
    tiles_.max_pixels = std::uint32_t(std::max<std::uint64_t>(max_pixels, 1));
    tiles_.invocations = round_up(tiles_.max_pixels, kWorkgroupSize);
}

Pipeline Renderer::compute_pipeline(const std::uint32_t* code, std::size_t bytes,
                                    const SpecData& spec, const std::string& name) {
    VkDevice device = ctx_.device().get();
    auto module_info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    module_info.codeSize = bytes;
    module_info.pCode = code;
    VkShaderModule module_handle = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateShaderModule(device, &module_info, nullptr, &module_handle));
    ShaderModule module = own<ShaderModule>(ctx_.device(), module_handle, name + " module");

    const VkSpecializationMapEntry entries[] = {
        {gpu::kSpecWorkgroupSize, offsetof(SpecData, workgroup_size), sizeof(std::uint32_t)},
        {gpu::kSpecEnableGgx, offsetof(SpecData, enable_ggx), sizeof(VkBool32)},
        {gpu::kSpecEnableShadows, offsetof(SpecData, enable_shadows), sizeof(VkBool32)},
        {gpu::kSpecHeapShared, offsetof(SpecData, heap_shared), sizeof(std::uint32_t)},
        {gpu::kSpecHeapCapacity, offsetof(SpecData, heap_capacity), sizeof(std::uint32_t)},
        {gpu::kSpecSpillStride, offsetof(SpecData, spill_stride), sizeof(std::uint32_t)},
    };
    VkSpecializationInfo spec_info{};
    spec_info.mapEntryCount = std::uint32_t(std::size(entries));
    spec_info.pMapEntries = entries;
    spec_info.dataSize = sizeof spec;
    spec_info.pData = &spec;

    auto info = vk_struct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module.get();
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = &spec_info;
    info.layout = pipeline_layout_.get();
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
    return own<Pipeline>(ctx_.device(), pipeline, name);
}

void Renderer::create_descriptors() {
    VkDevice device = ctx_.device().get();
    VkDescriptorSetLayoutBinding bindings[gpu::kBindingCount];
    for (std::uint32_t b = 0; b < gpu::kBindingCount; ++b)
        bindings[b] = {b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    auto layout_info = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    layout_info.bindingCount = gpu::kBindingCount;
    layout_info.pBindings = bindings;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateDescriptorSetLayout(device, &layout_info, nullptr, &set_layout));
    set_layout_ = own<DescriptorSetLayout>(ctx_.device(), set_layout, "kernel buffers layout");

    VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, gpu::kBindingCount};
    auto pool_info = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    pool_info.maxSets = 1;
    pool_info.poolSizeCount = 1;
    pool_info.pPoolSizes = &pool_size;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreateDescriptorPool(device, &pool_info, nullptr, &pool));
    descriptor_pool_ = own<DescriptorPool>(ctx_.device(), pool, "descriptor pool");

    auto alloc_info = vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    alloc_info.descriptorPool = pool;
    alloc_info.descriptorSetCount = 1;
    alloc_info.pSetLayouts = &set_layout;
    VK_CHECK(vkd_.vkAllocateDescriptorSets(device, &alloc_info, &descriptor_set_));
    ctx_.device().set_name(descriptor_set_, "kernel buffers");

    const Buffer* buffers[gpu::kBindingCount] = {};
    buffers[gpu::kBindingBvhNodes] = &bvh_nodes_;
    buffers[gpu::kBindingTriangles] = &triangles_;
    buffers[gpu::kBindingNormals] = &normals_;
    buffers[gpu::kBindingMaterials] = &materials_;
    buffers[gpu::kBindingLights] = &lights_;
    buffers[gpu::kBindingLightNodes] = &light_nodes_;
    buffers[gpu::kBindingGBuffer] = &gbuffer_;
    buffers[gpu::kBindingRadiance] = &radiance_;
    buffers[gpu::kBindingPixelStats] = &pixel_stats_;
    buffers[gpu::kBindingHeapSpill] = &heap_spill_;
    buffers[gpu::kBindingCutState] = &cut_states_;
    VkDescriptorBufferInfo infos[gpu::kBindingCount];
    VkWriteDescriptorSet writes[gpu::kBindingCount];
    for (std::uint32_t b = 0; b < gpu::kBindingCount; ++b) {
        infos[b] = {buffers[b]->get(), 0, VK_WHOLE_SIZE};
        writes[b] = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
        writes[b].dstSet = descriptor_set_;
        writes[b].dstBinding = b;
        writes[b].descriptorCount = 1;
        writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[b].pBufferInfo = &infos[b];
    }
    vkd_.vkUpdateDescriptorSets(device, gpu::kBindingCount, writes, 0, nullptr);

    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(gpu::PushConstants)};
    auto pipeline_layout_info = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    pipeline_layout_info.setLayoutCount = 1;
    pipeline_layout_info.pSetLayouts = &set_layout;
    pipeline_layout_info.pushConstantRangeCount = 1;
    pipeline_layout_info.pPushConstantRanges = &push;
    VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
    VK_CHECK(vkd_.vkCreatePipelineLayout(device, &pipeline_layout_info, nullptr, &pipeline_layout));
    pipeline_layout_ = own<PipelineLayout>(ctx_.device(), pipeline_layout, "kernel layout");
}

void Renderer::create_pipelines() {
    SpecData spec{};
    spec.workgroup_size = kWorkgroupSize;
    spec.enable_ggx = tuning_.force_ggx || prepared_.has_specular;
    spec.enable_shadows = tuning_.force_shadows || prepared_.has_occluders;
    spec.heap_shared = heap_shared_;
    spec.heap_capacity = heap_capacity_;
    spec.spill_stride = tiles_.invocations;
    primary_pipeline_ = compute_pipeline(lc_spirv_primary, sizeof lc_spirv_primary, spec,
                                         "primary.comp (camera rays)");
    if (lightcuts_)
        shade_pipeline_ = compute_pipeline(lc_spirv_lightcuts, sizeof lc_spirv_lightcuts, spec,
                                           "lightcuts.comp (cut selection + shading)");
    else
        shade_pipeline_ = compute_pipeline(lc_spirv_brute, sizeof lc_spirv_brute, spec,
                                           "brute.comp (all lights)");
}

void Renderer::record_pass(VkCommandBuffer cmd, const gpu::FrameParams& frame, bool first,
                           bool last) {
    const std::uint32_t pixels = frame.tile_width * frame.tile_height;
    const std::uint32_t groups = (pixels + kWorkgroupSize - 1) / kWorkgroupSize;
    constexpr VkPipelineStageFlags kCompute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    constexpr VkPipelineStageFlags kComputeAndTransfer =
        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    auto barrier = [&](VkPipelineStageFlags src_stage, VkAccessFlags src,
                       VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
        auto b = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
        b.srcAccessMask = src;
        b.dstAccessMask = dst;
        vkd_.vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
    };
    constexpr VkAccessFlags kShaderReadWrite = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;

    const std::uint32_t dispatches = shading_dispatches();
    reserve_timestamps(2 + dispatches);
    VkQueryPool queries = timestamps_.get();
    if (queries) vkd_.vkCmdResetQueryPool(cmd, queries, 0, 2 + dispatches);

    // The previous submission's kernels and copies are done with the tile
    // buffers before this one overwrites them.
    barrier(kComputeAndTransfer, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
            kComputeAndTransfer,
            kShaderReadWrite | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
    if (first) {
        vkd_.vkCmdFillBuffer(cmd, radiance_.get(), 0, VK_WHOLE_SIZE, 0);
        vkd_.vkCmdFillBuffer(cmd, pixel_stats_.get(), 0, VK_WHOLE_SIZE, 0);
        // The kernels add to the sums the fills just zeroed.
        barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, kCompute,
                kShaderReadWrite);
    }

    gpu::PushConstants push{};
    push.frame = frame;
    push.light_first = 0;
    push.cut_flags = 0;
    push.refine_budget = gpu::kUnlimitedRefinements;
    vkd_.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_.get(), 0, 1,
                                 &descriptor_set_, 0, nullptr);
    vkd_.vkCmdPushConstants(cmd, pipeline_layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                            sizeof push, &push);
    if (queries) vkd_.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 0);
    vkd_.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, primary_pipeline_.get());
    vkd_.vkCmdDispatch(cmd, groups, 1, 1);
    if (queries) vkd_.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);

    // Shading reads the G-buffer the camera-ray kernel just wrote and adds
    // to the pixel flags it may have set.
    barrier(kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute, kShaderReadWrite);
    vkd_.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, shade_pipeline_.get());
    if (lightcuts_) {
        // Every cut from the roots to the end in one dispatch, or in
        // dispatches of refine_budget_ refinements each.
        push.refine_budget = refine_budget_;
        for (std::uint32_t d = 0; d < dispatches; ++d) {
            if (d > 0)
                // The cuts continue from the state the previous dispatch saved.
                barrier(kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute, kShaderReadWrite);
            push.cut_flags = (d == 0 ? gpu::kCutFirstDispatch : 0u) |
                             (d + 1 == dispatches ? gpu::kCutLastDispatch : 0u);
            vkd_.vkCmdPushConstants(cmd, pipeline_layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                                    sizeof push, &push);
            vkd_.vkCmdDispatch(cmd, groups, 1, 1);
            if (queries)
                vkd_.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 2 + d);
        }
    } else {
        // Brute force in ranges of light_chunk_ lights (all of them unless
        // the driver's loop limit forced smaller ranges).
        for (std::uint32_t d = 0; d < dispatches; ++d) {
            const std::uint32_t first_light = d * light_chunk_;
            if (d > 0)
                // Each range adds to the sums the previous range wrote.
                barrier(kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute, kShaderReadWrite);
            push.light_first = first_light;
            push.frame.light_count =
                std::min(light_chunk_, frame_.light_count - std::min(first_light, frame_.light_count));
            vkd_.vkCmdPushConstants(cmd, pipeline_layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                                    sizeof push, &push);
            vkd_.vkCmdDispatch(cmd, groups, 1, 1);
            if (queries)
                vkd_.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 2 + d);
        }
    }

    if (!last) return;
    if (radiance_readback_.get() == VK_NULL_HANDLE) {
        // The host reads the tile's sums straight from mapped memory after the fence.
        barrier(kCompute, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
        return;
    }
    // The copies below read the tile's final sums.
    barrier(kCompute, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy radiance_region{0, 0, VkDeviceSize(pixels) * 3 * sizeof(float)};
    vkd_.vkCmdCopyBuffer(cmd, radiance_.get(), radiance_readback_.get(), 1, &radiance_region);
    VkBufferCopy stats_region{0, 0, VkDeviceSize(pixels) * sizeof(gpu::PixelStats)};
    vkd_.vkCmdCopyBuffer(cmd, pixel_stats_.get(), stats_readback_.get(), 1, &stats_region);
    // The host reads the copies after the fence.
    barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

double Renderer::render_tile(std::uint32_t x0, std::uint32_t y0, std::uint32_t w, std::uint32_t h,
                             RenderResult& result) {
    gpu::FrameParams frame = frame_;
    frame.tile_x = x0;
    frame.tile_y = y0;
    frame.tile_width = w;
    frame.tile_height = h;
    const std::uint32_t pixels = w * h;
    const Buffer& stats_buffer = stats_readback_.get() ? stats_readback_ : pixel_stats_;
    const auto* pixel_stats = static_cast<const gpu::PixelStats*>(stats_buffer.mapped());
    double slowest_ms = 0.0;
    for (;;) {
        for (std::uint32_t s = 0; s < frame_.spp; ++s) {
            frame.sample_index = s;
            begin(cmd_);
            record_pass(cmd_, frame, s == 0, s + 1 == frame_.spp);
            const Clock::time_point submitted = Clock::now();
            submit_and_wait(cmd_);
            const double wall_ms = seconds_since(submitted) * 1e3;

            const std::uint32_t dispatches = shading_dispatches();
            if (timestamps_) {
                // Timestamps of the pass just waited for.
                std::vector<std::uint64_t> ticks(2 + dispatches);
                VK_CHECK(vkd_.vkGetQueryPoolResults(
                    ctx_.device().get(), timestamps_.get(), 0, std::uint32_t(ticks.size()),
                    ticks.size() * sizeof ticks[0], ticks.data(), sizeof ticks[0],
                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
                const std::uint32_t bits = ctx_.timestamp_valid_bits();
                const std::uint64_t mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
                const double seconds_per_tick = ctx_.timestamp_period() * 1e-9;
                auto seconds = [&](std::size_t from, std::size_t to) {
                    return double((ticks[to] - ticks[from]) & mask) * seconds_per_tick;
                };
                seconds_primary_ += seconds(0, 1);
                seconds_shading_ += seconds(1, ticks.size() - 1);
                double slowest = seconds(0, 1);
                for (std::size_t q = 1; q + 1 < ticks.size(); ++q)
                    slowest = std::max(slowest, seconds(q, q + 1));
                slowest_ms = std::max(slowest_ms, slowest * 1e3);
            } else {
                slowest_ms = std::max(slowest_ms, wall_ms / (1 + dispatches));
            }
            samples_done_ += pixels;
            report_progress(false);
        }

        // The stats of the tile's last pass (its fence has signalled).
        std::uint32_t cut_short = 0;
        for (std::uint32_t i = 0; i < pixels; ++i) {
            const std::uint32_t flags = pixel_stats[i].flags;
            // A loop cut short leaves anything behind: that is retried first.
            if (flags & gpu::kPixelLoopLimit) {
                cut_short += 1;
                continue;
            }
            if (flags & (gpu::kPixelHeapOverflow | gpu::kPixelCutUnfinished))
                throw std::logic_error(
                    std::string("Lightcuts kernel: ") +
                    (flags & gpu::kPixelHeapOverflow ? "heap outgrew its capacity"
                                                     : "cut unfinished after the last dispatch") +
                    " at pixel (" + std::to_string(x0 + i % w) + ", " +
                    std::to_string(y0 + i / w) + ")");
        }
        if (cut_short == 0) break;
        // lavapipe ends an invocation's loops after 65535 iterations in all.
        // The work per invocation then shrinks (brute force: fewer lights
        // per dispatch; Lightcuts: fewer refinements per dispatch) and the
        // tile starts again.
        const bool can_shrink = lightcuts_ ? refine_budget_ > 1 : light_chunk_ > 1;
        if (!can_shrink)
            throw std::runtime_error(
                "the Vulkan device " + ctx_.device_name() + " cut the kernels' loops short at " +
                std::to_string(cut_short) + " pixel(s) of tile (" + std::to_string(x0) + ", " +
                std::to_string(y0) + ", " + std::to_string(w) + "x" + std::to_string(h) +
                ") even for the smallest split of the work (llvmpipe/lavapipe stops every "
                "shader invocation after 65535 loop iterations)");
        if (lightcuts_)
            refine_budget_ = refine_budget_ == gpu::kUnlimitedRefinements
                                 ? 128
                                 : std::max(1u, refine_budget_ / 4);
        else
            light_chunk_ = std::max(1u, light_chunk_ / 4);
        samples_done_ -= std::uint64_t(pixels) * frame_.spp;
    }

    // Read back the tile's sums.
    const Buffer& radiance = radiance_readback_.get() ? radiance_readback_ : radiance_;
    const float* sums = static_cast<const float*>(radiance.mapped());
    const float spp = float(frame_.spp);
    RenderStats& out = result.stats;
    for (std::uint32_t i = 0; i < pixels; ++i) {
        const std::uint32_t x = x0 + i % w, y = y0 + i / w;
        result.image.set(x, y, glm::vec3(sums[3 * i], sums[3 * i + 1], sums[3 * i + 2]) / spp);
        const gpu::PixelStats& ps = pixel_stats[i];
        out.shadow_rays += ps.shadow_rays;
        out.max_cut_pixels += ps.max_cut_samples;
        out.heap_spill_pixels += ps.spill_samples;
        if (lightcuts_)
            out.cut_size[std::size_t(y) * frame_.width + x] = float(ps.cut_size_sum) / spp;
    }
    return slowest_ms;
}

void Renderer::report_progress(bool done) {
    if (done) {
        progress_.finish();
        return;
    }
    progress_.update(samples_total_ ? double(samples_done_) / double(samples_total_) : 1.0);
}

RenderResult Renderer::run() {
    RenderResult result;
    result.image = Image(frame_.width, frame_.height);
    RenderStats& stats = result.stats;
    stats.device = ctx_.device_name();
    if (lightcuts_) stats.cut_size.assign(std::size_t(frame_.width) * frame_.height, 0.0f);
    if (frame_.width == 0 || frame_.height == 0) return result;

    bvh_nodes_ = upload("bvh nodes", prepared_.bvh.nodes);
    triangles_ = upload("triangles", prepared_.scene.triangles);
    normals_ = upload("normals", prepared_.scene.normals);
    materials_ = upload("materials", prepared_.scene.materials);
    lights_ = upload("lights", prepared_.tree.lights);
    light_nodes_ = upload("light tree nodes", prepared_.tree.nodes);

    choose_heap_and_tiles();
    const VkDeviceSize n = tiles_.invocations;
    gbuffer_ = storage_buffer("g-buffer", n * sizeof(gpu::GBufferTexel), MemoryUse::kDevice);
    radiance_ = storage_buffer("radiance", n * 3 * sizeof(float), MemoryUse::kDevice,
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    pixel_stats_ = storage_buffer("pixel stats", n * sizeof(gpu::PixelStats), MemoryUse::kDevice,
                                  VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    const VkDeviceSize heap_slots = lightcuts_ ? n * heap_capacity_ : 1;
    heap_spill_ = storage_buffer("heap spill", heap_slots * sizeof(gpu::CutEntry),
                                 MemoryUse::kDevice);
    cut_states_ = storage_buffer("cut state", (lightcuts_ ? n : 1) * sizeof(gpu::CutState),
                                 MemoryUse::kDevice);
    if (!radiance_.mapped() || !pixel_stats_.mapped()) {
        radiance_readback_ = storage_buffer("radiance read-back", radiance_.size(),
                                            MemoryUse::kReadback, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        stats_readback_ = storage_buffer("pixel stats read-back", pixel_stats_.size(),
                                         MemoryUse::kReadback, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    }
    create_descriptors();
    create_pipelines();

    // Tiles: bands of rows, each cut into tiles of about `budget` pixels.
    // The budget adapts so one dispatch takes about target_dispatch_ms
    // (growing at most 2x per tile, as the next tile may be harder):
    // starting small keeps the first dispatch short on any device.
    const std::uint32_t width = frame_.width, height = frame_.height;
    samples_total_ = std::uint64_t(width) * height * frame_.spp;
    double budget = std::min<double>(4 * kWorkgroupSize, tiles_.max_pixels);
    for (std::uint32_t y0 = 0; y0 < height;) {
        const std::uint32_t band = std::min<std::uint32_t>(
            height - y0, std::max<std::uint32_t>(1, std::uint32_t(std::sqrt(budget))));
        for (std::uint32_t x0 = 0; x0 < width;) {
            std::uint32_t w = std::max<std::uint32_t>(1, std::uint32_t(budget / band));
            w = std::min({w, width - x0, std::max<std::uint32_t>(1, tiles_.max_pixels / band)});
            const double ms = render_tile(x0, y0, w, band, result);
            const double pixels = double(w) * band;
            const double wanted = ms > 0.0 ? pixels * tuning_.target_dispatch_ms / ms : 4 * budget;
            budget = std::clamp(wanted, budget / 4, budget * 2);
            budget = std::clamp(budget, 1.0, double(tiles_.max_pixels));
            x0 += w;
        }
        y0 += band;
    }
    report_progress(true);

    stats.camera_rays = std::uint64_t(width) * height * frame_.spp;
    stats.heap_capacity_shared = lightcuts_ ? heap_shared_ : 0;
    stats.seconds_primary = seconds_primary_;
    stats.seconds_shading = seconds_shading_;
    stats.buffer_bytes = buffer_bytes_;
    return result;
}

}  // namespace

Tuning Tuning::from_environment() {
    Tuning tuning;
    if (const char* v = std::getenv("LC_VK_FORCE_FEATURES")) {
        const std::string features = v;
        const bool all = features.find("all") != std::string::npos;
        tuning.force_ggx = all || features.find("ggx") != std::string::npos;
        tuning.force_shadows = all || features.find("shadows") != std::string::npos;
    }
    if (const char* v = std::getenv("LC_VK_MAX_TILE_PIXELS"))
        tuning.max_tile_pixels = std::uint32_t(std::strtoul(v, nullptr, 10));
    if (const char* v = std::getenv("LC_VK_LIGHTS_PER_DISPATCH"))
        tuning.lights_per_dispatch = std::uint32_t(std::strtoul(v, nullptr, 10));
    if (const char* v = std::getenv("LC_VK_REFINEMENTS_PER_DISPATCH"))
        tuning.refinements_per_dispatch = std::uint32_t(std::strtoul(v, nullptr, 10));
    if (const char* v = std::getenv("LC_VK_TARGET_MS")) {
        const double ms = std::strtod(v, nullptr);
        if (ms > 0.0) tuning.target_dispatch_ms = ms;
    }
    return tuning;
}

RenderResult render_vulkan(const PreparedScene& prepared, const RenderOptions& options,
                           const VulkanOptions& vulkan, const Tuning& tuning) {
    const Clock::time_point start = Clock::now();
    MessageLog log;
    RenderResult result;
    try {
        // Everything Vulkan is destroyed at the end of this block, so the
        // messages of object destruction are in the log before it is read.
        Context context(vulkan, &log);
        Renderer renderer(context, prepared, options, tuning);
        result = renderer.run();
    } catch (const std::exception& e) {
        if (log.count() == 0) throw;
        std::string message = e.what();
        for (const std::string& m : log.messages()) message += "\n  validation " + m;
        throw std::runtime_error(message);
    }
    if (log.count() > 0) {
        std::string message = "Vulkan validation reported " + std::to_string(log.count()) +
                              " message(s):";
        for (const std::string& m : log.messages()) message += "\n  " + m;
        throw std::runtime_error(message);
    }
    result.stats.seconds_total = seconds_since(start);
    return result;
}

}  // namespace lc::vk

namespace lc {

RenderResult render_vulkan(const PreparedScene& prepared, const RenderOptions& options,
                           const VulkanOptions& vulkan) {
    return vk::render_vulkan(prepared, options, vulkan, vk::Tuning::from_environment());
}

}  // namespace lc
