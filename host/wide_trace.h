// The CPU path's shadow rays through the 4-wide copy of the BVH
// (lc::WideBvhNode, collapse_bvh): one SSE slab test checks a node's four
// children at once. The triangle test is the kernels' own
// (lc_intersect_sheared), so the answer is the binary traversal's: a
// triangle is tested here whenever it is there (each of its boxes passes
// the same test, lanes computed with the same operations), and both return
// true exactly when one of those tests hits.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "lightcuts/bvh.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lc::cpu {

// Deepest wide node is no deeper than the binary tree's deepest (below
// kBvhStackSize); each visit pops one entry and pushes at most four.
inline constexpr std::uint32_t kWideStackSize = 3u * gpu::kBvhStackSize + 4u;

// Any hit with t in (0, t_max) among `kernel`'s triangles (a kernel struct
// of host/cpu_kernel.h: its lc_safe_inverse, lc_shear_ray,
// lc_intersect_sheared and triangles), the same test as lc_trace_any.
template <class Kernel>
bool trace_any_wide(Kernel& kernel, const WideBvhNode* nodes, glm::vec3 org, glm::vec3 dir, float t_max) {
    const glm::vec3 inv = kernel.lc_safe_inverse(dir);
    const auto sheared = kernel.lc_shear_ray(dir);
    std::uint32_t stack[kWideStackSize];
    std::uint32_t sp = 0;
    stack[sp++] = 0u;
#if defined(__SSE2__)
    const __m128 ox = _mm_set1_ps(org.x), oy = _mm_set1_ps(org.y), oz = _mm_set1_ps(org.z);
    const __m128 ix = _mm_set1_ps(inv.x), iy = _mm_set1_ps(inv.y), iz = _mm_set1_ps(inv.z);
    const __m128 zero = _mm_setzero_ps(), far_limit = _mm_set1_ps(t_max);
    const __m128 widen = _mm_set1_ps(1.0000004f);  // lc_hit_box's robust far distance
    const __m128i no_child = _mm_set1_epi32(-1);
#endif
    while (sp > 0u) {
        const WideBvhNode& node = nodes[stack[--sp]];
        unsigned mask = 0u;
#if defined(__SSE2__)
        // lc_hit_box on four boxes: the same operations in the same order.
        const __m128 t0x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.lo_x), ox), ix);
        const __m128 t1x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.hi_x), ox), ix);
        const __m128 t0y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.lo_y), oy), iy);
        const __m128 t1y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.hi_y), oy), iy);
        const __m128 t0z = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.lo_z), oz), iz);
        const __m128 t1z = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.hi_z), oz), iz);
        const __m128 t_near = _mm_max_ps(_mm_max_ps(_mm_min_ps(t0x, t1x), _mm_min_ps(t0y, t1y)),
                                         _mm_max_ps(_mm_min_ps(t0z, t1z), zero));
        const __m128 t_far = _mm_mul_ps(_mm_min_ps(_mm_min_ps(_mm_max_ps(t0x, t1x), _mm_max_ps(t0y, t1y)),
                                                   _mm_min_ps(_mm_max_ps(t0z, t1z), far_limit)),
                                        widen);
        const __m128i present =
            _mm_cmpgt_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(node.count)), no_child);
        mask = unsigned(_mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t_near, t_far), _mm_castsi128_ps(present))));
#else
        for (unsigned s = 0; s < 4u; ++s) {
            if (node.count[s] < 0) continue;
            const glm::vec3 t0 = (glm::vec3(node.lo_x[s], node.lo_y[s], node.lo_z[s]) - org) * inv;
            const glm::vec3 t1 = (glm::vec3(node.hi_x[s], node.hi_y[s], node.hi_z[s]) - org) * inv;
            const glm::vec3 tn = glm::min(t0, t1), tf = glm::max(t0, t1);
            const float t_near = glm::max(glm::max(tn.x, tn.y), glm::max(tn.z, 0.0f));
            const float t_far = glm::min(glm::min(tf.x, tf.y), glm::min(tf.z, t_max)) * 1.0000004f;
            if (t_near <= t_far) mask |= 1u << s;
        }
#endif
        while (mask != 0u) {
            const unsigned s = unsigned(__builtin_ctz(mask));
            mask &= mask - 1u;
            const std::int32_t count = node.count[s];
            if (count == 0) {
                stack[sp++] = node.child[s];
                continue;
            }
            const std::uint32_t first = node.child[s];
            for (std::uint32_t i = first; i < first + std::uint32_t(count); ++i) {
                float b1, b2;
                if (kernel.lc_intersect_sheared(org, sheared, kernel.triangles[i], t_max, b1, b2) > 0.0f) return true;
            }
        }
    }
    return false;
}

}  // namespace lc::cpu
