// Both children's error bounds of a refinement at once, in two SSE lanes
// (lc_cut_refine through LC_CHILD_ERRORS, host/cpu_kernel.h). For the common
// case, point-like clusters that emit in every direction under a Lambert or
// Lambert + GGX material, it computes the cosine bound, the distance bound
// and the error of lc_cluster_bound / lc_cluster_error lane by lane, with the
// same operations in the same order, so the results are the scalar ones bit
// for bit (tests/test_lightcuts.cpp checks it); the GGX lobe's bound stays
// scalar. Every other case (leaves, directional or oriented clusters, the
// Disney BRDF) returns false and the caller evaluates one child at a time.
// A change to lc_cluster_bound, lc_cosine_bound, lc_box_distance2 or
// lc_luminance (shaders/shared) must be made here too; the test fails until
// it is.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "shared/types.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lc::cpu {

#if defined(__SSE2__)
// Lanes (a, b, 0, 0).
inline __m128 lanes(float a, float b) { return _mm_setr_ps(a, b, 0.0f, 0.0f); }
// ((a.x * v_x + a.y * v_y) + a.z * v_z): glm's dot with a broadcast.
inline __m128 dot_lanes(glm::vec3 a, __m128 vx, __m128 vy, __m128 vz) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(a.x), vx), _mm_mul_ps(_mm_set1_ps(a.y), vy)),
                      _mm_mul_ps(_mm_set1_ps(a.z), vz));
}
inline __m128 abs_lanes(__m128 v) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), v); }
#endif

