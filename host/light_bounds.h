// What the light tree needs to know of a light (pbrt-v4's LightBounds):
// where it sits in its tree's box, and the cone of directions it emits
// into. With the emission switch in shaders/lc_shared/shading.h, the only
// place the tree looks at a light's type.
//
// The cone: every light's axis lies within theta_o of `axis`, and each
// light emits only within theta_e of its own axis. Built on the host for the
// light tree's nodes; read by the kernels' lc_emission_bound.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "lc_shared/types.h"

namespace lc {

// A plain struct, left unwritten by default construction (the tree
// builder makes millions without zeroing them): start from everywhere() or
// of_light().
struct EmissionCone {
    glm::vec3 axis;        // as the kernels decode it (see quantized())
    float theta_o;         // spread of the axes; pi: they can point anywhere
    float theta_e;
    bool two_sided;
    // Spots: the smallest max(1e-3, cos inner - cos outer) of the lights
    // (their outer angles are in theta_e). Others: 1.
    float falloff_width;

    // A light that emits everywhere (point and directional lights): axis
    // +z, theta_o pi, theta_e pi/2, one-sided, falloff width 1.
    static EmissionCone everywhere();
    // The cone of one light (spot: its axis and outer angle; oriented: its
    // normal and pi/2).
    static EmissionCone of_light(const gpu::Light& light);

