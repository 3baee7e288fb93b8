#include "kernels.h"

#include <stdint.h>  // the generated SPIR-V headers use ::uint32_t

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <future>
#include <string>
#include <vector>

#include "spirv/primary.h"
#include "spirv_specialize.h"
#include "vk_check.h"

namespace lc::vk {

namespace {

// Values of the kernels' specialization constants (shaders/bindings.glsl).
struct SpecData {
    std::uint32_t workgroup_size;
    VkBool32 enable_ggx;
    VkBool32 enable_shadows;
    std::uint32_t heap_slots;
    VkBool32 enable_oriented;
    VkBool32 stochastic;
    VkBool32 enable_textures;
    VkBool32 enable_disney;
    VkBool32 enable_sheen;
    VkBool32 enable_clearcoat;
    VkBool32 split_scene;
    VkBool32 texel_reads;
    VkBool32 heap_private;
    std::uint32_t chunk_shift[gpu::kSceneArrayCount];
};

// One specialization constant: its id, where SpecData holds its value, and
// whether it is a bool (VkBool32) or a 32-bit unsigned integer.
struct SpecEntry {
    std::uint32_t id;
    std::uint32_t offset;
    bool boolean;
};

std::vector<SpecEntry> spec_entries() {
    std::vector<SpecEntry> entries = {
        {gpu::kSpecWorkgroupSize, offsetof(SpecData, workgroup_size), false},
        {gpu::kSpecEnableGgx, offsetof(SpecData, enable_ggx), true},
        {gpu::kSpecEnableShadows, offsetof(SpecData, enable_shadows), true},
        {gpu::kSpecHeapSlots, offsetof(SpecData, heap_slots), false},
        {gpu::kSpecEnableOriented, offsetof(SpecData, enable_oriented), true},
        {gpu::kSpecStochastic, offsetof(SpecData, stochastic), true},
        {gpu::kSpecEnableTextures, offsetof(SpecData, enable_textures), true},
        {gpu::kSpecEnableDisney, offsetof(SpecData, enable_disney), true},
        {gpu::kSpecEnableSheen, offsetof(SpecData, enable_sheen), true},
        {gpu::kSpecEnableClearcoat, offsetof(SpecData, enable_clearcoat), true},
        {gpu::kSpecSplitScene, offsetof(SpecData, split_scene), true},
        {gpu::kSpecTexelReads, offsetof(SpecData, texel_reads), true},
        {gpu::kSpecHeapPrivate, offsetof(SpecData, heap_private), true},
    };
    for (std::uint32_t b = 0; b < gpu::kSceneArrayCount; ++b)
        entries.push_back(
            {gpu::kSpecChunkShift + b, std::uint32_t(offsetof(SpecData, chunk_shift) + b * sizeof(std::uint32_t)), false});
    return entries;
}

// The kernel's pipeline with the constants of `spec`: specialized by the
// driver, or (`on_host`) in the module itself before the driver sees it
// (spirv_specialize.h).
Pipeline compute_pipeline(const Context& ctx, VkPipelineLayout layout, const KernelCode& code,
                          const SpecData& spec, bool on_host) {
    VkDevice device = ctx.device().get();
    const VolkDeviceTable& vkd = ctx.fn();
    const std::string name = code.name;
    const std::vector<SpecEntry> entries = spec_entries();
    std::vector<VkSpecializationMapEntry> map;
    SpecValues values;
    for (const SpecEntry& e : entries) {
        map.push_back({e.id, e.offset, sizeof(std::uint32_t)});
        std::uint32_t value = 0;
        std::memcpy(&value, reinterpret_cast<const char*>(&spec) + e.offset, sizeof value);
        values[e.id] = e.boolean ? (value != 0u ? "true" : "false") : std::to_string(value);
    }
    std::vector<std::uint32_t> specialized;
    if (on_host)
        specialized =
            specialize_spirv_cached(code.words, code.bytes / sizeof(std::uint32_t), values, name, spirv_cache_dir());

    auto module_info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    module_info.codeSize = on_host ? specialized.size() * sizeof(std::uint32_t) : code.bytes;
    module_info.pCode = on_host ? specialized.data() : code.words;
    VkShaderModule module_handle = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateShaderModule(device, &module_info, nullptr, &module_handle));
    ShaderModule module = own<ShaderModule>(ctx.device(), module_handle, name + " module");

    VkSpecializationInfo spec_info{};
    spec_info.mapEntryCount = std::uint32_t(map.size());
    spec_info.pMapEntries = map.data();
    spec_info.dataSize = sizeof spec;
    spec_info.pData = &spec;

    auto info = vk_struct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module.get();
    info.stage.pName = "main";
    // A module specialized on the host has no constants left to set.
    info.stage.pSpecializationInfo = on_host ? nullptr : &spec_info;
    info.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateComputePipelines(device, ctx.pipeline_cache(), 1, &info, nullptr, &pipeline));
    return own<Pipeline>(ctx.device(), pipeline, name);
}

}  // namespace

Kernels::Kernels(const Context& ctx, VkPipelineLayout layout, const ShadingMethod& method,
                 const KernelSwitches& switches) {
    SpecData spec{};
    spec.workgroup_size = gpu::kWorkgroupSize;
    spec.enable_ggx = switches.ggx;
    spec.enable_shadows = switches.shadows;
    // Kernels without a heap do not declare its constants; any valid value does.
    spec.heap_slots = std::max(method.heap_slots(), 1u);
    spec.enable_oriented = switches.oriented;
    spec.stochastic = method.stochastic();
    spec.enable_textures = switches.textures;
    spec.enable_disney = switches.disney;
    spec.enable_sheen = switches.sheen;
    spec.enable_clearcoat = switches.clearcoat;
    spec.split_scene = switches.chunks.split;
    spec.texel_reads = switches.texel_reads;
    spec.heap_private = switches.heap_private;
    for (std::uint32_t b = 0; b < gpu::kSceneArrayCount; ++b) spec.chunk_shift[b] = switches.chunks.shift[b];
    // Both pipelines at once: a driver that compiles on the host (lavapipe:
    // about 0.20 s for Lightcuts' kernel once the host has specialized it,
    // 0.86 s when the driver specializes it, LC_VK_SPECIALIZE_ON_HOST=off)
    // gets a core for each, and so does the host's specialization.
    // vkCreateComputePipelines may run on several threads, with a pipeline
    // cache too (one made without the externally-synchronized flag).
    std::future<Pipeline> primary = std::async(std::launch::async, [&] {
        return compute_pipeline(ctx, layout,
                                {lc_spirv_primary, sizeof lc_spirv_primary, "primary.comp (camera rays)"}, spec,
                                switches.specialize_on_host);
    });
    shading_ = compute_pipeline(ctx, layout, method.kernel(), spec, switches.specialize_on_host);
    primary_ = primary.get();
}

}  // namespace lc::vk
