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
//
// The quad functions below do the same for one cluster at the four shaded
// points of a 2x2 quad (host/quad_cut.h), the points in the lanes: its
// bound (quad_errors, with the GGX lobe's, quad_ggx_bounds) and its
// representative's contribution (quad_light_units), bit for bit the scalar
// functions' (tests/test_quad_cut.cpp).
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
// glm's min and max lane by lane, which the kernels' min and max are on the
// CPU: min(x, y) = y < x ? y : x and max(x, y) = x < y ? y : x, so a NaN in
// x is kept (and -0 or +0 chosen as there). _mm_min_ps(a, b) = a < b ? a : b,
// hence the swapped operands.
inline __m128 glsl_min(__m128 x, __m128 y) { return _mm_min_ps(y, x); }
inline __m128 glsl_max(__m128 x, __m128 y) { return _mm_max_ps(y, x); }
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
        glsl_max(_mm_sub_ps(abs_lanes(dot_lanes(sp.t, c_x, c_y, c_z)), dot_lanes(at, e_x, e_y, e_z)), zero);
    const __m128 near_y =
        glsl_max(_mm_sub_ps(abs_lanes(dot_lanes(sp.b, c_x, c_y, c_z)), dot_lanes(ab, e_x, e_y, e_z)), zero);
    const __m128 q = _mm_add_ps(_mm_add_ps(_mm_mul_ps(near_x, near_x), _mm_mul_ps(near_y, near_y)),
                                _mm_mul_ps(z_max, z_max));
    const __m128 bound = _mm_mul_ps(z_max, _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(q)));
    const __m128 cos_bound = glsl_min(_mm_mul_ps(bound, _mm_set1_ps(Kernel::kBoundSlack)), _mm_set1_ps(1.0f));
    // z_max <= 0 returns 0 there, and so cos_bound <= 0 here.
    alignas(16) float cosines[4];
    _mm_store_ps(cosines, _mm_and_ps(cos_bound, _mm_cmpgt_ps(z_max, zero)));
    if (!(cosines[0] > 0.0f) && !(cosines[1] > 0.0f)) {
        errors = glm::vec2(0.0f);
        return true;
    }
    // The falloff: kBoundSlack / max(lc_box_distance2, the clamp).
    const __m128 d_x = glsl_max(glsl_max(lo_x, _mm_sub_ps(px, max_x)), zero);
    const __m128 d_y = glsl_max(glsl_max(lo_y, _mm_sub_ps(py, max_y)), zero);
    const __m128 d_z = glsl_max(glsl_max(lo_z, _mm_sub_ps(pz, max_z)), zero);
    const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d_x, d_x), _mm_mul_ps(d_y, d_y)), _mm_mul_ps(d_z, d_z));
    const std::uint32_t type_left = (left.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    const std::uint32_t type_right = (right.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    const __m128 clamp = lanes(kernel.lc_falloff_clamp2(min_distance2, type_left),
                               kernel.lc_falloff_clamp2(min_distance2, type_right));
    const __m128 factor = _mm_div_ps(_mm_set1_ps(Kernel::kBoundSlack), glsl_max(d2, clamp));
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

#if defined(__SSE2__)
// The four shaded points of a quad (host/quad_cut.h) lane by lane, for
// quad_errors: positions, frames and the diffuse colours.
struct QuadLanes {
    __m128 px, py, pz;
    __m128 nx, ny, nz, anx, any, anz;
    __m128 tx, ty, tz, atx, aty, atz;
    __m128 bx, by, bz, abx, aby, abz;
    __m128 kd_r, kd_g, kd_b;
    __m128 wox, woy, woz, alpha;  // the view direction and the GGX roughness
    __m128 active;        // all ones in the lanes of active points
    unsigned specular;    // lanes whose material has a GGX lobe
    bool covered = false; // no active point has the Disney BRDF
};

template <class SurfacePoint>
QuadLanes quad_lanes(const SurfacePoint* sp, unsigned active) {
    QuadLanes q;
    alignas(16) float v[28][4];
    alignas(16) std::uint32_t mask[4];
    q.specular = 0u;
    q.covered = true;
    for (unsigned p = 0; p < 4u; ++p) {
        const bool on = (active >> p & 1u) != 0u;
        mask[p] = on ? ~0u : 0u;
        const SurfacePoint& s = sp[p];
        const glm::vec3 zero(0.0f);
        const glm::vec3 pos = on ? s.p : zero, n = on ? s.n : zero, t = on ? s.t : zero, b = on ? s.b : zero;
        const float f[28] = {pos.x, pos.y, pos.z, n.x, n.y, n.z, std::fabs(n.x), std::fabs(n.y), std::fabs(n.z),
                             t.x, t.y, t.z, std::fabs(t.x), std::fabs(t.y), std::fabs(t.z),
                             b.x, b.y, b.z, std::fabs(b.x), std::fabs(b.y), std::fabs(b.z),
                             on ? s.mat.kd_r : 0.0f, on ? s.mat.kd_g : 0.0f, on ? s.mat.kd_b : 0.0f,
                             on ? s.wo.x : 0.0f, on ? s.wo.y : 0.0f, on ? s.wo.z : 0.0f,
                             on ? s.mat.alpha : 1.0f};
        for (unsigned i = 0; i < 28u; ++i) v[i][p] = f[i];
        if (!on) continue;
        if ((s.mat.flags & gpu::kMaterialDisney) != 0u) q.covered = false;
        if ((s.mat.flags & gpu::kMaterialHasSpecular) != 0u) q.specular |= 1u << p;
    }
    __m128* out[28] = {&q.px, &q.py, &q.pz, &q.nx, &q.ny, &q.nz, &q.anx, &q.any, &q.anz,
                       &q.tx, &q.ty, &q.tz, &q.atx, &q.aty, &q.atz, &q.bx, &q.by, &q.bz,
                       &q.abx, &q.aby, &q.abz, &q.kd_r, &q.kd_g, &q.kd_b, &q.wox, &q.woy, &q.woz, &q.alpha};
    for (unsigned i = 0; i < 28u; ++i) *out[i] = _mm_load_ps(v[i]);
    q.active = _mm_load_ps(reinterpret_cast<const float*>(mask));
    return q;
}

// ((a_x * v_x + a_y * v_y) + a_z * v_z) lane by lane: glm's dot.
inline __m128 dot4(__m128 ax, __m128 ay, __m128 az, __m128 vx, __m128 vy, __m128 vz) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, vx), _mm_mul_ps(ay, vy)), _mm_mul_ps(az, vz));
}