    bool emits_everywhere() const { return theta_o >= 3.14159265f; }
};

// The point a light occupies in its tree's box: the position of a point,
// spot or oriented light, the unit direction of a directional light (Walter
// 2005 §4.1 clusters directional lights as points on the unit sphere).
// Throws std::invalid_argument for an unknown type.
glm::vec3 tree_point(const gpu::Light& light);

// The smallest cone (in pbrt-v4's sense) holding both (DirectionCone::Union).
EmissionCone cone_union(const EmissionCone& a, const EmissionCone& b);

// What the tree metric's cone term reads of a cluster's cone, besides its
// axis: the cosine and sine of half its spread theta_o, and cos theta_o
// (Walter's cos beta). A cone that emits everywhere has cos_half -2, no
// cosine's value, which union_cos_beta tests for.
struct ConeSpread {
    float cos_half, sin_half, cos_beta;
    static ConeSpread of(const EmissionCone& cone);
};

// cos theta_o of cone_union's cone of a (axis_a, spread a) and b (axis_b,
// spread b), short of the few-ulp widening that holds both cones once
// cone_union turns the axis, for the tree metric, which asks it of every
// candidate pair. No angles: with the half angles alpha = theta_a / 2,
// beta = theta_b / 2 and gamma = theta_d / 2 (theta_d between the axes,
// whose sine and cosine are |a - b| / 2 and |a + b| / 2 for unit axes), b
// lies in a when gamma + beta <= alpha, and otherwise the union's spread is
// alpha + beta + gamma, everywhere from pi on (or for opposite axes, as
// cone_union has no turn to make there): cosines of sums, in products.
// Symmetric in a and b to the last bit (the metric computes each pair's
// cost once). Axes of unit length (the stored ones, lc_decode_axis); a and
// b the ConeSpread::of of their cones. union_cos_beta4 below computes
// the same floats four pairs at a time: a change here must be made there.
inline float union_cos_beta(glm::vec3 axis_a, const ConeSpread& a, glm::vec3 axis_b, const ConeSpread& b) {
    const glm::vec3 sum = axis_a + axis_b, difference = axis_a - axis_b;
    const float sum2 = sum.x * sum.x + sum.y * sum.y + sum.z * sum.z;
    const float difference2 = difference.x * difference.x + difference.y * difference.y + difference.z * difference.z;
    const float cos_gamma = 0.5f * std::sqrt(sum2);
    const float sin_gamma = 0.5f * std::sqrt(difference2);
    // alpha + beta, then + gamma.
    const float cos_ab = a.cos_half * b.cos_half - a.sin_half * b.sin_half;
    const float sin_ab = a.sin_half * b.cos_half + a.cos_half * b.sin_half;
    const float cos_union = cos_ab * cos_gamma - sin_ab * sin_gamma;
    const float sin_union = sin_ab * cos_gamma + cos_ab * sin_gamma;
    // alpha + beta + gamma < 3 pi / 2 here, so it reaches pi where its sine
    // is not positive and its cosine negative.
    const bool everywhere = (sin_union <= 0.0f && cos_union < 0.0f) || sum2 == 0.0f;
    const bool b_in_a = cos_gamma * b.cos_half - sin_gamma * b.sin_half >= a.cos_half;
    const bool a_in_b = cos_gamma * a.cos_half - sin_gamma * a.sin_half >= b.cos_half;
    float cos_beta = everywhere ? -1.0f : cos_union;
    if (a_in_b) cos_beta = b.cos_beta;
    if (b_in_a) cos_beta = a.cos_beta;
    if (a_in_b && b_in_a) cos_beta = b.cos_beta < a.cos_beta ? b.cos_beta : a.cos_beta;
    return a.cos_half < -1.0f || b.cos_half < -1.0f ? -1.0f : cos_beta;
}

#if defined(__SSE2__)
// union_cos_beta of four pairs, lane by lane: the same operations in the
// same order, so the same floats (tests/test_lights.cpp,
// UnionCosBetaIsConeUnions). The tree builder's partner search spends
// most of its time here; compilers do not turn union_cos_beta's selects
// into vector code themselves.
struct ConeLanes {
    __m128 axis_x, axis_y, axis_z, cos_half, sin_half, cos_beta;
};

inline __m128 union_cos_beta4(const ConeLanes& a, const ConeLanes& b) {
    const auto select = [](__m128 mask, __m128 yes, __m128 no) {
        return _mm_or_ps(_mm_and_ps(mask, yes), _mm_andnot_ps(mask, no));
    };
    const __m128 sx = _mm_add_ps(a.axis_x, b.axis_x), sy = _mm_add_ps(a.axis_y, b.axis_y);
    const __m128 sz = _mm_add_ps(a.axis_z, b.axis_z);
    const __m128 dx = _mm_sub_ps(a.axis_x, b.axis_x), dy = _mm_sub_ps(a.axis_y, b.axis_y);
    const __m128 dz = _mm_sub_ps(a.axis_z, b.axis_z);
    const __m128 sum2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(sx, sx), _mm_mul_ps(sy, sy)), _mm_mul_ps(sz, sz));
    const __m128 difference2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 half = _mm_set1_ps(0.5f);
    const __m128 cos_gamma = _mm_mul_ps(half, _mm_sqrt_ps(sum2));
    const __m128 sin_gamma = _mm_mul_ps(half, _mm_sqrt_ps(difference2));
    const __m128 cos_ab = _mm_sub_ps(_mm_mul_ps(a.cos_half, b.cos_half), _mm_mul_ps(a.sin_half, b.sin_half));
    const __m128 sin_ab = _mm_add_ps(_mm_mul_ps(a.sin_half, b.cos_half), _mm_mul_ps(a.cos_half, b.sin_half));
    const __m128 cos_union = _mm_sub_ps(_mm_mul_ps(cos_ab, cos_gamma), _mm_mul_ps(sin_ab, sin_gamma));
    const __m128 sin_union = _mm_add_ps(_mm_mul_ps(sin_ab, cos_gamma), _mm_mul_ps(cos_ab, sin_gamma));
    const __m128 zero = _mm_setzero_ps(), minus_one = _mm_set1_ps(-1.0f);
    const __m128 everywhere = _mm_or_ps(_mm_and_ps(_mm_cmple_ps(sin_union, zero), _mm_cmplt_ps(cos_union, zero)),
                                        _mm_cmpeq_ps(sum2, zero));
    const __m128 b_in_a =
        _mm_cmpge_ps(_mm_sub_ps(_mm_mul_ps(cos_gamma, b.cos_half), _mm_mul_ps(sin_gamma, b.sin_half)), a.cos_half);
    const __m128 a_in_b =
        _mm_cmpge_ps(_mm_sub_ps(_mm_mul_ps(cos_gamma, a.cos_half), _mm_mul_ps(sin_gamma, a.sin_half)), b.cos_half);
    __m128 cos_beta = select(everywhere, minus_one, cos_union);
    cos_beta = select(a_in_b, b.cos_beta, cos_beta);
    cos_beta = select(b_in_a, a.cos_beta, cos_beta);
    const __m128 smaller = select(_mm_cmplt_ps(b.cos_beta, a.cos_beta), b.cos_beta, a.cos_beta);
    cos_beta = select(_mm_and_ps(a_in_b, b_in_a), smaller, cos_beta);
    return select(_mm_or_ps(_mm_cmplt_ps(a.cos_half, minus_one), _mm_cmplt_ps(b.cos_half, minus_one)), minus_one,
                  cos_beta);
}
#endif

// The cone with its axis packed as the node stores it (octahedral, two
// snorm16) and theta_o widened by the angle the packing moved the axis, so
// it still holds every light. `packed` receives the stored bits.
EmissionCone quantized(const EmissionCone& cone, std::uint32_t& packed);

}  // namespace lc
