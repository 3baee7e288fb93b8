#include "shading_method.h"

#include <stdint.h>  // the generated SPIR-V headers use ::uint32_t

#include <algorithm>
#include <stdexcept>

#include "spirv/brute.h"
#include "spirv/lightcuts.h"

namespace lc::vk {

namespace {

// Brute force: every light at every pixel, in one dispatch or in ranges of
// lights, one dispatch per range, each adding to the pixel's sum.
class BruteForce final : public ShadingMethod {
public:
    BruteForce(const gpu::FrameParams& frame, const Tuning& tuning)
        : light_count_(frame.light_count), chunk_(std::max(frame.light_count, 1u)) {
        if (tuning.lights_per_dispatch > 0) chunk_ = std::min(chunk_, tuning.lights_per_dispatch);
    }

    KernelCode kernel() const override {
        return {lc_spirv_brute, sizeof lc_spirv_brute, "brute.comp (all lights)"};
    }

    std::uint32_t dispatch_count() const override {
        return std::max(1u, (light_count_ + chunk_ - 1) / chunk_);
    }

    void set_push_constants(std::uint32_t d, gpu::PushConstants& push) const override {
        const std::uint32_t first = std::min(d * chunk_, light_count_);
        push.light_first = first;
        push.light_count = std::min(chunk_, light_count_ - first);
    }

    // Each invocation loops over its range of lights (plus the BVH of each
    // shadow ray), so a quarter of the range is well under the limit that
    // the whole range went over.
    bool split_finer() override {
        if (chunk_ <= 1) return false;
        chunk_ = std::max(1u, chunk_ / 4);
        return true;
    }

private:
    std::uint32_t light_count_;
    std::uint32_t chunk_;  // lights per dispatch
};

// The first refinement budget when the driver's loop limit forces a split.
constexpr std::uint32_t kFirstRefineBudget = 128;

// Lightcuts: every cut from the roots to the end in one dispatch, or a
// budget of refinements per dispatch, the cut paused in CutState and the
// heap's spill buffer in between.
class Lightcuts final : public ShadingMethod {
public:
    Lightcuts(const gpu::FrameParams& frame, const LightTree& tree, const Tuning& tuning,
              std::uint32_t shared_memory_bytes)
        : max_cut_(frame.max_cut) {
        // Walter 2005 §4 keeps a max-heap of the refinable clusters of the
        // cut; the tree bounds its size, whatever max_cut says. The first K
        // slots live in shared memory, as many as fit a whole workgroup.
        heap_.capacity = tree.cut_heap_capacity(frame.max_cut);
        const std::uint32_t k_max =
            shared_memory_bytes / (gpu::kWorkgroupSize * std::uint32_t(sizeof(gpu::CutEntry)));
        if (k_max == 0)
            throw std::runtime_error("Vulkan device has too little shared memory (" +
                                     std::to_string(shared_memory_bytes) +
                                     " bytes) for the cut heap");
        heap_.shared = std::min(k_max, heap_.capacity);
        // A refinement adds one cluster to the cut and takes one interior
        // node off the heap for good, so a cut never sees more refinements
        // than either allows.
        const std::uint64_t interior = tree.nodes.size() - tree.lights.size();
        max_refinements_ = std::uint32_t(std::min<std::uint64_t>(frame.max_cut, interior));
        if (tuning.refinements_per_dispatch > 0) budget_ = tuning.refinements_per_dispatch;
    }

    KernelCode kernel() const override {
        return {lc_spirv_lightcuts, sizeof lc_spirv_lightcuts,
                "lightcuts.comp (cut selection + shading)"};
    }
    HeapLayout heap() const override { return heap_; }
    TileBuffer heap_spill() const override {
        return {"heap spill", std::uint64_t(heap_.capacity) * sizeof(gpu::CutEntry),
                std::to_string(heap_.capacity) + " heap slots per pixel for max_cut " +
                    std::to_string(max_cut_)};
    }
    TileBuffer cut_state() const override { return {"cut state", sizeof(gpu::CutState), ""}; }
    bool reports_cuts() const override { return true; }

    // max_refinements / budget + 1 dispatches of `budget` refinements each
    // finish every cut (the last one also finds it final).
    std::uint32_t dispatch_count() const override {
        return budget_ == gpu::kUnlimitedRefinements ? 1 : max_refinements_ / budget_ + 1;
    }

    void set_push_constants(std::uint32_t d, gpu::PushConstants& push) const override {
        push.refine_budget = budget_;
        push.cut_flags = (d == 0 ? gpu::kCutFirstDispatch : 0u) |
                         (d + 1 == dispatch_count() ? gpu::kCutLastDispatch : 0u);
    }

    bool split_finer() override {
        if (budget_ <= 1) return false;
        budget_ = budget_ == gpu::kUnlimitedRefinements ? kFirstRefineBudget
                                                        : std::max(1u, budget_ / 4);
        return true;
    }

private:
    std::uint32_t max_cut_;
    HeapLayout heap_;
    std::uint32_t max_refinements_ = 0;
    std::uint32_t budget_ = gpu::kUnlimitedRefinements;  // refinements per dispatch
};

}  // namespace

std::unique_ptr<ShadingMethod> make_shading_method(const RenderOptions& options,
                                                   const gpu::FrameParams& frame,
                                                   const LightTree& tree, const Tuning& tuning,
                                                   std::uint32_t shared_memory_bytes) {
    if (options.method == "lightcuts")
        return std::make_unique<Lightcuts>(frame, tree, tuning, shared_memory_bytes);
    return std::make_unique<BruteForce>(frame, tuning);
}

}  // namespace lc::vk
