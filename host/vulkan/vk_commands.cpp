#include "vk_commands.h"

#include "vk_check.h"

namespace lc::vk {

namespace {

// A submission that takes longer than this is treated as a hung device.
constexpr std::uint64_t kFenceTimeoutNs = 600ull * 1000 * 1000 * 1000;

}  // namespace

Submitter::Submitter(const Context& ctx) : ctx_(ctx) {
    const VolkDeviceTable& vkd = ctx.fn();
    VkDevice device = ctx.device().get();
    auto pool_info = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = ctx.queue_family();
    VkCommandPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateCommandPool(device, &pool_info, nullptr, &pool));
    pool_ = own<CommandPool>(ctx.device(), pool, "command pool");

    auto cmd_info = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    cmd_info.commandPool = pool;
    cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmd_info.commandBufferCount = 1;
    VK_CHECK(vkd.vkAllocateCommandBuffers(device, &cmd_info, &cmd_));
    ctx.device().set_name(cmd_, "render commands");

    auto fence_info = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    VkFence fence = VK_NULL_HANDLE;
    VK_CHECK(vkd.vkCreateFence(device, &fence_info, nullptr, &fence));
    fence_ = own<Fence>(ctx.device(), fence, "submission fence");
}

VkCommandBuffer Submitter::begin() {
    auto begin_info = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(ctx_.fn().vkBeginCommandBuffer(cmd_, &begin_info));
    return cmd_;
}

void Submitter::submit_and_wait() {
    const VolkDeviceTable& vkd = ctx_.fn();
    VK_CHECK(vkd.vkEndCommandBuffer(cmd_));
    auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd_;
    VkFence fence = fence_.get();
    VK_CHECK(vkd.vkQueueSubmit(ctx_.queue(), 1, &submit, fence));
    VK_CHECK(vkd.vkWaitForFences(ctx_.device().get(), 1, &fence, VK_TRUE, kFenceTimeoutNs));
    VK_CHECK(vkd.vkResetFences(ctx_.device().get(), 1, &fence));
}

Timestamps::Timestamps(const Context& ctx) : ctx_(ctx) {}

void Timestamps::reset(VkCommandBuffer cmd, std::uint32_t count) {
    if (!available()) return;
    if (count > capacity_) {
        // The previous submission has finished (the host waited for it), so
        // its pool can go.
        auto info = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
        info.queryType = VK_QUERY_TYPE_TIMESTAMP;
        info.queryCount = count;
        VkQueryPool pool = VK_NULL_HANDLE;
        VK_CHECK(ctx_.fn().vkCreateQueryPool(ctx_.device().get(), &info, nullptr, &pool));
        pool_ = own<QueryPool>(ctx_.device(), pool, "dispatch timestamps");
        capacity_ = count;
    }
    ctx_.fn().vkCmdResetQueryPool(cmd, pool_.get(), 0, count);
}

void Timestamps::write(VkCommandBuffer cmd, std::uint32_t index) const {
    if (!available()) return;
    ctx_.fn().vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), index);
}

std::vector<double> Timestamps::intervals(std::uint32_t count) const {
    if (!available() || count < 2) return {};
    // Host read-back of the timestamps of the submission just waited for.
    std::vector<std::uint64_t> ticks(count);
    VK_CHECK(ctx_.fn().vkGetQueryPoolResults(ctx_.device().get(), pool_.get(), 0, count,
                                             ticks.size() * sizeof ticks[0], ticks.data(),
                                             sizeof ticks[0],
                                             VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const std::uint32_t bits = ctx_.timestamp_valid_bits();
    const std::uint64_t mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
    const double seconds_per_tick = ctx_.timestamp_period() * 1e-9;
    std::vector<double> seconds(count - 1);
    for (std::uint32_t i = 0; i + 1 < count; ++i)
        seconds[i] = double((ticks[i + 1] - ticks[i]) & mask) * seconds_per_tick;
    return seconds;
}

}  // namespace lc::vk
