// Everything one Vulkan render builds on a device, in the order each part
// needs the others. render_vulkan runs a TileScheduler over it; kernel-level
// tests record passes on it directly.
#pragma once

#include <memory>

#include "gpu_resources.h"
#include "kernels.h"
#include "shading_method.h"
#include "tile_pass.h"
#include "vk_commands.h"
#include "vk_context.h"
#include "vulkan_renderer.h"

namespace lc::vk {

// The frame constants of a render: validates the options (throws
// std::invalid_argument) and checks that the device offers the push
// constants the kernels need.
gpu::FrameParams frame_params(const Context& ctx, const PreparedScene& prepared,
                              const RenderOptions& options);

// The tuning with the device's defaults filled in (Tuning::target_dispatch_ms,
// presplit_on_llvmpipe).
Tuning device_tuning(const Context& ctx, Tuning tuning);

// Whether Lightcuts shares each cut between the pixels of a 2x2 quad
// (quadcuts.comp): cut_sharing "quad", where the device has subgroup quad
// operations and the quad's heap fits, else std::invalid_argument saying
// why. "auto" is "pixel" on Vulkan.
bool share_cuts(const Context& ctx, const LightTree& tree, const RenderOptions& options,
                const gpu::FrameParams& frame, const Tuning& tuning);

// The smallest tile worth a pass on this device (Tuning::min_tile_pixels
// where set): Tuning::kGpuMinTilePixels on a GPU; on a CPU device enough
// workgroups to keep each of its threads busy.
std::uint32_t min_tile_pixels(const Context& ctx, const Tuning& tuning);

// scene_arrays() and then the frame constants: what the kernels read, in
// binding order.
std::vector<SceneArray> kernel_arrays(const PreparedScene& prepared, const gpu::FrameParams& frame);

// Members are built top to bottom and destroyed bottom to top, after the
// destructor has waited for the device: no submission outlives the buffers
// it uses, even when an exception unwinds mid-render.
struct RenderSetup {
    RenderSetup(const Context& context, const PreparedScene& prepared,
                const RenderOptions& options, const gpu::FrameParams& frame, const Tuning& tuning);
    ~RenderSetup();
    RenderSetup(const RenderSetup&) = delete;
    RenderSetup& operator=(const RenderSetup&) = delete;

    const Context& ctx;
    Submitter submitter;
    Timestamps timestamps;
    std::unique_ptr<ShadingMethod> method;
    GpuResources resources;
    Kernels kernels;
    TilePass pass;
};

}  // namespace lc::vk
