#include "shading_method.h"

#include <stdint.h>  // the generated SPIR-V headers use ::uint32_t

#include <algorithm>
#include <stdexcept>

#include "spirv/brute.h"
#include "spirv/lightcuts.h"
#include "spirv/quadcuts.h"
#include "spirv/sampled.h"

namespace lc::vk {

namespace {

// A method that loops over a range of items per pixel (brute force: the
// lights; sampled: the light samples), in one dispatch or in ranges, one
// dispatch per range, each adding to the pixel's sum.
class RangedMethod final : public ShadingMethod {
public:
    RangedMethod(KernelCode code, std::uint32_t items, const Tuning& tuning)
        : code_(code), items_(items), chunk_(std::max(items, 1u)) {
        if (tuning.lights_per_dispatch > 0) chunk_ = std::min(chunk_, tuning.lights_per_dispatch);
    }

    KernelCode kernel() const override { return code_; }

    std::uint32_t dispatch_count() const override {
        return std::max(1u, (items_ + chunk_ - 1) / chunk_);
    }

    void set_push_constants(std::uint32_t d, gpu::PushConstants& push) const override {
        const std::uint32_t first = std::min(d * chunk_, items_);
        push.light_first = first;
        push.light_count = std::min(chunk_, items_ - first);
    }

    // Each invocation loops over its range (plus the BVH of each shadow
    // ray), so a quarter of the range is well under the limit that the
    // whole range went over.
    bool split_finer() override {
        if (chunk_ <= 1) return false;
        chunk_ = std::max(1u, chunk_ / 4);
        return true;
    }

private:
    KernelCode code_;
    std::uint32_t items_;
    std::uint32_t chunk_;  // items per dispatch
};

// The first refinement budget when the driver's loop limit forces a split.
constexpr std::uint32_t kFirstRefineBudget = 128;

// Lightcuts: every cut from the roots to the end in one dispatch, or a
// budget of steps per dispatch, the cut paused in CutState and the heap in
// the heap-save buffer in between. A step is one refinement, or (stochastic) one
// fresh representative drawn for a cluster of the final cut.
class Lightcuts final : public ShadingMethod {
public:
    Lightcuts(const gpu::FrameParams& frame, const LightTree& tree, const Tuning& tuning,
              std::uint32_t cut_heap, std::uint32_t shared_memory_bytes, bool stochastic, bool quads)
        : stochastic_(stochastic), quads_(quads) {
        // Walter 2005 §4 keeps a max-heap of the refinable clusters of the
        // cut, here bounded by K = render.cut_heap (lc_shared/lightcuts.h,
        // lc_heap_push); the tree bounds it too, whatever max_cut says. A
        // quad's shared cut pools its four points' K, as on the CPU
        // (host/cpu_renderer.cpp), and each of its lanes holds all of it
        // (quadcuts.comp). The slots are each invocation's own private
        // array, which does not limit K, or (Tuning::heap_memory) all
        // slots of every invocation live in shared memory, which does.
        heap_slots_ = tree.cut_heap_slots(frame.max_cut, quads ? quad_cut_heap(cut_heap) : cut_heap);
        const std::uint64_t bytes = std::uint64_t(heap_slots_) * gpu::kWorkgroupSize * entry_bytes();
        if (tuning.heap_memory != Tuning::HeapMemory::kPrivate && bytes > shared_memory_bytes)
            throw std::runtime_error(
                "cut_heap " + std::to_string(cut_heap) + std::string(quads ? " shared by quads" : "") + " needs " +
                std::to_string(bytes) + " bytes of shared memory per workgroup (" +
                std::to_string(gpu::kWorkgroupSize) + " invocations x " + std::to_string(heap_slots_) +
                " slots x " + std::to_string(entry_bytes()) + " bytes); the Vulkan device offers " +
                std::to_string(shared_memory_bytes) + ", so at most cut_heap " +
                std::to_string(shared_memory_bytes / (gpu::kWorkgroupSize * entry_bytes()) / (quads ? 4u : 1u)) +
                (quads ? " (or cut_sharing \"pixel\")" : ""));
        // Private heaps are bounded too: a kernel with a huge private array
        // takes the driver's compiler minutes and gigabytes, or fails.
        const std::uint64_t private_bytes = std::uint64_t(heap_slots_) * entry_bytes();
        if (tuning.heap_memory == Tuning::HeapMemory::kPrivate && private_bytes > Tuning::kMaxPrivateHeapBytes)
            throw std::runtime_error(
                "cut_heap " + std::to_string(cut_heap) + " with max_cut " + std::to_string(frame.max_cut) +
                std::string(quads ? " shared by quads" : "") + " needs " + std::to_string(heap_slots_) +
                " heap slots, " + std::to_string(private_bytes) + " bytes a pixel; the Vulkan kernels take at most " +
                std::to_string(Tuning::kMaxPrivateHeapBytes / entry_bytes()) +
                " slots: lower cut_heap or max_cut (a cut at the default max_cut needs at most 1000), or render on "
                "the CPU");
        // A refinement adds one cluster to the cut and takes one interior
        // node off the heap for good, so a cut never sees more refinements
        // than either allows.
        const std::uint64_t interior = tree.nodes.size() - tree.lights.size();
        const std::uint64_t refinements = std::min<std::uint64_t>(frame.max_cut, interior);
        // The refinements, the step that finds the cut final, and the fresh
        // draws of the heap's clusters.
        max_steps_ = refinements + 1 + (stochastic ? std::uint64_t(heap_slots_) * frame.light_samples : 0);
        if (tuning.refinements_per_dispatch > 0 && max_steps_ > tuning.whole_cut_steps)
            budget_ = tuning.refinements_per_dispatch;
    }

