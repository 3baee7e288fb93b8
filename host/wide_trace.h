// The CPU path's rays through wide copies of the BVH: shadow rays (any hit)
// and, through the 8-wide one, closest hits (trace_closest_wide8). The
// shadow rays through the 4-wide copy of the BVH
// (lc::WideBvhNode and lc::WideLeaf, collapse_bvh): one SSE slab test checks
// a node's four children at once, one SSE triangle test a leaf's (up to)
// four triangles. Both are the kernels' own tests (lc_hit_box and the
// watertight lc_intersect_sheared of shaders/lc_shared/trace.h) computed lane
// by lane with the same operations in the same order, so the answer is the
// binary traversal's: a triangle is tested here whenever it is there (each
// of its boxes passes the same test), and each test gives the same result.
// (The 8-wide tree also tests some triangles together that the binary tree
// keeps apart, in leaves of their own (collapse_bvh8). A triangle the ray
// hits lies inside its own boxes, and lc_hit_box widens the far distance
// so that rounding does not make a ray miss a box around its hit point:
// the extra tests find nothing the binary walk does not. The Bvh tests
// check every walk against brute force.)
// A change to lc_hit_box or lc_intersect_sheared (shaders/lc_shared/trace.h)
// must be made here too; the Bvh tests compare the two traversals.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include <glm/glm.hpp>

#include "lightcuts/bvh.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#include <immintrin.h>
#endif

namespace lc::cpu {

static_assert(gpu::kBvhMaxLeafTriangles <= 4, "a WideLeaf holds one binary leaf");

// Deepest wide node is no deeper than the binary tree's deepest (below
// kBvhStackSize); each visit pops one entry and pushes at most four.
inline constexpr std::uint32_t kWideStackSize = 3u * gpu::kBvhStackSize + 4u;

#if defined(__SSE2__)
// One ray, set up for the SSE tests below: its origin, inverse direction and
// length broadcast to four lanes, and its shear (lc_shear_ray) with the
// origin in the permuted axes.
struct WideRay {
    __m128 ox, oy, oz, ix, iy, iz, far_limit;
    __m128 sx, sy, sz, o_kx, o_ky, o_kz;
    int kx, ky, kz;
};

// The part of a WideRay that only the triangle tests read (wide_hit_leaf):
// the shear and the length. Always inlined: trace_any_wide8 calls it inside
// its AVX2 loop, where a call out to this SSE code made the walk 1.4 times
// slower (the loop's 256-bit constants spilled around the call).
template <class Kernel>
inline __attribute__((always_inline)) void wide_ray_shear(Kernel& kernel, glm::vec3 org, glm::vec3 dir, float t_max,
                                                          WideRay& r) {
    const auto sheared = kernel.lc_shear_ray(dir);
    r.far_limit = _mm_set1_ps(t_max);
    r.kx = sheared.kx, r.ky = sheared.ky, r.kz = sheared.kz;
    r.sx = _mm_set1_ps(sheared.sx), r.sy = _mm_set1_ps(sheared.sy), r.sz = _mm_set1_ps(sheared.sz);
    r.o_kx = _mm_set1_ps(org[r.kx]), r.o_ky = _mm_set1_ps(org[r.ky]), r.o_kz = _mm_set1_ps(org[r.kz]);
}

template <class Kernel>
WideRay wide_ray(Kernel& kernel, glm::vec3 org, glm::vec3 dir, float t_max) {
    const glm::vec3 inv = kernel.lc_safe_inverse(dir);
    WideRay r;
    r.ox = _mm_set1_ps(org.x), r.oy = _mm_set1_ps(org.y), r.oz = _mm_set1_ps(org.z);
    r.ix = _mm_set1_ps(inv.x), r.iy = _mm_set1_ps(inv.y), r.iz = _mm_set1_ps(inv.z);
    wide_ray_shear(kernel, org, dir, t_max, r);
    return r;
}

// lc_hit_box on a node's four boxes: bit s set where the ray enters child s.
inline unsigned wide_hit_boxes(const WideBvhNode& node, const WideRay& r) {
    const __m128 zero = _mm_setzero_ps();
    const __m128 widen = _mm_set1_ps(1.0000004f);  // lc_hit_box's robust far distance
    const __m128 t0x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.lo_x), r.ox), r.ix);
    const __m128 t1x = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.hi_x), r.ox), r.ix);
    const __m128 t0y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.lo_y), r.oy), r.iy);
    const __m128 t1y = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.hi_y), r.oy), r.iy);
    const __m128 t0z = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.lo_z), r.oz), r.iz);
    const __m128 t1z = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.hi_z), r.oz), r.iz);
    const __m128 t_near = _mm_max_ps(_mm_max_ps(_mm_min_ps(t0x, t1x), _mm_min_ps(t0y, t1y)),
                                     _mm_max_ps(_mm_min_ps(t0z, t1z), zero));
    const __m128 t_far = _mm_mul_ps(_mm_min_ps(_mm_min_ps(_mm_max_ps(t0x, t1x), _mm_max_ps(t0y, t1y)),
                                               _mm_min_ps(_mm_max_ps(t0z, t1z), r.far_limit)),
                                    widen);
    const __m128i present =
        _mm_cmpgt_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(node.count)), _mm_set1_epi32(-1));
    return unsigned(_mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t_near, t_far), _mm_castsi128_ps(present))));
}