// lc_ggx_bound of one box at the quad's points, lane by lane, with the
// same operations in the same order as lc_ggx_bound, lc_box_cone,
// lc_cos_h_max, lc_ggx_d and lc_smith_g1: into ggx[p] for the lanes of
// `lanes`, 0 elsewhere.
template <class Kernel>
void quad_ggx_bounds(const QuadLanes& q, const gpu::LightNode& node, unsigned lanes, float ggx[4]) {
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), half = _mm_set1_ps(0.5f);
    // cos_o = dot(n, wo); the lanes with cos_o <= 0 give 0.
    const __m128 cos_o = dot4(q.nx, q.ny, q.nz, q.wox, q.woy, q.woz);
    // lc_box_cone: the box seen from each point.
    const __m128 c_x = _mm_mul_ps(half, _mm_add_ps(_mm_sub_ps(_mm_set1_ps(node.min_x), q.px),
                                                   _mm_sub_ps(_mm_set1_ps(node.max_x), q.px)));
    const __m128 c_y = _mm_mul_ps(half, _mm_add_ps(_mm_sub_ps(_mm_set1_ps(node.min_y), q.py),
                                                   _mm_sub_ps(_mm_set1_ps(node.max_y), q.py)));
    const __m128 c_z = _mm_mul_ps(half, _mm_add_ps(_mm_sub_ps(_mm_set1_ps(node.min_z), q.pz),
                                                   _mm_sub_ps(_mm_set1_ps(node.max_z), q.pz)));
    const glm::vec3 extent(node.max_x - node.min_x, node.max_y - node.min_y, node.max_z - node.min_z);
    const __m128 radius = _mm_set1_ps(0.5f * std::sqrt((extent.x * extent.x + extent.y * extent.y) +
                                                       extent.z * extent.z));
    const __m128 dist = _mm_sqrt_ps(dot4(c_x, c_y, c_z, c_x, c_y, c_z));
    const __m128 outside = _mm_cmpgt_ps(dist, radius);  // else any direction: cos_h_max = 1
    const __m128 a_x = _mm_div_ps(c_x, dist), a_y = _mm_div_ps(c_y, dist), a_z = _mm_div_ps(c_z, dist);
    const __m128 sin_c = glsl_min(_mm_div_ps(radius, dist), one);
    // lc_cos_h_max.
    const __m128 two_cos_o = _mm_mul_ps(_mm_set1_ps(2.0f), cos_o);
    const __m128 wr_x = _mm_sub_ps(_mm_mul_ps(two_cos_o, q.nx), q.wox);
    const __m128 wr_y = _mm_sub_ps(_mm_mul_ps(two_cos_o, q.ny), q.woy);
    const __m128 wr_z = _mm_sub_ps(_mm_mul_ps(two_cos_o, q.nz), q.woz);
    const __m128 cos_r = dot4(wr_x, wr_y, wr_z, a_x, a_y, a_z);
    const __m128 cos_c = _mm_sqrt_ps(glsl_max(_mm_sub_ps(one, _mm_mul_ps(sin_c, sin_c)), zero));
    const __m128 in_cone = _mm_cmpge_ps(cos_r, cos_c);  // the mirror direction in the cone: 1
    const __m128 x_x = _mm_sub_ps(_mm_mul_ps(wr_y, a_z), _mm_mul_ps(a_y, wr_z));
    const __m128 x_y = _mm_sub_ps(_mm_mul_ps(wr_z, a_x), _mm_mul_ps(a_z, wr_x));
    const __m128 x_z = _mm_sub_ps(_mm_mul_ps(wr_x, a_y), _mm_mul_ps(a_x, wr_y));
    const __m128 sin_r = _mm_sqrt_ps(dot4(x_x, x_y, x_z, x_x, x_y, x_z));
    const __m128 cos_delta = glsl_min(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(cos_r, cos_c), _mm_mul_ps(sin_r, sin_c)), _mm_set1_ps(Kernel::kCosineAbsSlack)),
        one);
    const __m128 narrowed = glsl_min(
        _mm_mul_ps(_mm_sqrt_ps(glsl_max(_mm_add_ps(half, _mm_mul_ps(half, cos_delta)), zero)),
                   _mm_set1_ps(Kernel::kBoundSlack)),
        one);
    const __m128 wide = _mm_andnot_ps(outside, one);
    const __m128 narrow = _mm_and_ps(outside, _mm_or_ps(_mm_and_ps(in_cone, one), _mm_andnot_ps(in_cone, narrowed)));
    const __m128 cos_h = _mm_or_ps(wide, narrow);
    // lc_ggx_d(cos_h, alpha) * lc_smith_g1(cos_o, alpha) / (4 cos_o) * kBoundSlack.
    const __m128 a2 = _mm_mul_ps(q.alpha, q.alpha);
    const __m128 c2 = _mm_mul_ps(cos_h, cos_h);
    const __m128 denom = _mm_add_ps(_mm_sub_ps(one, c2), _mm_mul_ps(a2, c2));
    const __m128 d = _mm_div_ps(a2, _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(Kernel::kPi), denom), denom));
    const __m128 g1 = _mm_div_ps(
        _mm_mul_ps(_mm_set1_ps(2.0f), cos_o),
        _mm_add_ps(cos_o, _mm_sqrt_ps(_mm_add_ps(a2, _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(one, a2), cos_o), cos_o)))));
    const __m128 bound = _mm_mul_ps(_mm_div_ps(_mm_mul_ps(d, g1), _mm_mul_ps(_mm_set1_ps(4.0f), cos_o)),
                                    _mm_set1_ps(Kernel::kBoundSlack));
    alignas(16) float out[4];
    _mm_store_ps(out, _mm_and_ps(bound, _mm_cmpnle_ps(cos_o, zero)));  // lc_ggx_bound: 0 where cos_o <= 0
    for (unsigned p = 0; p < 4u; ++p) ggx[p] = (lanes >> p & 1u) != 0u ? out[p] : 0.0f;
}

