// The light tree (Walter et al. 2005, section 4): one binary tree per light
// type, flattened into one array of 2n-1 nodes per tree, read as-is by the
// CPU reference and the Vulkan kernels.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "shared/types.h"

namespace lc {

struct LightTree {
    // One tree per light type that has lights, one after the other in type
    // order (2n-1 nodes each); roots[type] is where each starts. Lights are
    // in leaf order, so a node's lights are a contiguous range; nodes'
    // rep_light index into `lights`.
    std::vector<gpu::LightNode> nodes;
    std::vector<gpu::Light> lights;
    std::array<std::uint32_t, gpu::kLightTypeCount> roots;
    // Lights with zero intensity: left out of the tree (they would only
    // widen the boxes of bright clusters) and out of `lights`.
    std::size_t black_lights = 0;
    double build_seconds = 0.0;

    LightTree() { roots.fill(gpu::kInvalidIndex); }

    std::uint32_t root_count() const;
    // The most entries a cut's heap can hold: the heap keeps only interior
    // nodes, and never more than the cut (max(max_cut, roots) clusters).
    // At least 1, whatever max_cut is.
    std::uint32_t cut_heap_capacity(std::uint32_t max_cut) const;
    // The slots a cut heap of capacity `cut_heap` (render.cut_heap) gets:
    // no more than cut_heap_capacity(max_cut) ever holds. At least 1.
    std::uint32_t cut_heap_slots(std::uint32_t max_cut, std::uint32_t cut_heap) const;
};

enum class TreeBuilder {
    kFast,    // locally-ordered clustering over a Morton order (light_tree.cpp)
    kExact,   // exhaustive greedy pairing, O(n^2) per merge; small n only
};

// Builds one tree per light type from lights of any types. Deterministic for
// a given seed (representative choice) whatever the thread count. Cluster
// intensities are summed in double; the loader has checked that every
// type's total fits a float.
// `cone_scale` multiplies c, the weight of the metric's cone term (the
// diagonal of the tree's lights by default, light_tree.cpp); 0 leaves the
// term out, to measure what it buys (bench/tree_quality).
LightTree build_light_tree(std::span<const gpu::Light> lights, std::uint32_t seed,
                           TreeBuilder builder = TreeBuilder::kFast, double cone_scale = 1.0);

}  // namespace lc