// lc_intersect_sheared on a leaf's `count` triangles, lane by lane: bit l
// set where the ray hits triangle l at t[l] in (0, far_limit); v and w over
// det are its barycentric weights b1 and b2 (as there, divided only for the
// triangle kept).
inline unsigned wide_leaf_hits(const WideLeaf& leaf, std::int32_t count, const WideRay& r, __m128& t, __m128& v,
                               __m128& w, __m128& det) {
    const __m128 zero = _mm_setzero_ps();
    const int kx = r.kx, ky = r.ky, kz = r.kz;
    const __m128 a_kz = _mm_sub_ps(_mm_load_ps(leaf.v0[kz]), r.o_kz);
    const __m128 b_kz = _mm_sub_ps(_mm_load_ps(leaf.v1[kz]), r.o_kz);
    const __m128 c_kz = _mm_sub_ps(_mm_load_ps(leaf.v2[kz]), r.o_kz);
    const __m128 ax = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v0[kx]), r.o_kx), _mm_mul_ps(r.sx, a_kz));
    const __m128 ay = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v0[ky]), r.o_ky), _mm_mul_ps(r.sy, a_kz));
    const __m128 bx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v1[kx]), r.o_kx), _mm_mul_ps(r.sx, b_kz));
    const __m128 by = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v1[ky]), r.o_ky), _mm_mul_ps(r.sy, b_kz));
    const __m128 cx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v2[kx]), r.o_kx), _mm_mul_ps(r.sx, c_kz));
    const __m128 cy = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(leaf.v2[ky]), r.o_ky), _mm_mul_ps(r.sy, c_kz));
    const __m128 u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
    v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
    w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
    const __m128 negative =
        _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
    const __m128 positive =
        _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
    det = _mm_add_ps(_mm_add_ps(u, v), w);
    const __m128 t_scaled =
        _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(u, a_kz), _mm_mul_ps(v, b_kz)), _mm_mul_ps(w, c_kz)), r.sz);
    t = _mm_div_ps(t_scaled, det);
    const __m128 outside = _mm_or_ps(_mm_and_ps(negative, positive), _mm_cmpeq_ps(det, zero));
    const __m128 in_range = _mm_and_ps(_mm_cmpgt_ps(t, zero), _mm_cmplt_ps(t, r.far_limit));
    const __m128 used = _mm_castsi128_ps(_mm_cmplt_epi32(_mm_set_epi32(3, 2, 1, 0), _mm_set1_epi32(count)));
    return unsigned(_mm_movemask_ps(_mm_and_ps(_mm_andnot_ps(outside, in_range), used)));
}

// lc_intersect_sheared on a leaf's `count` triangles, lane by lane: true if
// the ray hits one.
inline bool wide_hit_leaf(const WideLeaf& leaf, std::int32_t count, const WideRay& r) {
    __m128 t, v, w, det;
    return wide_leaf_hits(leaf, count, r, t, v, w, det) != 0u;
}
#endif

