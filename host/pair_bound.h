// Both children's error bounds of a refinement at once, in two SSE lanes
// (lc_cut_refine through LC_CHILD_ERRORS, host/cpu_kernel.h). For the common
// case, point-like clusters that emit in every direction under a Lambert or
// Lambert + GGX material, it computes the cosine bound, the distance bound
// and the error of lc_cluster_bound / lc_cluster_error lane by lane, with the
// same operations in the same order, so the results are the scalar ones bit
// for bit (tests/test_lightcuts.cpp checks it); the GGX lobe's bound stays
// scalar. Every other case (leaves, directional or oriented clusters, the
// Disney BRDF) returns false; the caller (BasicShadeKernel::lc_child_errors)
// then takes the quad evaluation below with the point in one lane where it
// covers both children, else evaluates one child at a time.
// A change to lc_cluster_bound, lc_cosine_bound, lc_box_distance2 or
// lc_luminance (shaders/lc_shared) must be made here too; the test fails until
// it is.
//
// The quad functions below do the same for one cluster at the four shaded
// points of a 2x2 quad (host/quad_cut.h), the points in the lanes: its
// bound with the GGX lobe's, the Disney BRDF's and the emission cone's of
// spots, oriented lights and VPLs (quad_errors; the code in
// quad_bounds_body.h; a change to lc_emission_bound, lc_ggx_bound or
// lc_disney_bound must be made there too),
// two clusters' bounds at once where the CPU has AVX2
// (quad8::quad_pair_errors) and four where it has AVX-512
// (quad16::quad_four_errors), and a representative's contribution
// (quad_light_units; two at once, quad8::quad_light_units_pair; the code in
// quad_bounds_body.h, light_values), bit for bit the scalar functions'
// (tests/test_quad_cut.cpp).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "lc_shared/octahedral.h"
#include "lc_shared/types.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#include <immintrin.h>
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

// lc_decode_axis of two packed axes at once, with its operations lane by
// lane: the same vectors bit for bit (tests/test_quad_cut.cpp), without the
// scalar code's branch on the octahedron's lower half, which half the
// clusters of a tree take and the other half do not.
inline void decode_axis_pair(std::uint32_t a, std::uint32_t b, glm::vec3& axis_a, glm::vec3& axis_b) {
    const __m128i packed = _mm_setr_epi32(int(a), int(b), 0, 0);
    const __m128 lo = _mm_cvtepi32_ps(_mm_srai_epi32(_mm_slli_epi32(packed, 16), 16));
    const __m128 hi = _mm_cvtepi32_ps(_mm_srai_epi32(packed, 16));
    const __m128 one = _mm_set1_ps(1.0f), minus_one = _mm_set1_ps(-1.0f), scale = _mm_set1_ps(32767.0f);
    const __m128 ex = glsl_min(glsl_max(_mm_div_ps(lo, scale), minus_one), one);
    const __m128 ey = glsl_min(glsl_max(_mm_div_ps(hi, scale), minus_one), one);
    const __m128 ax = abs_lanes(ex), ay = abs_lanes(ey);
    const __m128 z = _mm_sub_ps(_mm_sub_ps(one, ax), ay);
    // Below the equator: x = (1 - |y|) sign(x), y = (1 - |x|) sign(y), with
    // sign(0) = 1 as there.
    const __m128 below = _mm_cmplt_ps(z, _mm_setzero_ps());
    const __m128 sign_x = _mm_or_ps(_mm_and_ps(_mm_cmpge_ps(ex, _mm_setzero_ps()), one),
                                    _mm_andnot_ps(_mm_cmpge_ps(ex, _mm_setzero_ps()), minus_one));
    const __m128 sign_y = _mm_or_ps(_mm_and_ps(_mm_cmpge_ps(ey, _mm_setzero_ps()), one),
                                    _mm_andnot_ps(_mm_cmpge_ps(ey, _mm_setzero_ps()), minus_one));
    const __m128 fx = _mm_mul_ps(_mm_sub_ps(one, ay), sign_x), fy = _mm_mul_ps(_mm_sub_ps(one, ax), sign_y);
    const __m128 x = _mm_or_ps(_mm_and_ps(below, fx), _mm_andnot_ps(below, ex));
    const __m128 y = _mm_or_ps(_mm_and_ps(below, fy), _mm_andnot_ps(below, ey));
    // glm::normalize: v * (1 / sqrt(dot(v, v))).
    const __m128 r = _mm_div_ps(one, _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)),
                                                            _mm_mul_ps(z, z))));
    alignas(16) float v[3][4];
    _mm_store_ps(v[0], _mm_mul_ps(x, r));
    _mm_store_ps(v[1], _mm_mul_ps(y, r));
    _mm_store_ps(v[2], _mm_mul_ps(z, r));
    axis_a = glm::vec3(v[0][0], v[1][0], v[2][0]);
    axis_b = glm::vec3(v[0][1], v[1][1], v[2][1]);
}
#endif

