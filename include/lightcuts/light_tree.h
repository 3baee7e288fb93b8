// The light tree (Walter et al. 2005, section 4): one binary tree per light
// type, flattened into one array of 2n-1 nodes per tree, read as-is by the
// CPU reference and the Vulkan kernels.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "../../shaders/shared/types.h"

namespace lc {

struct LightTree {
    // Point tree first (2*n_point - 1 nodes, root at 0), then the directional
    // tree (root at root_directional). Lights are in leaf order, so a node's
    // lights are a contiguous range; nodes' rep_light index into `lights`.
    std::vector<gpu::LightNode> nodes;
    std::vector<gpu::Light> lights;
    std::uint32_t root_point = gpu::kInvalidIndex;
    std::uint32_t root_directional = gpu::kInvalidIndex;
    double build_seconds = 0.0;
};

enum class TreeBuilder {
    kFast,    // kd-tree nearest neighbours + lazily invalidated priority queue
    kExact,   // exhaustive greedy pairing, O(n^2) per merge; small n only
};

// Builds both trees from lights of any types. Deterministic for a given seed
// (representative choice) whatever the thread count.
LightTree build_light_tree(std::span<const gpu::Light> lights, std::uint32_t seed,
                           TreeBuilder builder = TreeBuilder::kFast);

}  // namespace lc