// Any hit with t in (0, t_max) among the triangles of the wide tree
// (nodes, leaves), the same answer as lc_trace_any. `kernel` is a kernel
// struct of host/cpu_kernel.h: its lc_safe_inverse and lc_shear_ray set the
// ray up, and without SSE its lc_hit_box, lc_intersect_sheared and
// triangles do the tests one at a time.
template <class Kernel>
bool trace_any_wide(Kernel& kernel, const WideBvhNode* nodes, const WideLeaf* leaves, glm::vec3 org,
                    glm::vec3 dir, float t_max) {
    std::uint32_t stack[kWideStackSize];
    std::uint32_t sp = 0;
    stack[sp++] = 0u;
#if defined(__SSE2__)
    const WideRay ray = wide_ray(kernel, org, dir, t_max);
#else
    const glm::vec3 inv = kernel.lc_safe_inverse(dir);
    const auto sheared = kernel.lc_shear_ray(dir);
#endif
    while (sp > 0u) {
        const WideBvhNode& node = nodes[stack[--sp]];
#if defined(__SSE2__)
        unsigned mask = wide_hit_boxes(node, ray);
#else
        unsigned mask = 0u;
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
            if (wide_hit_leaf(leaf, count, ray)) return true;
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


// Up to four rays: ray r from org[r] along dir[r], for t in (0, t_max[r]),
// where bit r of `valid` is set. (One struct by reference: with the three
// arrays as separate pointer parameters, GCC 12.2 at -O3 dropped a caller's
// stores to them as dead; -fno-ipa-modref or -fno-tree-dse kept them.)
template <unsigned R>
struct RayPacket {
    glm::vec3 org[R];
    glm::vec3 dir[R];
    float t_max[R];
    unsigned valid = 0u;
};
using RayPacket4 = RayPacket<4>;
using RayPacket8 = RayPacket<8>;

#if defined(__SSE2__) && (defined(__x86_64__) || defined(__i386__))
#define LC_WIDE8_TRACE 1
// Whether this CPU runs AVX2 (and its operating system saves the wide
// registers): trace_any_wide8 is then used. Asked once.
inline bool cpu_has_avx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
}

// One ray's constants for the 8-wide slab test, broadcast to the lanes.
struct Wide8Ray {
    __m256 ox, oy, oz, ix, iy, iz, far_limit;
};

template <class Kernel>
__attribute__((target("avx2"), always_inline)) inline Wide8Ray wide8_ray(Kernel& kernel, glm::vec3 org, glm::vec3 dir,
                                                                         float t_max) {
    const glm::vec3 inv = kernel.lc_safe_inverse(dir);
    return Wide8Ray{_mm256_set1_ps(org.x), _mm256_set1_ps(org.y), _mm256_set1_ps(org.z), _mm256_set1_ps(inv.x),
                    _mm256_set1_ps(inv.y),  _mm256_set1_ps(inv.z),  _mm256_set1_ps(t_max)};
}

// lc_hit_box on a node's eight boxes: bit s set where the ray enters child
// s, at the distance in lane s of t_entry.
__attribute__((target("avx2"), always_inline)) inline unsigned wide8_hit_boxes(const WideBvhNode8& node,
                                                                               const Wide8Ray& r, __m256& t_entry) {
    const __m256 zero = _mm256_setzero_ps();
    const __m256 widen = _mm256_set1_ps(1.0000004f);  // lc_hit_box's robust far distance
    const __m256 t0x = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.lo_x), r.ox), r.ix);
    const __m256 t1x = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.hi_x), r.ox), r.ix);
    const __m256 t0y = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.lo_y), r.oy), r.iy);
    const __m256 t1y = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.hi_y), r.oy), r.iy);
    const __m256 t0z = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.lo_z), r.oz), r.iz);
    const __m256 t1z = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.hi_z), r.oz), r.iz);
    const __m256 t_near = _mm256_max_ps(_mm256_max_ps(_mm256_min_ps(t0x, t1x), _mm256_min_ps(t0y, t1y)),
                                        _mm256_max_ps(_mm256_min_ps(t0z, t1z), zero));
    const __m256 t_far = _mm256_mul_ps(_mm256_min_ps(_mm256_min_ps(_mm256_max_ps(t0x, t1x), _mm256_max_ps(t0y, t1y)),
                                                     _mm256_min_ps(_mm256_max_ps(t0z, t1z), r.far_limit)),
                                       widen);
    const __m256i present = _mm256_cmpgt_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(node.count)),
                                               _mm256_set1_epi32(-1));
    t_entry = t_near;
    return unsigned(
        _mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(t_near, t_far, _CMP_LE_OQ), _mm256_castsi256_ps(present))));
}

__attribute__((target("avx2"), always_inline)) inline unsigned wide8_hit_boxes(const WideBvhNode8& node,
                                                                               const Wide8Ray& r) {
    __m256 t_entry;
    return wide8_hit_boxes(node, r, t_entry);
}