// Whether the pair evaluation covers this child.
inline bool pair_bound_covers(const gpu::LightNode& node) {
    const std::uint32_t type = (node.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    return (node.flags & gpu::kNodeLeaf) == 0u && type != gpu::kLightDirectional && node.cos_theta_o <= -1.0f;
}

// Whether the quad evaluations cover this cluster: the pair evaluation's
// clusters and those with emission cones (spots, oriented lights, VPLs).
inline bool quad_bound_covers(const gpu::LightNode& node) {
    const std::uint32_t type = (node.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
    return (node.flags & gpu::kNodeLeaf) == 0u && type != gpu::kLightDirectional;
}

// Whether quad_light_units covers this light: not a directional one.
inline bool quad_units_cover(const gpu::Light& light) {
    const std::uint32_t type = light.type & gpu::kLightTypeMask;
    return type != gpu::kLightDirectional && type <= gpu::kLightVpl;
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
// QuadLanes' vector fields (quad_bounds_body.h), for the copies of one
// width's lanes into a wider one's (quad8::widen, quad16::widen).
#define LC_QUAD_LANE_VECTORS(X)                                                                                     \
    X(px) X(py) X(pz) X(nx) X(ny) X(nz) X(anx) X(any) X(anz) X(tx) X(ty) X(tz) X(atx) X(aty) X(atz) X(bx) X(by)   \
    X(bz) X(abx) X(aby) X(abz) X(kd_r) X(kd_g) X(kd_b) X(ks_r) X(ks_g) X(ks_b) X(wox) X(woy) X(woz) X(cos_o)       \
    X(wr_x) X(wr_y) X(wr_z) X(a2) X(g1) X(four_cos_o) X(active) X(specular_lanes) X(disney_lanes) X(sheen_lanes)   \
    X(coat_lanes) X(one_minus_metallic) X(two_roughness) X(schlick_o) X(spec0_r) X(spec0_g) X(spec0_b) X(sheen_r) \
    X(sheen_g) X(sheen_b) X(coat_weight) X(coat_a2) X(coat_a2_minus_1) X(coat_pi_log) X(coat_g1)

// The quad evaluation with the four points in the four SSE lanes.
namespace quad4 {
using V = __m128;
inline V v_set1(float x) { return _mm_set1_ps(x); }
inline V v_zero() { return _mm_setzero_ps(); }
inline V v_add(V a, V b) { return _mm_add_ps(a, b); }
inline V v_sub(V a, V b) { return _mm_sub_ps(a, b); }
inline V v_mul(V a, V b) { return _mm_mul_ps(a, b); }
inline V v_div(V a, V b) { return _mm_div_ps(a, b); }
inline V v_sqrt(V a) { return _mm_sqrt_ps(a); }
inline V v_and(V a, V b) { return _mm_and_ps(a, b); }
inline V v_andnot(V a, V b) { return _mm_andnot_ps(a, b); }
inline V v_or(V a, V b) { return _mm_or_ps(a, b); }
inline V v_cmpgt(V a, V b) { return _mm_cmpgt_ps(a, b); }
inline V v_cmpge(V a, V b) { return _mm_cmpge_ps(a, b); }
inline V v_cmpnle(V a, V b) { return _mm_cmpnle_ps(a, b); }
inline V v_abs(V a) { return abs_lanes(a); }
inline V v_min(V x, V y) { return glsl_min(x, y); }
inline V v_max(V x, V y) { return glsl_max(x, y); }
inline int v_movemask(V a) { return _mm_movemask_ps(a); }
inline V v_set2(float a, float) { return _mm_set1_ps(a); }  // one cluster in all four lanes
#include "quad_bounds_body.h"
}  // namespace quad4

using QuadLanes = quad4::QuadLanes;
using quad4::dot4;

// The four shaded points of a quad (host/quad_cut.h) lane by lane.
template <class Kernel, class SurfacePoint>
QuadLanes quad_lanes(Kernel& kernel, const SurfacePoint* sp, unsigned active) {
    QuadLanes q;
    alignas(16) float v[31][4];
    alignas(16) std::uint32_t mask[2][4];
    q.specular = 0u;
    q.covered = true;
    // The Disney terms (QuadLanes), each from the scalar function
    // lc_disney_bound calls, so that the lanes hold its very floats.
    alignas(16) float d[14][4] = {};
    alignas(16) std::uint32_t dmask[3][4] = {};
    for (unsigned p = 0; p < 4u; ++p) {
        const bool on = (active >> p & 1u) != 0u;
        const SurfacePoint& s = sp[p];
        const bool specular = on && (s.mat.flags & gpu::kMaterialHasSpecular) != 0u;
        mask[0][p] = on ? ~0u : 0u;
        mask[1][p] = specular ? ~0u : 0u;
        const glm::vec3 zero(0.0f);
        const glm::vec3 pos = on ? s.p : zero, n = on ? s.n : zero, t = on ? s.t : zero, b = on ? s.b : zero;
        const float f[31] = {pos.x, pos.y, pos.z, n.x, n.y, n.z, std::fabs(n.x), std::fabs(n.y), std::fabs(n.z),
                             t.x, t.y, t.z, std::fabs(t.x), std::fabs(t.y), std::fabs(t.z),
                             b.x, b.y, b.z, std::fabs(b.x), std::fabs(b.y), std::fabs(b.z),
                             on ? s.mat.kd_r : 0.0f, on ? s.mat.kd_g : 0.0f, on ? s.mat.kd_b : 0.0f,
                             specular ? s.mat.ks_r : 0.0f, specular ? s.mat.ks_g : 0.0f, specular ? s.mat.ks_b : 0.0f,
                             on ? s.wo.x : 0.0f, on ? s.wo.y : 0.0f, on ? s.wo.z : 0.0f,
                             on ? s.mat.alpha : 1.0f};
        for (unsigned i = 0; i < 31u; ++i) v[i][p] = f[i];
        if (!on) continue;
        if (specular) q.specular |= 1u << p;
        if ((s.mat.flags & gpu::kMaterialDisney) == 0u || !Kernel::kEnableDisney) continue;
        if (Kernel::seed_lobe_bound) q.covered = false;  // a benchmark's bound: the scalar code's
        q.disney |= 1u << p;
        const gpu::Material& m = s.mat;
        const float cos_o = glm::dot(s.n, s.wo);
        const bool sheen = Kernel::kEnableSheen && (m.flags & gpu::kMaterialHasSheen) != 0u;
        const bool coat = Kernel::kEnableClearcoat && (m.flags & gpu::kMaterialHasClearcoat) != 0u;
        const glm::vec3 spec0 = kernel.lc_disney_spec0(m);
        const glm::vec3 sheen_color = sheen ? kernel.lc_disney_sheen_color(m) : glm::vec3(0.0f);
        const float alpha_c = kernel.lc_clearcoat_alpha(m), a2 = alpha_c * alpha_c;
        const float terms[14] = {1.0f - m.metallic,
                                 2.0f * m.roughness,
                                 kernel.lc_schlick_weight(cos_o),
                                 spec0.x, spec0.y, spec0.z,
                                 sheen_color.x, sheen_color.y, sheen_color.z,
                                 0.25f * m.clearcoat,
                                 a2,
                                 a2 - 1.0f,
                                 Kernel::kPi * std::log(a2),
                                 kernel.lc_smith_g1(cos_o, Kernel::kClearcoatSmithAlpha)};
        for (unsigned i = 0; i < 14u; ++i) d[i][p] = terms[i];
        dmask[0][p] = ~0u;
        dmask[1][p] = sheen ? ~0u : 0u;
        dmask[2][p] = coat ? ~0u : 0u;
    }
    __m128* disney_out[14] = {&q.one_minus_metallic, &q.two_roughness, &q.schlick_o, &q.spec0_r, &q.spec0_g,
                              &q.spec0_b, &q.sheen_r, &q.sheen_g, &q.sheen_b, &q.coat_weight, &q.coat_a2,
                              &q.coat_a2_minus_1, &q.coat_pi_log, &q.coat_g1};
    for (unsigned i = 0; i < 14u; ++i) *disney_out[i] = _mm_load_ps(d[i]);
    q.disney_lanes = _mm_load_ps(reinterpret_cast<const float*>(dmask[0]));
    q.sheen_lanes = _mm_load_ps(reinterpret_cast<const float*>(dmask[1]));
    q.coat_lanes = _mm_load_ps(reinterpret_cast<const float*>(dmask[2]));
    __m128* out[30] = {&q.px, &q.py, &q.pz, &q.nx, &q.ny, &q.nz, &q.anx, &q.any, &q.anz,
                       &q.tx, &q.ty, &q.tz, &q.atx, &q.aty, &q.atz, &q.bx, &q.by, &q.bz,
                       &q.abx, &q.aby, &q.abz, &q.kd_r, &q.kd_g, &q.kd_b, &q.ks_r, &q.ks_g, &q.ks_b,
                       &q.wox, &q.woy, &q.woz};
    for (unsigned i = 0; i < 30u; ++i) *out[i] = _mm_load_ps(v[i]);
    quad4::set_ggx_terms(q, _mm_load_ps(v[30]));
    q.active = _mm_load_ps(reinterpret_cast<const float*>(mask[0]));
    q.specular_lanes = _mm_load_ps(reinterpret_cast<const float*>(mask[1]));
    return q;
}

// lc_cluster_error of one `node` at the quad's four points, into errors[p]
// (zero in inactive lanes), or false where this evaluation does not cover
// them (the cases pair_errors leaves out). The same operations in the same
// order as lc_cluster_bound, so the values are the scalar ones bit for bit.
template <class Kernel, class SurfacePoint>
bool quad_errors(Kernel& kernel, const QuadLanes& q, const SurfacePoint* sp, const gpu::LightNode& node,
                 float min_distance2, float errors[4]) {
    (void)sp;
    if (!q.covered || !quad_bound_covers(node)) return false;
    const quad4::QuadNodes n =
        quad4::quad_nodes(kernel, node, node, min_distance2, q.specular != 0u || q.disney != 0u);
    __m128 e;
    quad4::cluster_errors<Kernel>(q, n, e);
    _mm_storeu_ps(errors, e);
    return true;
}

// The same for two clusters at once, in the eight lanes of AVX2: the first
// in lanes 0-3, the second in lanes 4-7, the points in both halves. A
// refinement's two children take one evaluation instead of two. Built for
// AVX2 (and taken where the CPU has it, host/quad_cut.h); the build's
// -ffp-contract=off keeps every multiply and add apart, so the values are
// the SSE ones and the scalar ones, bit for bit.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace quad8 {
using V = __m256;
inline V v_set1(float x) { return _mm256_set1_ps(x); }
inline V v_zero() { return _mm256_setzero_ps(); }
inline V v_add(V a, V b) { return _mm256_add_ps(a, b); }
inline V v_sub(V a, V b) { return _mm256_sub_ps(a, b); }
inline V v_mul(V a, V b) { return _mm256_mul_ps(a, b); }
inline V v_div(V a, V b) { return _mm256_div_ps(a, b); }
inline V v_sqrt(V a) { return _mm256_sqrt_ps(a); }
inline V v_and(V a, V b) { return _mm256_and_ps(a, b); }
inline V v_andnot(V a, V b) { return _mm256_andnot_ps(a, b); }
inline V v_or(V a, V b) { return _mm256_or_ps(a, b); }
// The SSE compares' predicates: ordered (false for a NaN) for > and >=,
// unordered (true for a NaN) for "not <=".
inline V v_cmpgt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OS); }
inline V v_cmpge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OS); }
inline V v_cmpnle(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NLE_US); }
inline V v_abs(V a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a); }
inline V v_min(V x, V y) { return _mm256_min_ps(y, x); }
inline V v_max(V x, V y) { return _mm256_max_ps(y, x); }
inline int v_movemask(V a) { return _mm256_movemask_ps(a); }
inline V v_set2(float a, float b) { return _mm256_setr_ps(a, a, a, a, b, b, b, b); }
#include "quad_bounds_body.h"

