// Bounding volume hierarchy over triangles, built on the CPU with binned SAH
// and read as-is by the CPU tracer and the Vulkan kernels.
#pragma once

#include <cstdint>
#include <vector>

#include "lc_shared/types.h"

namespace lc {

// A node of the 4-wide copy of the tree that the CPU path's shadow rays
// traverse (host/wide_trace.h): the boxes of up to four children side by
// side, so that one SIMD slab test checks them all. Made from the binary
// tree by pulling grandchildren up (collapse_bvh), so it has the same
// leaves; the GPU kernels keep the binary tree.
struct alignas(16) WideBvhNode {
    float lo_x[4], lo_y[4], lo_z[4];
    float hi_x[4], hi_y[4], hi_z[4];
    std::uint32_t child[4];  // a leaf's WideLeaf index, or an inner child's WideBvhNode index
    std::int32_t count[4];   // a leaf's triangles (> 0); 0: an inner child; -1: no child
};

// The same tree 8 wide, for CPUs with AVX2 (host/wide_trace.h,
// trace_any_wide8): up to eight children's boxes per node, tested in one
// 256-bit slab test. Fewer levels than the 4-wide tree, so a ray visits
// fewer nodes. Made by collapse_bvh8, with leaves of its own (Bvh::wide8_leaves).
struct alignas(32) WideBvhNode8 {
    float lo_x[8], lo_y[8], lo_z[8];
    float hi_x[8], hi_y[8], hi_z[8];
    std::uint32_t child[8];  // a leaf's WideLeaf index, or an inner child's WideBvhNode8 index
    std::int32_t count[8];   // a leaf's triangles (> 0); 0: an inner child; -1: no child
};

// The triangles of one leaf (at most gpu::kBvhMaxLeafTriangles = 4; how many
// is its slot's count), lane by lane, so that one SIMD test checks them all:
// v0[axis][lane] and so on, unused lanes zero. `first` is the leaf's first
// triangle in the binary tree's order.
struct alignas(16) WideLeaf {
    float v0[3][4], v1[3][4], v2[3][4];
    std::uint32_t first, pad0, pad1, pad2;
};

struct Bvh {
    std::vector<gpu::BvhNode> nodes;      // root at 0 (a single empty leaf if no triangles)
    std::vector<WideBvhNode> wide_nodes;  // root at 0 (all slots empty if no triangles)
    std::vector<WideLeaf> wide_leaves;    // one per leaf of wide_nodes
    std::vector<WideBvhNode8> wide8_nodes;  // root at 0 (all slots empty if no triangles)
    std::vector<WideLeaf> wide8_leaves;     // one per leaf of wide8_nodes
    std::vector<gpu::Bvh4Node> kernel_nodes;  // wide_nodes as the Vulkan kernels read them (bvh4_nodes)
    double build_seconds = 0.0;
};

// The 4-wide tree of a binary one and its triangles (build_bvh calls it):
// each wide node takes the children of a binary node and keeps replacing its
// largest inner child by that child's two children while it has fewer than
// four.
void collapse_bvh(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::Triangle>& triangles,
                  std::vector<WideBvhNode>& wide_nodes, std::vector<WideLeaf>& wide_leaves);
// The same with up to eight children per node, for the CPU's shadow rays:
// its leaves are the binary leaves and the small subtrees (at most four
// triangles) that a leaf test costs less than splitting on the 8-wide walk
// (bvh_build.cpp, wide8_leaves).
void collapse_bvh8(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::Triangle>& triangles,
                   std::vector<WideBvhNode8>& wide_nodes, std::vector<WideLeaf>& wide_leaves);

// The 4-wide tree as the Vulkan kernels' shadow rays read it: wide_nodes
// with each leaf slot naming the leaf's first triangle (WideLeaf::first)
// instead of its WideLeaf.
std::vector<gpu::Bvh4Node> bvh4_nodes(const std::vector<WideBvhNode>& wide_nodes,
                                      const std::vector<WideLeaf>& wide_leaves);

// Builds the BVH and reorders `triangles`, `normals` and `uvs` when given
// (same permutation) so that each leaf references a contiguous range. Depth
// stays below gpu::kBvhStackSize so fixed-size traversal stacks never overflow.
Bvh build_bvh(std::vector<gpu::Triangle>& triangles, std::vector<gpu::TriangleNormals>& normals,
              std::vector<gpu::TriangleUvs>* uvs = nullptr);

}  // namespace lc