// trace_any_wide's answer from the 8-wide tree (lc::WideBvhNode8,
// collapse_bvh8): one 256-bit slab test checks a node's eight boxes, with
// lc_hit_box's operations lane by lane (nothing is contracted: the build
// passes -ffp-contract=off), and leaves are tested with wide_hit_leaf. Fewer
// levels than the 4-wide tree, so fewer nodes per ray: 1.1 to 1.3 times the
// rays per second on lightcuts' shadow rays of the shipped room
// (bench/embree_rays). The body of trace_any_wide8_avx2 and _avx512 below.
template <class Kernel>
__attribute__((target("avx2"), always_inline)) inline bool wide8_walk(Kernel& kernel, const WideBvhNode8* nodes,
                                                                      const WideLeaf* leaves, glm::vec3 org,
                                                                      glm::vec3 dir, float t_max) {
    // Each visit pops one entry and pushes at most eight.
    std::uint32_t stack[7u * gpu::kBvhStackSize + 8u];
    std::uint32_t sp = 0;
    stack[sp++] = 0u;
    // The triangle tests' set-up (the shear) is made at the first leaf the
    // ray reaches: many shadow rays reach none.
    WideRay ray;
    bool sheared = false;
    const Wide8Ray r = wide8_ray(kernel, org, dir, t_max);
    while (sp > 0u) {
        const WideBvhNode8& node = nodes[stack[--sp]];
        unsigned mask = wide8_hit_boxes(node, r);
        while (mask != 0u) {
            const unsigned s = unsigned(__builtin_ctz(mask));
            mask &= mask - 1u;
            const std::int32_t count = node.count[s];
            if (count == 0) {
                stack[sp++] = node.child[s];
                continue;
            }
            if (!sheared) {
                wide_ray_shear(kernel, org, dir, t_max, ray);
                sheared = true;
            }
            if (wide_hit_leaf(leaves[node.child[s]], count, ray)) return true;
        }
    }
    return false;
}

// Up to R rays (bit r of packet.valid; R is 4 or 8) through the 8-wide
// tree together: bit r of the result is set where ray r is blocked. Each
// stack entry carries the rays that entered its node, and each of them is
// tested against the node's boxes on its own (wide8_hit_boxes): a ray
// visits exactly the nodes and leaves its own walk would, so every answer
// is trace_any_wide8's; what the rays share is the pops, the reads of the
// nodes and the branches. For rays that take nearly the same path: the
// points of a quad or an octet to one light, a point to neighbouring
// lights. (Eight rays rather than four: the octets' cuts 2 to 5% faster,
// brute force 3 to 4%, docs/results/speed.md.)
template <unsigned R, class Kernel>
__attribute__((target("avx2"), always_inline)) inline unsigned wide8_walk_packet(Kernel& kernel,
                                                                          const WideBvhNode8* nodes,
                                                                          const WideLeaf* leaves,
                                                                          const RayPacket<R>& packet) {
    static_assert(R == 4u || R == 8u);
    using Bits = std::conditional_t<R == 4u, std::uint32_t, std::uint64_t>;
    const unsigned valid = packet.valid & ((1u << R) - 1u);
    Wide8Ray rays[R];
    WideRay sheared[R];
    unsigned has_shear = 0u;
    // Every slot gets a ray, so that the box tests of a full packet below
    // run without branches: a slot not in the packet repeats the first
    // ray, and its answers are masked off.
    const unsigned first = valid != 0u ? unsigned(__builtin_ctz(valid)) : 0u;
    for (unsigned r = 0; r < R; ++r) {
        const unsigned from = (valid >> r & 1u) != 0u ? r : first;
        rays[r] = wide8_ray(kernel, packet.org[from], packet.dir[from], packet.t_max[from]);
    }
    std::uint32_t stack[7u * gpu::kBvhStackSize + 8u];
    std::uint8_t stack_rays[7u * gpu::kBvhStackSize + 8u];
    std::uint32_t sp = 0;
    stack[sp] = 0u;
    stack_rays[sp++] = std::uint8_t(valid);
    unsigned blocked = 0u;
    while (sp > 0u) {
        --sp;
        const unsigned active = stack_rays[sp] & ~blocked;
        if (active == 0u) continue;
        const WideBvhNode8& node = nodes[stack[sp]];
        unsigned any = 0u;
        Bits by_ray = 0u;
        // More than half the packet's rays here: every slot's test, without
        // branches; fewer (the rays of a block's points part ways as they
        // go down): only the active rays'. (Every slot: the octets' cuts
        // 2.5 to 4% slower on the room; only the active ones: brute force's
        // full packets 1 to 2% slower. docs/results/speed.md.)
        if (__builtin_popcount(active) > int(R / 2u)) {
            for (unsigned r = 0; r < R; ++r) {
                const unsigned mask = wide8_hit_boxes(node, rays[r]) & (0u - (active >> r & 1u));
                any |= mask;
                by_ray |= Bits(mask) << 8u * r;
            }
        } else {
            for (unsigned todo = active; todo != 0u; todo &= todo - 1u) {
                const unsigned r = unsigned(__builtin_ctz(todo));
                const unsigned mask = wide8_hit_boxes(node, rays[r]);
                any |= mask;
                by_ray |= Bits(mask) << 8u * r;
            }
        }
        // Ray r's box bits in byte r: a child's rays are one bit of each
        // byte, gathered into the top byte by one multiplication (the
        // partial products land on distinct bits, so nothing carries).
        while (any != 0u) {
            const unsigned s = unsigned(__builtin_ctz(any));
            any &= any - 1u;
            unsigned entered;
            if constexpr (R == 4u)
                entered = (((by_ray >> s) & 0x01010101u) * 0x01020408u) >> 24 & 0xFu;
            else
                entered = unsigned((((by_ray >> s) & 0x0101010101010101ull) * 0x0102040810204080ull) >> 56);
            const std::int32_t count = node.count[s];
            if (count == 0) {
                stack[sp] = node.child[s];
                stack_rays[sp++] = std::uint8_t(entered);
                continue;
            }
            for (unsigned todo = entered & ~blocked; todo != 0u; todo &= todo - 1u) {
                const unsigned r = unsigned(__builtin_ctz(todo));
                if ((has_shear >> r & 1u) == 0u) {
                    wide_ray_shear(kernel, packet.org[r], packet.dir[r], packet.t_max[r], sheared[r]);
                    has_shear |= 1u << r;
                }
                if (wide_hit_leaf(leaves[node.child[s]], count, sheared[r])) blocked |= 1u << r;
            }
            if (blocked == valid) return blocked;
        }
    }
    return blocked;
}