    std::size_t entry_bytes() const { return quads_ ? sizeof(gpu::QuadCutEntry) : sizeof(gpu::CutEntry); }

    KernelCode kernel() const override {
        if (quads_) return {lc_spirv_quadcuts, sizeof lc_spirv_quadcuts, "quadcuts.comp (cuts shared by quads)"};
        return {lc_spirv_lightcuts, sizeof lc_spirv_lightcuts,
                stochastic_ ? "lightcuts.comp (stochastic lightcuts)" : "lightcuts.comp (cut selection + shading)"};
    }
    bool stochastic() const override { return stochastic_; }
    bool quad_cuts() const override { return quads_; }
    std::uint32_t heap_slots() const override { return heap_slots_; }
    std::uint32_t heap_entry_bytes() const override { return std::uint32_t(entry_bytes()); }
    TileBuffer heap_save() const override {
        return {"heap save", std::uint64_t(heap_slots_) * entry_bytes(),
                std::to_string(heap_slots_) + " heap slots per pixel"};
    }
    TileBuffer cut_state() const override { return {"cut state", sizeof(gpu::CutState), ""}; }
    bool reports_cuts() const override { return true; }

    // Dispatches of `budget` steps each that finish every cut.
    std::uint32_t dispatch_count() const override {
        return budget_ == gpu::kUnlimitedRefinements ? 1 : std::uint32_t((max_steps_ + budget_ - 1) / budget_);
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
    bool stochastic_;
    bool quads_;
    std::uint32_t heap_slots_ = 0;
    std::uint64_t max_steps_ = 0;
    std::uint32_t budget_ = gpu::kUnlimitedRefinements;  // refinements per dispatch
};

}  // namespace

std::unique_ptr<ShadingMethod> make_shading_method(const RenderOptions& options,
                                                   const gpu::FrameParams& frame,
                                                   const LightTree& tree, const Tuning& tuning,
                                                   std::uint32_t shared_memory_bytes, bool quads) {
    if (method_selects_cuts(options.method))
        return std::make_unique<Lightcuts>(frame, tree, tuning, options.cut_heap, shared_memory_bytes,
                                           options.method == "stochastic", quads);
    if (options.method == "sampled")
        return std::make_unique<RangedMethod>(
            KernelCode{lc_spirv_sampled, sizeof lc_spirv_sampled, "sampled.comp (light samples)"},
            frame.light_samples, tuning);
    return std::make_unique<RangedMethod>(
        KernelCode{lc_spirv_brute, sizeof lc_spirv_brute, "brute.comp (all lights)"}, frame.light_count, tuning);
}

}  // namespace lc::vk