// lc_cluster_error of one `node` at the quad's four points, into errors[p]
// (zero in inactive lanes), or false where this evaluation does not cover
// them (the cases pair_errors leaves out). The same operations in the same
// order as lc_cluster_bound, so the values are the scalar ones bit for bit.
template <class Kernel, class SurfacePoint>
bool quad_errors(Kernel& kernel, const QuadLanes& q, const SurfacePoint* sp, const gpu::LightNode& node,
                 float min_distance2, float errors[4]) {
    if (!q.covered || !pair_bound_covers(node)) return false;
    const __m128 half = _mm_set1_ps(0.5f), zero = _mm_setzero_ps();
    const __m128 min_x = _mm_set1_ps(node.min_x), min_y = _mm_set1_ps(node.min_y), min_z = _mm_set1_ps(node.min_z);
    const __m128 max_x = _mm_set1_ps(node.max_x), max_y = _mm_set1_ps(node.max_y), max_z = _mm_set1_ps(node.max_z);
    const __m128 lo_x = _mm_sub_ps(min_x, q.px), lo_y = _mm_sub_ps(min_y, q.py), lo_z = _mm_sub_ps(min_z, q.pz);
    const __m128 hi_x = _mm_sub_ps(max_x, q.px), hi_y = _mm_sub_ps(max_y, q.py), hi_z = _mm_sub_ps(max_z, q.pz);
    const __m128 c_x = _mm_mul_ps(half, _mm_add_ps(lo_x, hi_x)), c_y = _mm_mul_ps(half, _mm_add_ps(lo_y, hi_y)),
                 c_z = _mm_mul_ps(half, _mm_add_ps(lo_z, hi_z));
    const __m128 e_x = _mm_mul_ps(half, _mm_sub_ps(hi_x, lo_x)), e_y = _mm_mul_ps(half, _mm_sub_ps(hi_y, lo_y)),
                 e_z = _mm_mul_ps(half, _mm_sub_ps(hi_z, lo_z));
    const __m128 ne = dot4(q.anx, q.any, q.anz, e_x, e_y, e_z);
    const __m128 z_max = _mm_add_ps(
        _mm_add_ps(dot4(q.nx, q.ny, q.nz, c_x, c_y, c_z), ne),
        _mm_mul_ps(_mm_set1_ps(Kernel::kCosineAbsSlack),
                   _mm_add_ps(dot4(q.anx, q.any, q.anz, abs_lanes(c_x), abs_lanes(c_y), abs_lanes(c_z)), ne)));
    const __m128 near_x = glsl_max(
        _mm_sub_ps(abs_lanes(dot4(q.tx, q.ty, q.tz, c_x, c_y, c_z)), dot4(q.atx, q.aty, q.atz, e_x, e_y, e_z)), zero);
    const __m128 near_y = glsl_max(
        _mm_sub_ps(abs_lanes(dot4(q.bx, q.by, q.bz, c_x, c_y, c_z)), dot4(q.abx, q.aby, q.abz, e_x, e_y, e_z)), zero);
    const __m128 qq = _mm_add_ps(_mm_add_ps(_mm_mul_ps(near_x, near_x), _mm_mul_ps(near_y, near_y)),
                                 _mm_mul_ps(z_max, z_max));
    const __m128 bound = _mm_mul_ps(z_max, _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(qq)));
    const __m128 cos_bound = glsl_min(_mm_mul_ps(bound, _mm_set1_ps(Kernel::kBoundSlack)), _mm_set1_ps(1.0f));
    // lc_cosine_bound and lc_cluster_bound return 0 where z_max <= 0 or the
    // cosine bound <= 0 (a NaN goes on, as there).
    const __m128 lit = _mm_and_ps(_mm_cmpnle_ps(z_max, zero), q.active);
    alignas(16) float cosines[4];
    _mm_store_ps(cosines, _mm_and_ps(cos_bound, lit));
    const __m128 positive = _mm_and_ps(_mm_cmpnle_ps(_mm_load_ps(cosines), zero), q.active);
    if (_mm_movemask_ps(positive) == 0) {
        for (unsigned p = 0; p < 4u; ++p) errors[p] = 0.0f;
        return true;
    }
    const __m128 d_x = glsl_max(glsl_max(lo_x, _mm_sub_ps(q.px, max_x)), zero);
    const __m128 d_y = glsl_max(glsl_max(lo_y, _mm_sub_ps(q.py, max_y)), zero);
    const __m128 d_z = glsl_max(glsl_max(lo_z, _mm_sub_ps(q.pz, max_z)), zero);
    const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d_x, d_x), _mm_mul_ps(d_y, d_y)), _mm_mul_ps(d_z, d_z));
    const std::uint32_t type = (node.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    const __m128 clamp = _mm_set1_ps(kernel.lc_falloff_clamp2(min_distance2, type));
    const __m128 factor = _mm_div_ps(_mm_set1_ps(Kernel::kBoundSlack), glsl_max(d2, clamp));
    const __m128 cos_over_pi = _mm_div_ps(_mm_load_ps(cosines), _mm_set1_ps(Kernel::kPi));
    __m128 r = _mm_mul_ps(q.kd_r, cos_over_pi);
    __m128 g = _mm_mul_ps(q.kd_g, cos_over_pi);
    __m128 b = _mm_mul_ps(q.kd_b, cos_over_pi);
    if (q.specular != 0u) {
        alignas(16) float ks[3][4] = {}, ggx[4] = {};
        unsigned lanes = 0u;
        for (unsigned p = 0; p < 4u; ++p) {
            if ((q.specular >> p & 1u) == 0u || cosines[p] <= 0.0f) continue;
            lanes |= 1u << p;
            ks[0][p] = sp[p].mat.ks_r;
            ks[1][p] = sp[p].mat.ks_g;
            ks[2][p] = sp[p].mat.ks_b;
        }
        quad_ggx_bounds<Kernel>(q, node, lanes, ggx);
        const __m128 gv = _mm_load_ps(ggx);
        r = _mm_add_ps(r, _mm_mul_ps(_mm_load_ps(ks[0]), gv));
        g = _mm_add_ps(g, _mm_mul_ps(_mm_load_ps(ks[1]), gv));
        b = _mm_add_ps(b, _mm_mul_ps(_mm_load_ps(ks[2]), gv));
    }
    r = _mm_mul_ps(_mm_mul_ps(r, factor), _mm_set1_ps(node.intensity_r));
    g = _mm_mul_ps(_mm_mul_ps(g, factor), _mm_set1_ps(node.intensity_g));
    b = _mm_mul_ps(_mm_mul_ps(b, factor), _mm_set1_ps(node.intensity_b));
    const __m128 error = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(_mm_set1_ps(0.2126f), r), _mm_mul_ps(_mm_set1_ps(0.7152f), g)),
        _mm_mul_ps(_mm_set1_ps(0.0722f), b));
    alignas(16) float out[4];
    _mm_store_ps(out, _mm_and_ps(error, positive));
    for (unsigned p = 0; p < 4u; ++p) errors[p] = out[p];
    return true;
}