// lc_trace_closest's hit from the 8-wide tree: the triangle (in the binary
// tree's order) whose own test (lc_intersect_sheared, lane by lane) gives
// the smallest t in (0, t_max), with that t and its barycentric weights,
// bit for bit; kInvalidIndex where none. The binary walk keeps the first
// of triangles hit at exactly the same distance that it meets, this one
// the first it meets (within a leaf the lowest, as there), so where two tie
// the two walks may name different ones. A node's leaves are tested when
// it is popped, its inner children pushed farthest first; a popped node
// the closest hit has passed is skipped.
template <class Kernel>
__attribute__((target("avx2"), always_inline)) inline std::uint32_t wide8_walk_closest(
    Kernel& kernel, const WideBvhNode8* nodes, const WideLeaf* leaves, glm::vec3 org, glm::vec3 dir, float t_max,
    float& t_hit, float& b1, float& b2) {
    std::uint32_t stack[7u * gpu::kBvhStackSize + 8u];
    float stack_entry[7u * gpu::kBvhStackSize + 8u];
    std::uint32_t sp = 0;
    stack[sp] = 0u;
    stack_entry[sp++] = 0.0f;
    std::uint32_t hit = gpu::kInvalidIndex;
    t_hit = t_max;
    b1 = 0.0f;
    b2 = 0.0f;
    Wide8Ray r = wide8_ray(kernel, org, dir, t_max);
    WideRay sheared;
    bool has_shear = false;
    while (sp > 0u) {
        --sp;
        // lc_hit_box would refuse it at the closest hit's distance.
        if (stack_entry[sp] > t_hit * 1.0000004f) continue;
        const WideBvhNode8& node = nodes[stack[sp]];
        __m256 entry;
        const unsigned mask = wide8_hit_boxes(node, r, entry);
        alignas(32) float entries[8];
        _mm256_store_ps(entries, entry);
        std::uint32_t inner[8];
        unsigned inner_count = 0u;
        for (unsigned todo = mask; todo != 0u; todo &= todo - 1u) {
            const unsigned s = unsigned(__builtin_ctz(todo));
            const std::int32_t count = node.count[s];
            if (count == 0) {
                // Kept in order of decreasing entry distance, so that the
                // nearest is pushed last and popped first.
                unsigned at = inner_count++;
                while (at > 0u && entries[inner[at - 1u]] < entries[s]) {
                    inner[at] = inner[at - 1u];
                    --at;
                }
                inner[at] = s;
                continue;
            }
            if (!has_shear) {
                wide_ray_shear(kernel, org, dir, t_hit, sheared);
                has_shear = true;
            }
            sheared.far_limit = _mm_set1_ps(t_hit);
            __m128 t, v, w, det;
            const unsigned lanes = wide_leaf_hits(leaves[node.child[s]], count, sheared, t, v, w, det);
            if (lanes == 0u) continue;
            alignas(16) float ts[4], vs[4], ws[4], dets[4];
            _mm_store_ps(ts, t), _mm_store_ps(vs, v), _mm_store_ps(ws, w), _mm_store_ps(dets, det);
            int best = -1;
            for (unsigned l = 0; l < 4u; ++l)
                if ((lanes >> l & 1u) != 0u && (best < 0 || ts[l] < ts[best])) best = int(l);
            t_hit = ts[best];
            b1 = vs[best] / dets[best];
            b2 = ws[best] / dets[best];
            hit = leaves[node.child[s]].first + std::uint32_t(best);
            r.far_limit = _mm256_set1_ps(t_hit);
        }
        for (unsigned k = 0; k < inner_count; ++k) {
            stack[sp] = node.child[inner[k]];
            stack_entry[sp++] = entries[inner[k]];
        }
    }
    return hit;
}

