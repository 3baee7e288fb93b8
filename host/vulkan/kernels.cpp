#include "kernels.h"

#include <stdint.h>  // the generated SPIR-V headers use ::uint32_t

#include <algorithm>
#include <cstddef>
#include <future>
#include <string>
#include <vector>

#include "spirv/primary.h"
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
    std::uint32_t chunk_shift[gpu::kSceneArrayCount];
};

Pipeline compute_pipeline(const Context& ctx, VkPipelineLayout layout, const KernelCode& code,
                          const SpecData& spec) {
    VkDevice device = ctx.device().get();
    const VolkDeviceTable& vkd = ctx.fn();
    const std::string name = code.name;
    auto module_info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    module_info.codeSize = code.bytes;
    module_info.pCode = code.words;
    VkShaderModule module_handle = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateShaderModule(device, &module_info, nullptr, &module_handle));
    ShaderModule module = own<ShaderModule>(ctx.device(), module_handle, name + " module");

    std::vector<VkSpecializationMapEntry> entries = {
        {gpu::kSpecWorkgroupSize, offsetof(SpecData, workgroup_size), sizeof(std::uint32_t)},
        {gpu::kSpecEnableGgx, offsetof(SpecData, enable_ggx), sizeof(VkBool32)},
        {gpu::kSpecEnableShadows, offsetof(SpecData, enable_shadows), sizeof(VkBool32)},
        {gpu::kSpecHeapSlots, offsetof(SpecData, heap_slots), sizeof(std::uint32_t)},
        {gpu::kSpecEnableOriented, offsetof(SpecData, enable_oriented), sizeof(VkBool32)},
        {gpu::kSpecStochastic, offsetof(SpecData, stochastic), sizeof(VkBool32)},
        {gpu::kSpecEnableTextures, offsetof(SpecData, enable_textures), sizeof(VkBool32)},
        {gpu::kSpecEnableDisney, offsetof(SpecData, enable_disney), sizeof(VkBool32)},
        {gpu::kSpecEnableSheen, offsetof(SpecData, enable_sheen), sizeof(VkBool32)},
        {gpu::kSpecEnableClearcoat, offsetof(SpecData, enable_clearcoat), sizeof(VkBool32)},
        {gpu::kSpecSplitScene, offsetof(SpecData, split_scene), sizeof(VkBool32)},
        {gpu::kSpecTexelReads, offsetof(SpecData, texel_reads), sizeof(VkBool32)},
    };
    for (std::uint32_t b = 0; b < gpu::kSceneArrayCount; ++b)
        entries.push_back({gpu::kSpecChunkShift + b,
                           std::uint32_t(offsetof(SpecData, chunk_shift) + b * sizeof(std::uint32_t)),
                           sizeof(std::uint32_t)});
    VkSpecializationInfo spec_info{};
    spec_info.mapEntryCount = std::uint32_t(entries.size());
    spec_info.pMapEntries = entries.data();
    spec_info.dataSize = sizeof spec;
    spec_info.pData = &spec;

    auto info = vk_struct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module.get();
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = &spec_info;
    info.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
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
    for (std::uint32_t b = 0; b < gpu::kSceneArrayCount; ++b) spec.chunk_shift[b] = switches.chunks.shift[b];
    // Both pipelines at once: a driver that compiles on the host (lavapipe:
    // about 0.17 s for the camera-ray kernel, 0.86 s for Lightcuts') gets a
    // core for each. vkCreateComputePipelines may run on several threads
    // without a pipeline cache.
    std::future<Pipeline> primary = std::async(std::launch::async, [&] {
        return compute_pipeline(ctx, layout,
                                {lc_spirv_primary, sizeof lc_spirv_primary, "primary.comp (camera rays)"}, spec);
    });
    shading_ = compute_pipeline(ctx, layout, method.kernel(), spec);
    primary_ = primary.get();
}

}  // namespace lc::vk