inline V twice(__m128 v) { return _mm256_insertf128_ps(_mm256_castps128_ps256(v), v, 1); }

// The quad's lanes in both halves.
inline void widen(const quad4::QuadLanes& q, QuadLanes& w) {
#define LC_WIDEN(field) w.field = twice(q.field);
    LC_QUAD_LANE_VECTORS(LC_WIDEN)
#undef LC_WIDEN
    w.specular = q.specular;
    w.covered = q.covered;
    w.disney = q.disney;
}

// Two quads' lanes side by side: the first's points in lanes 0-3, the
// second's in 4-7 (a block of eight points, host/quad_cut.h). Given the
// same cluster twice, quad_pair_errors then gives its bound at the eight
// points, and quad_light_unit_lanes a light's units there.
inline void join(const quad4::QuadLanes& a, const quad4::QuadLanes& b, QuadLanes& w) {
#define LC_JOIN(field) w.field = _mm256_insertf128_ps(_mm256_castps128_ps256(a.field), b.field, 1);
    LC_QUAD_LANE_VECTORS(LC_JOIN)
#undef LC_JOIN
    w.specular = a.specular | b.specular << 4u;
    w.covered = a.covered && b.covered;
    w.disney = a.disney | b.disney << 4u;
}

// lc_cluster_error of `a` into errors_a[p] and of `b` into errors_b[p], at
// the quad's points (zero in inactive lanes). For clusters that
// quad_errors covers (the caller checks).
template <class Kernel>
void quad_pair_errors(Kernel& kernel, const QuadLanes& q, const gpu::LightNode& a, const gpu::LightNode& b,
                      float min_distance2, float errors_a[4], float errors_b[4]) {
    V e;
    cluster_errors<Kernel>(q, quad_nodes(kernel, a, b, min_distance2, q.specular != 0u || q.disney != 0u), e);
    _mm_storeu_ps(errors_a, _mm256_castps256_ps128(e));
    _mm_storeu_ps(errors_b, _mm256_extractf128_ps(e, 1));
}
// quad_light_units of `a` (lanes 0-3) and `b` (4-7) at once, as lanes:
// rows 0-2 of v the units' red, green and blue, 3-5 the directions to the
// light, 6 the rays' lengths; bit l of `lit` set where lane l's unit is
// not zero (elsewhere the lane's values are zeros or not meaningful).
// false (nothing written) where quad_light_units does not cover both.
template <class Kernel>
bool quad_light_unit_lanes(Kernel& kernel, const QuadLanes& q, const gpu::Light& a, const gpu::Light& b,
                           float min_distance2, float v[7][8], unsigned& lit) {
    if (!q.covered || !quad_units_cover(a) || !quad_units_cover(b)) return false;
    V r, g, bl, wx, wy, wz, length;
    lit = unsigned(
        _mm256_movemask_ps(light_values<Kernel>(q, light_lanes(kernel, a, b, min_distance2), r, g, bl, wx, wy, wz, length)));
    const V rows[7] = {r, g, bl, wx, wy, wz, length};
    for (unsigned k = 0; k < 7u; ++k) _mm256_storeu_ps(v[k], rows[k]);
    return true;
}
// quad_light_units of `a` and `b` at once, in the eight lanes of AVX2, into
// unit[0], wi[0], t_max[0] and unit[1], wi[1], t_max[1]; false (nothing
// written) where quad_light_units does not cover both.
template <class Kernel>
bool quad_light_units_pair(Kernel& kernel, const QuadLanes& q, const gpu::Light& a, const gpu::Light& b,
                           float min_distance2, glm::vec3 unit[2][4], glm::vec3 wi[2][4], float t_max[2][4]) {
    alignas(32) float v[7][8];
    unsigned lit;
    if (!quad_light_unit_lanes(kernel, q, a, b, min_distance2, v, lit)) return false;
    for (unsigned h = 0; h < 2u; ++h)
        for (unsigned p = 0; p < 4u; ++p) {
            const unsigned lane = 4u * h + p;
            unit[h][p] = glm::vec3(0.0f);
            if ((lit >> lane & 1u) == 0u) continue;
            unit[h][p] = glm::vec3(v[0][lane], v[1][lane], v[2][lane]);
            wi[h][p] = glm::vec3(v[3][lane], v[4][lane], v[5][lane]);
            t_max[h][p] = v[6][lane];
        }
    return true;
}
}  // namespace quad8
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

