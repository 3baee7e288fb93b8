#include "tile_pass.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <utility>

namespace lc::vk {

namespace {

constexpr VkPipelineStageFlags kCompute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
constexpr VkPipelineStageFlags kComputeAndTransfer =
    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
constexpr VkAccessFlags kShaderReadWrite = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;

}  // namespace

std::uint32_t workgroup_stride(std::uint32_t groups) {
    // (groups - 1) * stride must stay below 2^32 in the kernels' arithmetic.
    if (groups < 3u || groups > 65536u) return 1u;
    // Of the strides within 64 of groups / golden ratio, the one whose
    // ratio to groups has the smallest largest partial quotient in its
    // continued fraction (1/phi's are all 1), the nearest of those: any run
    // of j then spreads j * stride mod groups evenly over the tile, where a
    // ratio close to a simple fraction (53/88 ~ 3/5) clusters it. Euclid's
    // algorithm gives the quotients and the gcd, which must be 1.
    const double centre = groups * 0.6180339887498949;
    std::uint32_t best = 1u, best_quotient = UINT32_MAX;
    double best_distance = 0.0;
    const std::uint32_t c = std::uint32_t(centre);
    const std::uint32_t lo = c > 64u ? c - 64u : 1u, hi = std::min(groups - 1u, c + 64u);
    for (std::uint32_t stride = lo; stride <= hi; ++stride) {
        std::uint32_t a = groups, b = stride, largest = 0u;
        while (b != 0u) {
            largest = std::max(largest, a / b);
            a = std::exchange(b, a % b);
        }
        if (a != 1u) continue;  // not coprime
        const double distance = std::abs(double(stride) - centre);
        if (largest < best_quotient || (largest == best_quotient && distance < best_distance)) {
            best = stride;
            best_quotient = largest;
            best_distance = distance;
        }
    }
    return best;
}

TilePass::TilePass(const Context& ctx, const GpuResources& resources, const Kernels& kernels,
                   const ShadingMethod& method, Timestamps& timestamps, bool spread_groups)
    : vkd_(ctx.fn()),
      resources_(resources),
      kernels_(kernels),
      method_(method),
      timestamps_(timestamps),
      spread_groups_(spread_groups) {}

void TilePass::barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src,
                       VkPipelineStageFlags dst_stage, VkAccessFlags dst) const {
    auto b = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    vkd_.vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
}

void TilePass::record(VkCommandBuffer cmd, const gpu::PushConstants& tile, bool first, bool last) {
    const std::uint32_t pixels = tile.tile_width * tile.tile_height;
    const std::uint32_t groups = (pixels + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize;
    timestamps_.reset(cmd, 2 + method_.dispatch_count());

    // The previous submission's kernels and copies (or whatever the caller
    // wrote with a transfer) are done with the tile buffers before this one
    // reads and overwrites them.
    barrier(cmd, kComputeAndTransfer, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
            kComputeAndTransfer,
            kShaderReadWrite | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
    if (first) {
        vkd_.vkCmdFillBuffer(cmd, resources_.radiance().get(), 0, VK_WHOLE_SIZE, 0);
        vkd_.vkCmdFillBuffer(cmd, resources_.pixel_stats().get(), 0, VK_WHOLE_SIZE, 0);
        // The kernels add to the sums the fills just zeroed.
        barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, kCompute,
                kShaderReadWrite);
    }

    gpu::PushConstants push = tile;
    push.light_first = 0;
    push.light_count = 0;
    push.cut_flags = 0;
    push.refine_budget = gpu::kUnlimitedRefinements;
    push.heap_save_stride = resources_.tiles().invocations;
    push.group_stride = spread_groups_ ? workgroup_stride(groups) : 1u;
    VkPipelineLayout layout = resources_.pipeline_layout();
    VkDescriptorSet set = resources_.descriptor_set();
    vkd_.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkd_.vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    timestamps_.write(cmd, 0);
    vkd_.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, kernels_.primary());
    vkd_.vkCmdDispatch(cmd, groups, 1, 1);
    timestamps_.write(cmd, 1);

    // Shading reads the G-buffer the camera-ray kernel just wrote and adds
    // to the pixel flags it may have set.
    barrier(cmd, kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute, kShaderReadWrite);
    const std::uint32_t shading_groups =
        (method_.invocations(tile.tile_width, tile.tile_height) + gpu::kWorkgroupSize - 1) / gpu::kWorkgroupSize;
    push.group_stride = spread_groups_ ? workgroup_stride(shading_groups) : 1u;
    record_shading(cmd, push, shading_groups);
    if (last) record_readback(cmd, pixels);
}

// All of one sample's shading, in as many dispatches as the method's split
// asks for, each continuing from what the previous one wrote.
void TilePass::record_shading(VkCommandBuffer cmd, gpu::PushConstants push, std::uint32_t groups) {
    vkd_.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, kernels_.shading());
    const std::uint32_t dispatches = method_.dispatch_count();
    for (std::uint32_t d = 0; d < dispatches; ++d) {
        if (d > 0)
            // This dispatch adds to the sums, and resumes the cuts, that the
            // previous one wrote.
            barrier(cmd, kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute, kShaderReadWrite);
        method_.set_push_constants(d, push);
        vkd_.vkCmdPushConstants(cmd, resources_.pipeline_layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                                sizeof push, &push);
        vkd_.vkCmdDispatch(cmd, groups, 1, 1);
        timestamps_.write(cmd, 2 + d);
    }
}

void TilePass::record_readback(VkCommandBuffer cmd, std::uint32_t pixels) {
    if (!resources_.needs_readback_copies()) {
        // The host reads the tile's sums straight from mapped memory after the fence.
        barrier(cmd, kCompute, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
        return;
    }
    // The copies below read the tile's final sums.
    barrier(cmd, kCompute, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy radiance_region{0, 0, VkDeviceSize(pixels) * 3 * sizeof(float)};
    vkd_.vkCmdCopyBuffer(cmd, resources_.radiance().get(), resources_.radiance_readback().get(), 1,
                         &radiance_region);
    VkBufferCopy stats_region{0, 0, VkDeviceSize(pixels) * sizeof(gpu::PixelStats)};
    vkd_.vkCmdCopyBuffer(cmd, resources_.pixel_stats().get(), resources_.stats_readback().get(), 1,
                         &stats_region);
    // The host reads the copies after the fence.
    barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

PassTiming TilePass::run(Submitter& submitter, const gpu::PushConstants& tile, bool first,
                         bool last) {
    record(submitter.begin(), tile, first, last);
    const auto submitted = std::chrono::steady_clock::now();
    submitter.submit_and_wait();
    const double wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - submitted).count();

    const std::uint32_t dispatches = method_.dispatch_count();
    PassTiming timing;
    const std::vector<double> seconds = timestamps_.intervals(2 + dispatches);
    if (seconds.empty()) {
        timing.slowest_dispatch_ms = wall_ms / (1 + dispatches);
        timing.slowest_shading_ms = timing.slowest_dispatch_ms;
        return timing;
    }
    timing.seconds_primary = seconds[0];
    timing.seconds_shading = std::accumulate(seconds.begin() + 1, seconds.end(), 0.0);
    timing.slowest_dispatch_ms = *std::max_element(seconds.begin(), seconds.end()) * 1e3;
    timing.slowest_shading_ms = *std::max_element(seconds.begin() + 1, seconds.end()) * 1e3;
    return timing;
}

}  // namespace lc::vk
