// Bounding volume hierarchy over triangles, built on the CPU with binned SAH
// and read as-is by the CPU tracer and the Vulkan kernels.
#pragma once

#include <vector>

#include "shared/types.h"

namespace lc {

struct Bvh {
    std::vector<gpu::BvhNode> nodes;   // root at 0 (a single empty leaf if no triangles)
    double build_seconds = 0.0;
};

// Builds the BVH and reorders `triangles`, `normals` and `uvs` when given
// (same permutation) so that each leaf references a contiguous range. Depth
// stays below gpu::kBvhStackSize so fixed-size traversal stacks never overflow.
Bvh build_bvh(std::vector<gpu::Triangle>& triangles, std::vector<gpu::TriangleNormals>& normals,
              std::vector<gpu::TriangleUvs>* uvs = nullptr);

}  // namespace lc
