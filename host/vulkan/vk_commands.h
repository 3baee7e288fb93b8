// Submitting work and timing it: the one command buffer every submission is
// recorded into, the fence the host waits on, and the timestamp queries
// around the dispatches of a pass.
#pragma once

#include <cstdint>
#include <vector>

#include "vk_context.h"

namespace lc::vk {

// One primary command buffer, re-recorded for every submission; the host
// waits for each submission before it records the next, so one suffices.
class Submitter {
public:
    explicit Submitter(const Context& ctx);

    // Starts recording (one-time submit) and returns the command buffer.
    VkCommandBuffer begin();
    // Ends recording, submits, and waits until the device has finished.
    void submit_and_wait();

private:
    const Context& ctx_;
    CommandPool pool_;                    // frees cmd_ with it
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    Fence fence_;
};

// GPU timestamps written between the dispatches of one submission. On a
// device whose compute queue has no timestamps every call is a no-op and
// available() is false.
class Timestamps {
public:
    explicit Timestamps(const Context& ctx);

    bool available() const { return ctx_.timestamp_valid_bits() > 0; }
    // Makes room for `count` timestamps and resets them in `cmd`.
    void reset(VkCommandBuffer cmd, std::uint32_t count);
    void write(VkCommandBuffer cmd, std::uint32_t index) const;
    // Seconds from each of timestamps 0 .. count-2 to the next, as written by
    // the submission just waited for.
    std::vector<double> intervals(std::uint32_t count) const;

private:
    const Context& ctx_;
    QueryPool pool_;
    std::uint32_t capacity_ = 0;
};

}  // namespace lc::vk