// Whether the pair evaluation covers this child.
inline bool pair_bound_covers(const gpu::LightNode& node) {
    const std::uint32_t type = (node.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    return (node.flags & gpu::kNodeLeaf) == 0u && type != gpu::kLightDirectional && node.cos_theta_o <= -1.0f;
}

// lc_cluster_error of `left` and `right` into `errors`, or false where the
// pair evaluation does not cover them. `kernel` is a kernel struct of
// host/cpu_kernel.h (its constants, lc_ggx_bound and lc_falloff_clamp2).
template <class Kernel, class SurfacePoint>
bool pair_errors(Kernel& kernel, const SurfacePoint& sp, const gpu::Material& m, const gpu::LightNode& left,
                 const gpu::LightNode& right, float min_distance2, glm::vec2& errors) {
#if defined(__SSE2__)
    if (!pair_bound_covers(left) || !pair_bound_covers(right) || (m.flags & gpu::kMaterialDisney) != 0u)
        return false;
    const __m128 half = _mm_set1_ps(0.5f), zero = _mm_setzero_ps();
    const __m128 px = _mm_set1_ps(sp.p.x), py = _mm_set1_ps(sp.p.y), pz = _mm_set1_ps(sp.p.z);
    const __m128 min_x = lanes(left.min_x, right.min_x), min_y = lanes(left.min_y, right.min_y),
                 min_z = lanes(left.min_z, right.min_z);
    const __m128 max_x = lanes(left.max_x, right.max_x), max_y = lanes(left.max_y, right.max_y),
                 max_z = lanes(left.max_z, right.max_z);
    // lc_cosine_bound.
    const __m128 lo_x = _mm_sub_ps(min_x, px), lo_y = _mm_sub_ps(min_y, py), lo_z = _mm_sub_ps(min_z, pz);
    const __m128 hi_x = _mm_sub_ps(max_x, px), hi_y = _mm_sub_ps(max_y, py), hi_z = _mm_sub_ps(max_z, pz);
    const __m128 c_x = _mm_mul_ps(half, _mm_add_ps(lo_x, hi_x)), c_y = _mm_mul_ps(half, _mm_add_ps(lo_y, hi_y)),
                 c_z = _mm_mul_ps(half, _mm_add_ps(lo_z, hi_z));
    const __m128 e_x = _mm_mul_ps(half, _mm_sub_ps(hi_x, lo_x)), e_y = _mm_mul_ps(half, _mm_sub_ps(hi_y, lo_y)),
                 e_z = _mm_mul_ps(half, _mm_sub_ps(hi_z, lo_z));
    const glm::vec3 an = glm::vec3(std::fabs(sp.n.x), std::fabs(sp.n.y), std::fabs(sp.n.z));
    const __m128 ne = dot_lanes(an, e_x, e_y, e_z);
    const __m128 z_max = _mm_add_ps(
        _mm_add_ps(dot_lanes(sp.n, c_x, c_y, c_z), ne),
        _mm_mul_ps(_mm_set1_ps(Kernel::kCosineAbsSlack),
                   _mm_add_ps(dot_lanes(an, abs_lanes(c_x), abs_lanes(c_y), abs_lanes(c_z)), ne)));
    const glm::vec3 at = glm::vec3(std::fabs(sp.t.x), std::fabs(sp.t.y), std::fabs(sp.t.z));
    const glm::vec3 ab = glm::vec3(std::fabs(sp.b.x), std::fabs(sp.b.y), std::fabs(sp.b.z));
    const __m128 near_x =
        _mm_max_ps(_mm_sub_ps(abs_lanes(dot_lanes(sp.t, c_x, c_y, c_z)), dot_lanes(at, e_x, e_y, e_z)), zero);
    const __m128 near_y =
        _mm_max_ps(_mm_sub_ps(abs_lanes(dot_lanes(sp.b, c_x, c_y, c_z)), dot_lanes(ab, e_x, e_y, e_z)), zero);
    const __m128 q = _mm_add_ps(_mm_add_ps(_mm_mul_ps(near_x, near_x), _mm_mul_ps(near_y, near_y)),
                                _mm_mul_ps(z_max, z_max));
    const __m128 bound = _mm_mul_ps(z_max, _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(q)));
    const __m128 cos_bound = _mm_min_ps(_mm_mul_ps(bound, _mm_set1_ps(Kernel::kBoundSlack)), _mm_set1_ps(1.0f));
    // z_max <= 0 returns 0 there, and so cos_bound <= 0 here.
    alignas(16) float cosines[4];
    _mm_store_ps(cosines, _mm_and_ps(cos_bound, _mm_cmpgt_ps(z_max, zero)));
    if (!(cosines[0] > 0.0f) && !(cosines[1] > 0.0f)) {
        errors = glm::vec2(0.0f);
        return true;
    }
    // The falloff: kBoundSlack / max(lc_box_distance2, the clamp).
    const __m128 d_x = _mm_max_ps(_mm_max_ps(lo_x, _mm_sub_ps(px, max_x)), zero);
    const __m128 d_y = _mm_max_ps(_mm_max_ps(lo_y, _mm_sub_ps(py, max_y)), zero);
    const __m128 d_z = _mm_max_ps(_mm_max_ps(lo_z, _mm_sub_ps(pz, max_z)), zero);
    const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d_x, d_x), _mm_mul_ps(d_y, d_y)), _mm_mul_ps(d_z, d_z));
    const std::uint32_t type_left = (left.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    const std::uint32_t type_right = (right.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    const __m128 clamp = lanes(kernel.lc_falloff_clamp2(min_distance2, type_left),
                               kernel.lc_falloff_clamp2(min_distance2, type_right));
    const __m128 factor = _mm_div_ps(_mm_set1_ps(Kernel::kBoundSlack), _mm_max_ps(d2, clamp));
    // lc_kd(m) * (cos_bound / kPi) [+ lc_ks(m) * lc_ggx_bound], times factor.
    const __m128 cos_over_pi = _mm_div_ps(_mm_load_ps(cosines), _mm_set1_ps(Kernel::kPi));
    __m128 r = _mm_mul_ps(_mm_set1_ps(m.kd_r), cos_over_pi);
    __m128 g = _mm_mul_ps(_mm_set1_ps(m.kd_g), cos_over_pi);
    __m128 b = _mm_mul_ps(_mm_set1_ps(m.kd_b), cos_over_pi);
    if ((m.flags & gpu::kMaterialHasSpecular) != 0u) {
        const float ggx_left = cosines[0] > 0.0f ? kernel.lc_ggx_bound(m, glm::vec3(left.min_x, left.min_y, left.min_z),
                                                                      glm::vec3(left.max_x, left.max_y, left.max_z),
                                                                      sp.p, sp.n, sp.wo)
                                                 : 0.0f;
        const float ggx_right =
            cosines[1] > 0.0f ? kernel.lc_ggx_bound(m, glm::vec3(right.min_x, right.min_y, right.min_z),
                                                    glm::vec3(right.max_x, right.max_y, right.max_z), sp.p, sp.n, sp.wo)
                              : 0.0f;
        const __m128 ggx = lanes(ggx_left, ggx_right);
        r = _mm_add_ps(r, _mm_mul_ps(_mm_set1_ps(m.ks_r), ggx));
        g = _mm_add_ps(g, _mm_mul_ps(_mm_set1_ps(m.ks_g), ggx));
        b = _mm_add_ps(b, _mm_mul_ps(_mm_set1_ps(m.ks_b), ggx));
    }
    r = _mm_mul_ps(_mm_mul_ps(r, factor), lanes(left.intensity_r, right.intensity_r));
    g = _mm_mul_ps(_mm_mul_ps(g, factor), lanes(left.intensity_g, right.intensity_g));
    b = _mm_mul_ps(_mm_mul_ps(b, factor), lanes(left.intensity_b, right.intensity_b));
    // lc_luminance.
    const __m128 error = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(_mm_set1_ps(0.2126f), r), _mm_mul_ps(_mm_set1_ps(0.7152f), g)),
        _mm_mul_ps(_mm_set1_ps(0.0722f), b));
    alignas(16) float out[4];
    _mm_store_ps(out, error);
    errors = glm::vec2(cosines[0] > 0.0f ? out[0] : 0.0f, cosines[1] > 0.0f ? out[1] : 0.0f);
    return true;
#else
    (void)kernel, (void)sp, (void)m, (void)left, (void)right, (void)min_distance2, (void)errors;
    return false;
#endif
}

}  // namespace lc::cpu