// Whether this CPU has AVX-512F and AVX-512DQ (quad16). Asked once.
inline bool cpu_has_avx512dq() {
    static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
    return has;
}

// Four clusters at once in the sixteen lanes of AVX-512: two refinements'
// children (QuadCut::refine_all pairs a pass's refinements), cluster k in
// lanes 4k to 4k+3, the points in every quarter. Each pair's nodes are laid
// out by quad8::quad_nodes and the halves joined, so every lane holds the
// floats quad8 would give it; the same operations in the same order after
// that, so the errors are quad8's and the scalar ones, bit for bit
// (tests/test_quad_cut.cpp). Only where cpu_has_avx512dq().
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,avx512f,avx512dq"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512dq")
#endif
namespace quad16 {
using V = __m512;
inline V v_set1(float x) { return _mm512_set1_ps(x); }
inline V v_zero() { return _mm512_setzero_ps(); }
inline V v_add(V a, V b) { return _mm512_add_ps(a, b); }
inline V v_sub(V a, V b) { return _mm512_sub_ps(a, b); }
inline V v_mul(V a, V b) { return _mm512_mul_ps(a, b); }
inline V v_div(V a, V b) { return _mm512_div_ps(a, b); }
// sqrt, min and max through their zero-masking forms with every lane on
// (the same instructions): GCC 12 warns that the plain ones' undefined
// pass-through operand is used uninitialized (its bug 105593).
inline V v_sqrt(V a) { return _mm512_maskz_sqrt_ps(__mmask16(0xFFFF), a); }
inline V v_and(V a, V b) { return _mm512_and_ps(a, b); }
inline V v_andnot(V a, V b) { return _mm512_andnot_ps(a, b); }
inline V v_or(V a, V b) { return _mm512_or_ps(a, b); }
// A compare's lanes as all ones or zeros, as the SSE and AVX compares give
// them; the predicates are quad8's.
inline V v_lanes(__mmask16 m) { return _mm512_castsi512_ps(_mm512_movm_epi32(m)); }
inline V v_cmpgt(V a, V b) { return v_lanes(_mm512_cmp_ps_mask(a, b, _CMP_GT_OS)); }
inline V v_cmpge(V a, V b) { return v_lanes(_mm512_cmp_ps_mask(a, b, _CMP_GE_OS)); }
inline V v_cmpnle(V a, V b) { return v_lanes(_mm512_cmp_ps_mask(a, b, _CMP_NLE_US)); }
inline V v_abs(V a) { return _mm512_andnot_ps(_mm512_set1_ps(-0.0f), a); }
inline V v_min(V x, V y) { return _mm512_maskz_min_ps(__mmask16(0xFFFF), y, x); }
inline V v_max(V x, V y) { return _mm512_maskz_max_ps(__mmask16(0xFFFF), y, x); }
inline int v_movemask(V a) { return int(_mm512_movepi32_mask(_mm512_castps_si512(a))); }
// The body's quad_nodes is not used here (join below); a and b alternate by quarter.
inline V v_set2(float a, float b) {
    return _mm512_setr_ps(a, a, a, a, b, b, b, b, a, a, a, a, b, b, b, b);
}
#include "quad_bounds_body.h"

inline V join(__m256 lo, __m256 hi) { return _mm512_insertf32x8(_mm512_castps256_ps512(lo), hi, 1); }

// The quad's lanes in all four quarters.
inline void widen(const quad8::QuadLanes& q, QuadLanes& w) {
#define LC_WIDEN(field) w.field = join(q.field, q.field);
    LC_QUAD_LANE_VECTORS(LC_WIDEN)
#undef LC_WIDEN
    w.specular = q.specular;
    w.covered = q.covered;
    w.disney = q.disney;
}

// How two pairs' lanes make sixteen: x's in lanes 0-7 and y's in 8-15
// (Join), or x's pair (a in 0-3, b in 4-7) spread as (a, a, b, b) (Spread).
struct Join {
    static V combine(__m256 x, __m256 y) { return join(x, y); }
};
struct Spread {
    static V combine(__m256 x, __m256) {
        const V w = join(x, x);
        // (The zero-masked form: GCC 12 warns of the plain one's undefined
        // pass-through, as for quad16's v_sqrt.)
        return _mm512_maskz_shuffle_f32x4(__mmask16(0xFFFF), w, w, _MM_SHUFFLE(1, 1, 0, 0));
    }
};

// Two pairs' quad8::QuadNodes as one, each field Combine::combine(x's,
// y's). A pair without emission cones gets the fields of clusters that
// emit everywhere (cone zero), where the other has some.
template <class Combine>
inline QuadNodes combine(const quad8::QuadNodes& x, const quad8::QuadNodes& y) {
    const auto combine = Combine::combine;
    QuadNodes n;
    n.min_x = combine(x.min_x, y.min_x), n.min_y = combine(x.min_y, y.min_y), n.min_z = combine(x.min_z, y.min_z);
    n.max_x = combine(x.max_x, y.max_x), n.max_y = combine(x.max_y, y.max_y), n.max_z = combine(x.max_z, y.max_z);
    n.radius = combine(x.radius, y.radius);
    n.intensity_r = combine(x.intensity_r, y.intensity_r);
    n.intensity_g = combine(x.intensity_g, y.intensity_g);
    n.intensity_b = combine(x.intensity_b, y.intensity_b);
    n.clamp = combine(x.clamp, y.clamp);
    n.any_cone = x.any_cone || y.any_cone;
    if (!n.any_cone) return n;
    const __m256 none = _mm256_setzero_ps();
    const auto cones = [&](const quad8::QuadNodes& h, __m256 quad8::QuadNodes::*f) {
        return h.any_cone ? h.*f : none;
    };
    __m256 quad8::QuadNodes::*fields[] = {&quad8::QuadNodes::cone,    &quad8::QuadNodes::axis_x,
                                          &quad8::QuadNodes::axis_y,  &quad8::QuadNodes::axis_z,
                                          &quad8::QuadNodes::cos_o,   &quad8::QuadNodes::sin_o,
                                          &quad8::QuadNodes::cos_e,   &quad8::QuadNodes::edge,
                                          &quad8::QuadNodes::falloff_width, &quad8::QuadNodes::two_sided,
                                          &quad8::QuadNodes::cosine,  &quad8::QuadNodes::spot};
    V QuadNodes::*wide[] = {&QuadNodes::cone,  &QuadNodes::axis_x, &QuadNodes::axis_y,        &QuadNodes::axis_z,
                            &QuadNodes::cos_o, &QuadNodes::sin_o,  &QuadNodes::cos_e,         &QuadNodes::edge,
                            &QuadNodes::falloff_width,             &QuadNodes::two_sided,     &QuadNodes::cosine,
                            &QuadNodes::spot};
    static_assert(sizeof fields / sizeof fields[0] == sizeof wide / sizeof wide[0]);
    for (std::size_t i = 0; i < sizeof wide / sizeof wide[0]; ++i)
        n.*wide[i] = combine(cones(x, fields[i]), cones(y, fields[i]));
    return n;
}

// Two pairs' quad8::QuadNodes as one: (a, b) in lanes 0-7, (c, d) in 8-15.
inline QuadNodes join(const quad8::QuadNodes& x, const quad8::QuadNodes& y) { return combine<Join>(x, y); }

// lc_cluster_error of nodes[k] into errors[k][p] at the quad's points (zero
// in inactive lanes). For clusters that quad_errors covers (the caller
// checks).
template <class Kernel>
void quad_four_errors(Kernel& kernel, const QuadLanes& q, const gpu::LightNode* const nodes[4], float min_distance2,
                      float errors[4][4]) {
    const bool ggx = q.specular != 0u || q.disney != 0u;
    V e;
    cluster_errors<Kernel>(q, join(quad8::quad_nodes(kernel, *nodes[0], *nodes[1], min_distance2, ggx),
                                   quad8::quad_nodes(kernel, *nodes[2], *nodes[3], min_distance2, ggx)),
                           e);
    alignas(64) float out[16];
    _mm512_store_ps(out, e);
    for (unsigned k = 0; k < 4u; ++k)
        for (unsigned p = 0; p < 4u; ++p) errors[k][p] = out[4u * k + p];
}

// lc_cluster_error of `a` and `b` at an octet's eight points (the two
// quads' lanes side by side, widened: quad8::join, then widen) into
// errors_a[p] and errors_b[p]: the pair's lanes built once and spread as
// (a, a, b, b). For clusters that quad_errors covers (the caller checks).
template <class Kernel>
void octet_pair_errors(Kernel& kernel, const QuadLanes& q, const gpu::LightNode& a, const gpu::LightNode& b,
                       float min_distance2, float errors_a[8], float errors_b[8]) {
    const quad8::QuadNodes pair = quad8::quad_nodes(kernel, a, b, min_distance2, q.specular != 0u || q.disney != 0u);
    V e;
    cluster_errors<Kernel>(q, combine<Spread>(pair, pair), e);
    alignas(64) float out[16];
    _mm512_store_ps(out, e);
    for (unsigned p = 0; p < 8u; ++p) errors_a[p] = out[p], errors_b[p] = out[8u + p];
}
}  // namespace quad16
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

