// The shared kernel headers (shaders/shared/*.h) compiled as C++ for the CPU
// reference: the same intersection, traversal, shading and bound code the
// Vulkan kernels run, here as member functions reading the host arrays.
#pragma once

#include <glm/glm.hpp>

#include "shared/types.h"
#include "shared/glsl_compat.h"

namespace lc::cpu {

using namespace glm;
using namespace lc::gpu;

struct TraceKernel {
    const BvhNode* bvh_nodes = nullptr;
    const Triangle* triangles = nullptr;

#define LC_BVH_NODE(i) bvh_nodes[i]
#define LC_TRIANGLE(i) triangles[i]
#include "shared/trace.h"
#undef LC_BVH_NODE
#undef LC_TRIANGLE
};

}  // namespace lc::cpu
