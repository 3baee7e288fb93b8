// One sample of one tile as one submission: zero the tile's sums (first
// sample), trace the camera rays into the G-buffer, run the shading
// method's dispatches (the one dispatch loop of the Vulkan path), and make
// the sums readable by the host (last sample).
#pragma once

#include <cstdint>

#include "gpu_resources.h"
#include "kernels.h"
#include "shading_method.h"
#include "vk_commands.h"

namespace lc::vk {

// GPU time of one pass (timestamps; zero without them) and its slowest
// dispatch, from timestamps or else from the wall time.
struct PassTiming {
    double seconds_primary = 0.0;
    double seconds_shading = 0.0;
    double slowest_dispatch_ms = 0.0;  // camera rays or shading
    double slowest_shading_ms = 0.0;
};

class TilePass {
public:
    // spread_groups: workgroups take the tile's blocks in the order of
    // workgroup_stride instead of tile order (PushConstants::group_stride).
    TilePass(const Context& ctx, const GpuResources& resources, const Kernels& kernels,
             const ShadingMethod& method, Timestamps& timestamps, bool spread_groups);

    // Records the pass of sample tile.sample_index over the tile that `tile`
    // names (its tile_* fields; the rest is filled per dispatch). `first`:
    // the tile's sums start from zero; otherwise the kernels add to what the
    // buffers hold. `last`: the host reads the sums after this pass
    // (GpuResources::radiance_sums, pixel_stats_sums).
    void record(VkCommandBuffer cmd, const gpu::PushConstants& tile, bool first, bool last);
    // Records, submits and waits for one pass.
    PassTiming run(Submitter& submitter, const gpu::PushConstants& tile, bool first, bool last);

private:
    void barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src,
                 VkPipelineStageFlags dst_stage, VkAccessFlags dst) const;
    void record_shading(VkCommandBuffer cmd, gpu::PushConstants push, std::uint32_t groups);
    void record_readback(VkCommandBuffer cmd, std::uint32_t pixels);

    const VolkDeviceTable& vkd_;
    const GpuResources& resources_;
    const Kernels& kernels_;
    const ShadingMethod& method_;
    Timestamps& timestamps_;  // 0 before camera rays, then one after every dispatch
    bool spread_groups_;
};

// The stride of PushConstants::group_stride for a dispatch of `groups`
// workgroups: coprime to groups and near groups / golden ratio, so that
// every contiguous range of workgroups shades blocks spread over the whole
// tile; 1 (tile order) for fewer than 3 workgroups or more than 65536.
std::uint32_t workgroup_stride(std::uint32_t groups);

}  // namespace lc::vk
