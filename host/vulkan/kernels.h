// The two compute pipelines of a render: camera rays (primary.comp) and the
// shading method's kernel, both specialised for the scene and the device
// (specialization constants of shaders/bindings.glsl).
#pragma once

#include <cstdint>

#include "bindings.glsl"

#include "shading_method.h"
#include "vk_context.h"

namespace lc::vk {

// Values of the specialization constants that do not come from the method.
// How the scene arrays are split into chunks (shaders/kernel.glsl,
// LC_SCENE_ARRAY): the kernels' specialization constants kSplitScene and
// kSpecChunkShift + binding.
struct SceneChunks {
    bool split = false;  // some array has more than one chunk
    // log2 of the elements per chunk of the array at each binding; 31 for an
    // array in one buffer (no index reaches 2^31).
    std::uint32_t shift[gpu::kSceneArrayCount];
    SceneChunks() {
        for (std::uint32_t& s : shift) s = 31;
    }
};

struct KernelSwitches {
    bool ggx = true;                 // compile the GGX lobe in
    bool shadows = true;             // compile shadow rays in
    bool oriented = true;            // compile spot and oriented lights (emission cones) in
    bool textures = true;            // compile texture lookups in
    bool disney = true;              // compile the Disney BRDF in
    bool sheen = true;               // ... and its sheen lobe
    bool clearcoat = true;           // ... and its clearcoat lobe
    bool texel_reads = false;        // read five scene arrays through their texel views
    SceneChunks chunks;              // how the scene arrays are split (GpuResources)
    bool specialize_on_host = false; // hand the driver modules specialized on the host (spirv_specialize.h)
    bool heap_private = false;       // the cut heaps in private memory instead of shared memory (heap.glsl)
};

class Kernels {
public:
    Kernels(const Context& ctx, VkPipelineLayout layout, const ShadingMethod& method,
            const KernelSwitches& switches);

    VkPipeline primary() const { return primary_.get(); }
    VkPipeline shading() const { return shading_.get(); }

private:
    Pipeline primary_, shading_;
};

}  // namespace lc::vk