// The walk for AVX2 CPUs.
template <class Kernel>
__attribute__((target("avx2"))) bool trace_any_wide8_avx2(Kernel& kernel, const WideBvhNode8* nodes,
                                                           const WideLeaf* leaves, glm::vec3 org, glm::vec3 dir,
                                                           float t_max) {
    return wide8_walk(kernel, nodes, leaves, org, dir, t_max);
}

// Whether this CPU runs AVX-512 with 256-bit vectors (AVX-512VL). Asked once.
inline bool cpu_has_avx512vl() {
    static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
    return has;
}

// The same walk where AVX-512VL gives 32 vector registers instead of 16:
// the ray's constants stay in registers through the leaf tests, which with
// 16 the compiler keeps on the stack and reloads every trip. The same
// 256-bit operations, so the same answers, bit for bit (test_bvh checks
// both walks against brute force). Only where cpu_has_avx512vl().
template <class Kernel>
__attribute__((target("avx2,avx512f,avx512vl"))) bool trace_any_wide8_avx512(Kernel& kernel,
                                                                              const WideBvhNode8* nodes,
                                                                              const WideLeaf* leaves, glm::vec3 org,
                                                                              glm::vec3 dir, float t_max) {
    return wide8_walk(kernel, nodes, leaves, org, dir, t_max);
}

// wide8_walk_packet for AVX2 and for AVX-512VL CPUs (a packet of four
// rays or of eight).
template <class Kernel, unsigned R>
__attribute__((target("avx2"))) unsigned trace_any_wide8_packet_avx2(Kernel& kernel, const WideBvhNode8* nodes,
                                                                      const WideLeaf* leaves,
                                                                      const RayPacket<R>& packet) {
    return wide8_walk_packet(kernel, nodes, leaves, packet);
}

template <class Kernel, unsigned R>
__attribute__((target("avx2,avx512f,avx512vl"))) unsigned trace_any_wide8_packet_avx512(
    Kernel& kernel, const WideBvhNode8* nodes, const WideLeaf* leaves, const RayPacket<R>& packet) {
    return wide8_walk_packet(kernel, nodes, leaves, packet);
}

// wide8_walk_closest for AVX2 and for AVX-512VL CPUs.
template <class Kernel>
__attribute__((target("avx2"))) std::uint32_t trace_closest_wide8_avx2(Kernel& kernel, const WideBvhNode8* nodes,
                                                                         const WideLeaf* leaves, glm::vec3 org,
                                                                         glm::vec3 dir, float t_max, float& t,
                                                                         float& b1, float& b2) {
    return wide8_walk_closest(kernel, nodes, leaves, org, dir, t_max, t, b1, b2);
}

template <class Kernel>
__attribute__((target("avx2,avx512f,avx512vl"))) std::uint32_t trace_closest_wide8_avx512(
    Kernel& kernel, const WideBvhNode8* nodes, const WideLeaf* leaves, glm::vec3 org, glm::vec3 dir, float t_max,
    float& t, float& b1, float& b2) {
    return wide8_walk_closest(kernel, nodes, leaves, org, dir, t_max, t, b1, b2);
}

// The closest hit through the 8-wide tree for this CPU: only where
// cpu_has_avx2().
template <class Kernel>
std::uint32_t trace_closest_wide8(Kernel& kernel, const WideBvhNode8* nodes, const WideLeaf* leaves, glm::vec3 org,
                                  glm::vec3 dir, float t_max, float& t, float& b1, float& b2) {
    return cpu_has_avx512vl() ? trace_closest_wide8_avx512(kernel, nodes, leaves, org, dir, t_max, t, b1, b2)
                              : trace_closest_wide8_avx2(kernel, nodes, leaves, org, dir, t_max, t, b1, b2);
}

// The packets' 8-wide walk for this CPU: only where cpu_has_avx2().
template <class Kernel, unsigned R>
unsigned trace_any_wide8_packet(Kernel& kernel, const WideBvhNode8* nodes, const WideLeaf* leaves,
                                const RayPacket<R>& packet) {
    return cpu_has_avx512vl() ? trace_any_wide8_packet_avx512(kernel, nodes, leaves, packet)
                              : trace_any_wide8_packet_avx2(kernel, nodes, leaves, packet);
}