// lc_light_unit of one point, spot, oriented light or VPL `light` at the
// quad's four points, lane by lane, into unit[p] (zero in inactive lanes),
// and for each point where the unit is not zero the shadow ray's direction
// wi[p] and length t_max[p]: the scalar function's values bit for bit
// (tests/test_quad_cut.cpp). False where this does not cover the case: a
// directional light, or the points' lanes not covered (QuadLanes). The
// BRDF is evaluated in the lanes too, the GGX lobe's and the Disney BRDF's
// (quad_bounds_body.h, light_values). A change to lc_light_unit,
// lc_brdf_cos or lc_disney_brdf_cos (shaders/lc_shared/shading.h) must be made
// there too; the test fails until it is.
template <class Kernel>
bool quad_light_units(Kernel& kernel, const QuadLanes& q, const gpu::Light& light, float min_distance2,
                      glm::vec3 unit[4], glm::vec3 wi[4], float t_max[4]) {
    if (!q.covered || !quad_units_cover(light)) return false;
    alignas(16) float v[7][4];
    __m128 r, g, b, wx, wy, wz, length;
    const unsigned lit = unsigned(_mm_movemask_ps(quad4::light_values<Kernel>(
        q, quad4::light_lanes(kernel, light, light, min_distance2), r, g, b, wx, wy, wz, length)));
    const __m128 rows[7] = {r, g, b, wx, wy, wz, length};
    for (unsigned k = 0; k < 7u; ++k) _mm_store_ps(v[k], rows[k]);
    for (unsigned p = 0; p < 4u; ++p) {
        unit[p] = glm::vec3(0.0f);
        if ((lit >> p & 1u) == 0u) continue;
        unit[p] = glm::vec3(v[0][p], v[1][p], v[2][p]);
        wi[p] = glm::vec3(v[3][p], v[4][p], v[5][p]);
        t_max[p] = v[6][p];
    }
    return true;
}
#endif

}  // namespace lc::cpu