// lc_light_unit of one point `light` at the quad's four points, lane by
// lane, into unit[p] (zero in inactive lanes), and for each point where the
// unit is not zero the shadow ray's direction wi[p] and length t_max[p]:
// the scalar function's values bit for bit (tests/test_quad_cut.cpp). False
// where this does not cover the case: a light that is not a point light, or
// a Disney material at an active point. Points with a GGX lobe get their
// BRDF from the scalar lc_brdf_cos, on the direction and cosine computed
// here. A change to lc_light_unit or lc_brdf_cos (shaders/shared/shading.h)
// must be made here too; the test fails until it is.
template <class Kernel, class SurfacePoint>
bool quad_light_units(Kernel& kernel, const QuadLanes& q, const SurfacePoint* sp, const gpu::Light& light,
                      float min_distance2, glm::vec3 unit[4], glm::vec3 wi[4], float t_max[4]) {
    if (!q.covered || (light.type & gpu::kLightTypeMask) != gpu::kLightPoint) return false;
    const __m128 zero = _mm_setzero_ps();
    const __m128 tx = _mm_sub_ps(_mm_set1_ps(light.x), q.px), ty = _mm_sub_ps(_mm_set1_ps(light.y), q.py),
                 tz = _mm_sub_ps(_mm_set1_ps(light.z), q.pz);
    const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz));
    const __m128 d = _mm_sqrt_ps(d2);
    const __m128 wx = _mm_div_ps(tx, d), wy = _mm_div_ps(ty, d), wz = _mm_div_ps(tz, d);
    const __m128 length = _mm_mul_ps(d, _mm_set1_ps(1.0f - Kernel::kShadowEndRelative));
    const __m128 factor = _mm_div_ps(
        _mm_set1_ps(1.0f), glsl_max(d2, _mm_set1_ps(kernel.lc_falloff_clamp2(min_distance2, gpu::kLightPoint))));
    const __m128 cos_i = dot4(q.nx, q.ny, q.nz, wx, wy, wz);
    // lc_light_unit's early returns: no direction (d = 0), the light behind
    // the surface, no emission towards it.
    const __m128 lit = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(d, zero), _mm_cmpnle_ps(cos_i, zero)),
                                  _mm_and_ps(_mm_cmpgt_ps(factor, zero), q.active));
    const __m128 c = _mm_div_ps(cos_i, _mm_set1_ps(Kernel::kPi));
    alignas(16) float v[9][4];
    _mm_store_ps(v[0], _mm_mul_ps(_mm_mul_ps(q.kd_r, c), factor));
    _mm_store_ps(v[1], _mm_mul_ps(_mm_mul_ps(q.kd_g, c), factor));
    _mm_store_ps(v[2], _mm_mul_ps(_mm_mul_ps(q.kd_b, c), factor));
    _mm_store_ps(v[3], wx);
    _mm_store_ps(v[4], wy);
    _mm_store_ps(v[5], wz);
    _mm_store_ps(v[6], length);
    _mm_store_ps(v[7], cos_i);
    _mm_store_ps(v[8], factor);
    const unsigned mask = unsigned(_mm_movemask_ps(lit));
    for (unsigned p = 0; p < 4u; ++p) {
        unit[p] = glm::vec3(0.0f);
        if ((mask >> p & 1u) == 0u) continue;
        wi[p] = glm::vec3(v[3][p], v[4][p], v[5][p]);
        t_max[p] = v[6][p];
        if ((q.specular >> p & 1u) != 0u)
            unit[p] = kernel.lc_brdf_cos(sp[p].mat, sp[p].n, wi[p], sp[p].wo, v[7][p]) * v[8][p];
        else
            unit[p] = glm::vec3(v[0][p], v[1][p], v[2][p]);
    }
    return true;
}
#endif

}  // namespace lc::cpu