// The 8-wide walk for this CPU: only where cpu_has_avx2().
template <class Kernel>
bool trace_any_wide8(Kernel& kernel, const WideBvhNode8* nodes, const WideLeaf* leaves, glm::vec3 org, glm::vec3 dir,
                     float t_max) {
    return cpu_has_avx512vl() ? trace_any_wide8_avx512(kernel, nodes, leaves, org, dir, t_max)
                              : trace_any_wide8_avx2(kernel, nodes, leaves, org, dir, t_max);
}
#else
inline bool cpu_has_avx2() { return false; }
inline bool cpu_has_avx512vl() { return false; }
#endif

#if defined(__SSE2__)
// A packet of rays from one origin as intervals, for a test of a box
// against all of them at once: on each axis the inverse directions lie in
// [inv_lo, inv_hi] and share a sign, so every ray enters the slab through
// the same plane (`near`: lo where the rays go up the axis, hi where they go
// down) and leaves through the other (`far`).
struct PacketBounds {
    float (WideBvhNode::*near[3])[4];
    float (WideBvhNode::*far[3])[4];
    __m128 inv_lo[3], inv_hi[3], org[3];
    __m128 t_max;  // the longest ray's
};
#endif


#if defined(__SSE2__)
// The packet's PacketBounds, if it is coherent: its rays leave one point in
// similar directions (a shaded point's rays to neighbouring lights), the
// case where interval bounds are tight. Rays from several points, or whose
// inverse directions differ in sign or by more than a factor of five on an
// axis, are traced ray by ray. (On the room's brute-force rays a factor of
// 1.25 took a third of the packets' gain away; 2, 5 and no limit ran at the
// same speed, bench/embree_rays.)
// `rays` holds the rays of `valid` (nonzero) set up by wide_ray, whose
// inverse directions are read back from their lanes.
inline bool packet_bounds(const RayPacket4& packet, unsigned valid, const WideRay rays[4], PacketBounds& b) {
    auto inverse = [](const WideRay& r) {
        return glm::vec3(_mm_cvtss_f32(r.ix), _mm_cvtss_f32(r.iy), _mm_cvtss_f32(r.iz));
    };
    const unsigned first = unsigned(__builtin_ctz(valid));
    const glm::vec3 org = packet.org[first];
    glm::vec3 inv_lo = inverse(rays[first]), inv_hi = inv_lo;
    float t_max = packet.t_max[first];
    for (unsigned r = first + 1u; r < 4u; ++r) {
        if ((valid >> r & 1u) == 0u) continue;
        if (packet.org[r] != org) return false;
        const glm::vec3 inv = inverse(rays[r]);
        inv_lo = glm::min(inv_lo, inv);
        inv_hi = glm::max(inv_hi, inv);
        t_max = std::max(t_max, packet.t_max[r]);
    }
    float(WideBvhNode::*const lo[3])[4] = {&WideBvhNode::lo_x, &WideBvhNode::lo_y, &WideBvhNode::lo_z};
    float(WideBvhNode::*const hi[3])[4] = {&WideBvhNode::hi_x, &WideBvhNode::hi_y, &WideBvhNode::hi_z};
    for (int k = 0; k < 3; ++k) {
        // lc_safe_inverse never gives 0: each inverse is either side of it.
        const bool up = inv_lo[k] > 0.0f;
        if (!up && !(inv_hi[k] < 0.0f)) return false;
        const float small = up ? inv_lo[k] : -inv_hi[k], large = up ? inv_hi[k] : -inv_lo[k];
        if (!(large <= 5.0f * small)) return false;
        b.near[k] = up ? lo[k] : hi[k];
        b.far[k] = up ? hi[k] : lo[k];
        b.inv_lo[k] = _mm_set1_ps(inv_lo[k]);
        b.inv_hi[k] = _mm_set1_ps(inv_hi[k]);
        b.org[k] = _mm_set1_ps(org[k]);
    }
    b.t_max = _mm_set1_ps(t_max);
    return true;
}

