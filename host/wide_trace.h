// The CPU path's shadow rays through the 4-wide copy of the BVH
// (lc::WideBvhNode and lc::WideLeaf, collapse_bvh): one SSE slab test checks
// a node's four children at once, one SSE triangle test a leaf's (up to)
// four triangles. Both are the kernels' own tests (lc_hit_box and the
// watertight lc_intersect_sheared of shaders/shared/trace.h) computed lane
// by lane with the same operations in the same order, so the answer is the
// binary traversal's: a triangle is tested here whenever it is there (each
// of its boxes passes the same test), and each test gives the same result.
// A change to lc_hit_box or lc_intersect_sheared (shaders/shared/trace.h)
// must be made here too; the Bvh tests compare the two traversals.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "lightcuts/bvh.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lc::cpu {

static_assert(gpu::kBvhMaxLeafTriangles <= 4, "a WideLeaf holds one binary leaf");

// Deepest wide node is no deeper than the binary tree's deepest (below
// kBvhStackSize); each visit pops one entry and pushes at most four.
inline constexpr std::uint32_t kWideStackSize = 3u * gpu::kBvhStackSize + 4u;

// Any hit with t in (0, t_max) among the triangles of the wide tree
// (nodes, leaves), the same answer as lc_trace_any. `kernel` is a kernel
// struct of host/cpu_kernel.h: its lc_safe_inverse and lc_shear_ray set the
// ray up, and without SSE its lc_hit_box, lc_intersect_sheared and
// triangles do the tests one at a time.
template <class Kernel>
bool trace_any_wide(Kernel& kernel, const WideBvhNode* nodes, const WideLeaf* leaves, glm::vec3 org,
                    glm::vec3 dir, float t_max) {
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
    // The ray's shear (lc_shear_ray) and its origin in the permuted axes.
    const int kx = sheared.kx, ky = sheared.ky, kz = sheared.kz;
    const __m128 sx = _mm_set1_ps(sheared.sx), sy = _mm_set1_ps(sheared.sy), sz = _mm_set1_ps(sheared.sz);
    const __m128 o_kx = _mm_set1_ps(org[kx]), o_ky = _mm_set1_ps(org[ky]), o_kz = _mm_set1_ps(org[kz]);
    const __m128i lane = _mm_set_epi32(3, 2, 1, 0);
#endif
    while (sp > 0u) {
        const WideBvhNode& node = nodes[stack[--sp]];
        unsigned mask = 0u;
#if defined(__SSE2__)
        // lc_hit_box on four boxes.
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
            const gpu::BvhNode box{node.lo_x[s], node.lo_y[s], node.lo_z[s], 0u,
                                   node.hi_x[s], node.hi_y[s], node.hi_z[s], 0u};
            float t_entry;
            if (kernel.lc_hit_box(box, org, inv, t_max, t_entry)) mask |= 1u << s;
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
            const WideLeaf& leaf = leaves[node.child[s]];
#if defined(__SSE2__)
            // lc_intersect_sheared on the leaf's triangles, lane by lane.
            const __m128 a_kz = _mm_sub_ps(_mm_load_ps(leaf.v0[kz]), o_kz);
            const __m128 b_kz = _mm_sub_ps(_mm_load_ps(leaf.v1[kz]), o_kz);
            const __m128 c_kz = _mm_sub_ps(_mm_load_ps(leaf.v2[kz]), o_kz);
            const __m128 ax = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v0[kx]), o_kx), _mm_mul_ps(sx, a_kz));
            const __m128 ay = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v0[ky]), o_ky), _mm_mul_ps(sy, a_kz));
            const __m128 bx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v1[kx]), o_kx), _mm_mul_ps(sx, b_kz));
            const __m128 by = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v1[ky]), o_ky), _mm_mul_ps(sy, b_kz));
            const __m128 cx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v2[kx]), o_kx), _mm_mul_ps(sx, c_kz));
            const __m128 cy = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v2[ky]), o_ky), _mm_mul_ps(sy, c_kz));
            const __m128 u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
            const __m128 v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
            const __m128 w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
            const __m128 negative =
                _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
            const __m128 positive =
                _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
            const __m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
            const __m128 t_scaled =
                _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(u, a_kz), _mm_mul_ps(v, b_kz)), _mm_mul_ps(w, c_kz)), sz);
            const __m128 t = _mm_div_ps(t_scaled, det);
            const __m128 outside = _mm_or_ps(_mm_and_ps(negative, positive), _mm_cmpeq_ps(det, zero));
            const __m128 in_range = _mm_and_ps(_mm_cmpgt_ps(t, zero), _mm_cmplt_ps(t, far_limit));
            const __m128 used = _mm_castsi128_ps(_mm_cmplt_epi32(lane, _mm_set1_epi32(count)));
            if (_mm_movemask_ps(_mm_and_ps(_mm_andnot_ps(outside, in_range), used)) != 0) return true;
#else
            for (std::uint32_t i = leaf.first; i < leaf.first + std::uint32_t(count); ++i) {
                float b1, b2;
                if (kernel.lc_intersect_sheared(org, sheared, kernel.triangles[i], t_max, b1, b2) > 0.0f) return true;
            }
#endif
        }
    }
    return false;
}

}  // namespace lc::cpu
