// A shading method as the Vulkan path sees it: its kernel, the per-pixel
// buffers and cut heap it needs, and how one sample's shading of a tile
// splits into dispatches. The tile pass runs any method with one dispatch
// loop; the tile scheduler asks the method to split its work finer when the
// driver cut the kernels' loops short (docs/vulkan.md, "Work split").
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bindings.glsl"
#include "lightcuts/render.h"
#include "vulkan_renderer.h"

namespace lc::vk {

// A kernel's SPIR-V (embedded at build time) and its pipeline's debug name.
struct KernelCode {
    const std::uint32_t* words = nullptr;
    std::size_t bytes = 0;
    const char* name = "";
};

// A per-tile buffer and its bytes per tile pixel; `why` explains the size
// when the buffer cannot fit a single workgroup.
struct TileBuffer {
    std::string name;
    std::uint64_t bytes_per_pixel = 0;
    std::string why;
};

class ShadingMethod {
public:
    virtual ~ShadingMethod() = default;

    virtual KernelCode kernel() const = 0;
    // Cut-heap slots per invocation, in its private memory or in workgroup
    // shared memory (shaders/heap.glsl); 0 for a method without a heap.
    virtual std::uint32_t heap_slots() const { return 0; }
    // Bytes per tile pixel of the heap-save and cut state buffers (0: not
    // used; the binding still gets a one-element buffer).
    virtual TileBuffer heap_save() const { return {"heap save", 0, ""}; }
    virtual TileBuffer cut_state() const { return {"cut state", 0, ""}; }
    // True when the method's cut sizes go into RenderStats::cut_size.
    virtual bool reports_cuts() const { return false; }
    // The kernel's kSpecStochastic (lightcuts.comp only).
    virtual bool stochastic() const { return false; }
    // Bytes of one heap slot (CutEntry, or QuadCutEntry for quads).
    virtual std::uint32_t heap_entry_bytes() const { return sizeof(gpu::CutEntry); }
    // True when the kernel shares each cut between the four pixels of a
    // 2x2 quad (quadcuts.comp): tiles then start at even pixels, and the
    // shading dispatch has one invocation per quad lane.
    virtual bool quad_cuts() const { return false; }
    // Shading invocations for a tile of width x height pixels.
    std::uint32_t invocations(std::uint32_t width, std::uint32_t height) const {
        return quad_cuts() ? 4u * ((width + 1u) / 2u) * ((height + 1u) / 2u) : width * height;
    }

    // Dispatches one sample's shading takes with the current split.
    virtual std::uint32_t dispatch_count() const = 0;
    // Fills in what dispatch `d` of dispatch_count() does; `push` holds the
    // tile's frame constants on entry.
    virtual void set_push_constants(std::uint32_t d, gpu::PushConstants& push) const = 0;
    // The driver cut an invocation's loops short: give each dispatch less
    // work. False when the work is already split as finely as it can be.
    virtual bool split_finer() = 0;
};

// "brute", "lightcuts", "sampled" or "stochastic" (options.method, already
// validated).
// `shared_memory_bytes` is the device's maxComputeSharedMemorySize; `quads`
// selects quadcuts.comp for "lightcuts".
std::unique_ptr<ShadingMethod> make_shading_method(const RenderOptions& options,
                                                   const gpu::FrameParams& frame,
                                                   const LightTree& tree, const Tuning& tuning,
                                                   std::uint32_t shared_memory_bytes, bool quads);

}  // namespace lc::vk