// lc_hit_box for a whole packet on a node's four boxes: bit s is set where
// child s may be entered by one of the rays. Each ray's distance to a plane
// on an axis is (plane - origin) * inverse, the same difference for every
// ray times an inverse within [inv_lo, inv_hi]: at least the smaller and at
// most the larger of the two ends' products. Float rounding is monotonic,
// so those bounds hold for the products lc_hit_box computes too, and a box
// that any ray's own test enters passes here (the converse need not hold:
// the triangles are tested ray by ray, exactly).
inline unsigned packet_hit_boxes(const WideBvhNode& node, const PacketBounds& b) {
    __m128 t_near = _mm_setzero_ps(), t_far = b.t_max;
    for (int k = 0; k < 3; ++k) {
        const __m128 near_d = _mm_sub_ps(_mm_load_ps(node.*b.near[k]), b.org[k]);
        const __m128 far_d = _mm_sub_ps(_mm_load_ps(node.*b.far[k]), b.org[k]);
        t_near = _mm_max_ps(t_near, _mm_min_ps(_mm_mul_ps(near_d, b.inv_lo[k]), _mm_mul_ps(near_d, b.inv_hi[k])));
        t_far = _mm_min_ps(t_far, _mm_max_ps(_mm_mul_ps(far_d, b.inv_lo[k]), _mm_mul_ps(far_d, b.inv_hi[k])));
    }
    t_far = _mm_mul_ps(t_far, _mm_set1_ps(1.0000004f));  // lc_hit_box's robust far distance
    const __m128i present =
        _mm_cmpgt_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(node.count)), _mm_set1_epi32(-1));
    return unsigned(_mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t_near, t_far), _mm_castsi128_ps(present))));
}

// A coherent packet's traversal: one box test for all rays per node
// (packet_hit_boxes), the triangles ray by ray. Returns the blocked rays.
inline unsigned trace_any_coherent(const WideBvhNode* nodes, const WideLeaf* leaves, const PacketBounds& bounds,
                                   const WideRay rays[4], unsigned valid) {
    std::uint32_t stack[kWideStackSize];
    std::uint32_t sp = 0;
    stack[sp++] = 0u;
    unsigned active = valid;
    while (sp > 0u) {
        const WideBvhNode& node = nodes[stack[--sp]];
        // Each ray's own box mask, computed the first time a leaf child is
        // reached: a ray is tested against the leaf's triangles only if it
        // enters the leaf's box.
        unsigned ray_masks[4] = {0u, 0u, 0u, 0u};
        bool ray_masks_known = false;
        for (unsigned mask = packet_hit_boxes(node, bounds); mask != 0u; mask &= mask - 1u) {
            const unsigned s = unsigned(__builtin_ctz(mask));
            const std::int32_t count = node.count[s];
            if (count == 0) {
                stack[sp++] = node.child[s];
                continue;
            }
            if (!ray_masks_known) {
                for (unsigned todo = active; todo != 0u; todo &= todo - 1u) {
                    const unsigned r = unsigned(__builtin_ctz(todo));
                    ray_masks[r] = wide_hit_boxes(node, rays[r]);
                }
                ray_masks_known = true;
            }
            const WideLeaf& leaf = leaves[node.child[s]];
            for (unsigned todo = active; todo != 0u; todo &= todo - 1u) {
                const unsigned r = unsigned(__builtin_ctz(todo));
                if ((ray_masks[r] >> s & 1u) != 0u && wide_hit_leaf(leaf, count, rays[r])) active &= ~(1u << r);
            }
            if (active == 0u) return valid;
        }
    }
    return valid & ~active;
}
#endif

// Up to four rays at once (a packet: typically one shaded point's rays to
// neighbouring lights) through the wide tree: bit r of the result is set
// where ray r is blocked, lc_trace_any's answer ray by ray; rays not in
// `valid` are not traced (their bit is 0). Coherent packets (packet_bounds)
// go down the tree together, a node's boxes tested once for all of them;
// the others are traced ray by ray (trace_any_wide).
template <class Kernel>
unsigned trace_any_wide4(Kernel& kernel, const WideBvhNode* nodes, const WideLeaf* leaves, const RayPacket4& packet) {
    const unsigned valid = packet.valid & 0xFu;
#if defined(__SSE2__)
    WideRay rays[4];
    for (unsigned r = 0; r < 4u; ++r)
        if ((valid >> r & 1u) != 0u) rays[r] = wide_ray(kernel, packet.org[r], packet.dir[r], packet.t_max[r]);
    PacketBounds bounds;
    if (valid != 0u && packet_bounds(packet, valid, rays, bounds))
        return trace_any_coherent(nodes, leaves, bounds, rays, valid);
#endif
    unsigned blocked = 0u;
    for (unsigned r = 0; r < 4u; ++r)
        if ((valid >> r & 1u) != 0u &&
            trace_any_wide(kernel, nodes, leaves, packet.org[r], packet.dir[r], packet.t_max[r]))
            blocked |= 1u << r;
    return blocked;
}

}  // namespace lc::cpu
