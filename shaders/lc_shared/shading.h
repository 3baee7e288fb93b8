// Camera rays, surface reconstruction, the BRDF, one light's contribution and
// the Lightcuts error bounds. Shared by the CPU reference and the Vulkan
// kernels (see glsl_compat.h); needs trace.h first.
//
// The includer defines:
//   LC_MATERIAL(i)   -> Material
//   LC_NORMALS(i)    -> TriangleNormals
//   LC_UVS(i), LC_TEXTURE(i), LC_TEXEL(i) (textures.h, included before this)
//   LC_LIGHT(i)      -> Light
//   LC_ENVIRONMENT_TEXEL(i) -> vec3 (radiance of environment texel i)
//   LC_VPL_MIN_DISTANCE2 -> float (FrameParams.vpl_min_distance2)
// and the feature switches kEnableGgx, kEnableShadows, kEnableOriented,
// kEnableTextures, kEnableDisney, kEnableSheen and kEnableClearcoat
// (specialization constants on the GPU, so a scene without GGX materials,
// without occluders, without spot and oriented lights or without Disney
// materials (or their sheen or clearcoat lobes) gets a kernel without that
// code; always true on the CPU).
// No include guard: each kernel context (a GLSL shader, a C++ kernel
// struct in host/cpu_kernel.h) includes it exactly once.

LC_KCONST float kPi = 3.14159265358979f;
// Rounding in the bound formulas is covered by this relative slack, so a
// bound is never below the value it bounds by an ulp.
LC_KCONST float kBoundSlack = 1.0f + 1e-5f;
LC_KCONST float kCosineAbsSlack = 1e-6f;

// Position on the image plane of sample `s` of `spp` in pixel (x, y):
// spp = 1 is the pixel centre; otherwise stratified over a cols x rows grid,
// jittered within each stratum by the seeded hash. Where spp does not fill
// the grid of about sqrt(spp) columns (spp 8 would leave one cell of a
// 3 x 3 grid empty, and that part of the pixel unseen: a bias), the strata
// are spp columns of full height.
// The key of camera sample `s` of pixel (x, y): the pixel's 28-bit index
// (x and y below 2^14, kMaxImageSide) with the sample's hash. One pixel's
// key for each pixel at a given sample: x ^ lc_hash(y ^ ...), x having 14
// bits, gave rows of pixels the same keys as other rows (505 pairs of rows
// at 16384 x 16384), so their random numbers, and their noise, were alike.
uint lc_pixel_key(uint x, uint y, uint s) { return lc_hash(((y << 14u) | x) ^ lc_hash(s)); }

vec2 lc_pixel_sample(uint x, uint y, uint s, uint spp, uint seed) {
    if (spp <= 1u) return vec2(float(x) + 0.5f, float(y) + 0.5f);
    uint cols = uint(ceil(sqrt(float(spp))));
    uint rows = (spp + cols - 1u) / cols;
    if (cols * rows != spp) {
        cols = spp;
        rows = 1u;
    }
    uint h = lc_hash(seed ^ lc_pixel_key(x, y, s));
    float jx = lc_unit_float(h);
    float jy = lc_unit_float(lc_hash(h));
    return vec2(float(x) + (float(s % cols) + jx) / float(cols),
                float(y) + (float(s / cols) + jy) / float(rows));
}

vec3 lc_camera_ray_dir(LC_IN(FrameParams) f, vec2 pixel) {
    float u = 2.0f * pixel.x / float(f.width) - 1.0f;
    float v = 1.0f - 2.0f * pixel.y / float(f.height);  // row 0 at the top
    vec3 d = vec3(f.cam_fwd_x, f.cam_fwd_y, f.cam_fwd_z) +
             u * vec3(f.cam_right_x, f.cam_right_y, f.cam_right_z) +
             v * vec3(f.cam_up_x, f.cam_up_y, f.cam_up_z);
    return normalize(d);
}

// Orthonormal basis around n (Duff et al., JCGT 2017).
void lc_basis(vec3 n, LC_OUT(vec3) t, LC_OUT(vec3) b) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// A shaded point: position offset off the surface, shading normal and view
// direction both on the camera's side, and its material with the textures
// at its texture coordinates applied (lc_material_at), looked up once
// before any light is shaded.
struct SurfacePoint {
    vec3 p;
    vec3 n;
    vec3 t, b;      // lc_basis(n): the frame the cosine bound works in, made once
    vec3 wo;
    uint material;  // index of the material record
    vec2 uv;
    vec4 footprint;   // the camera ray's cone on the surface, in uv (lc_uv_footprint); 0 for others
    Material mat;     // lc_material_at(material, uv, footprint)
};

// A shaded point from its parts (the G-buffer's, or a test's).
SurfacePoint lc_make_surface(vec3 p, vec3 n, vec3 wo, uint material, vec2 uv, vec4 footprint) {
    SurfacePoint sp;
    sp.p = p;
    sp.n = n;
    lc_basis(n, sp.t, sp.b);
    sp.wo = wo;
    sp.material = material;
    sp.uv = uv;
    sp.footprint = footprint;
    sp.mat = lc_material_at(material, uv, footprint);
    return sp;
}

// The point at barycentrics (b1, b2) of triangle tri_index, hit by a ray
// along ray_dir whose cone is cone_width wide there (0 for a ray without
// one: its textures are read at full resolution).
SurfacePoint lc_surface_point(uint tri_index, float b1, float b2, vec3 ray_dir, float cone_width) {
    Triangle tri = LC_TRIANGLE(tri_index);
    TriangleNormals tn = LC_NORMALS(tri_index);
    vec3 v0 = lc_tri_v0(tri);
    vec3 v1 = lc_tri_v1(tri);
    vec3 v2 = lc_tri_v2(tri);
    float b0 = 1.0f - b1 - b2;
    // Barycentric interpolation is more accurate than org + t * dir.
    vec3 p = b0 * v0 + b1 * v1 + b2 * v2;
    vec3 ng = normalize(cross(v1 - v0, v2 - v0));
    TriangleUvs tuv = LC_UVS(tri_index);
    vec4 footprint = kEnableTextures && cone_width > 0.0f ? lc_uv_footprint(cone_width, ray_dir, v0, v1, v2, tuv)
                                                          : vec4(0.0f);
    vec3 ns = b0 * vec3(tn.n0_x, tn.n0_y, tn.n0_z) + b1 * vec3(tn.n1_x, tn.n1_y, tn.n1_z) +
              b2 * vec3(tn.n2_x, tn.n2_y, tn.n2_z);
    float ns_len = length(ns);
    ns = ns_len > 1e-12f ? ns / ns_len : ng;
    vec2 uv = lc_triangle_uv(tri_index, b1, b2);
    Material mat = lc_material_at(tri.material, uv, footprint);
    ns = lc_normal_mapped(mat, uv, footprint, ns, v0, v1, v2, tuv);
    // Two-sided surfaces: both normals turn to the side the ray came from.
    if (dot(ng, ray_dir) > 0.0f) ng = -ng;
    if (dot(ns, ng) < 0.0f) ns = -ns;
    SurfacePoint sp;
    sp.p = lc_offset_hit_point(p, ng, tri);
    sp.n = ns;
    lc_basis(ns, sp.t, sp.b);
    sp.wo = -ray_dir;
    sp.material = tri.material;
    sp.uv = uv;
    sp.footprint = footprint;
    sp.mat = mat;
    return sp;
}

// Radiance of the environment towards direction d (+Y up, lat-long map of
// docs/scene-format.md; black without one).
vec3 lc_environment_radiance(LC_IN(FrameParams) f, vec3 d) {
    if (f.env_width == 0u || f.env_height == 0u) return vec3(0.0f);
    // theta from atan2 rather than acos(d.y): near the poles a float d.y
    // is too coarse to tell a tall map's rows apart (host/path_emitters.cpp).
    float u = 0.5f + atan(d.x, -d.z) * (0.5f / kPi);
    float v = atan(sqrt(d.x * d.x + d.z * d.z), d.y) * (1.0f / kPi);
    uint col = min(uint(max(u, 0.0f) * float(f.env_width)), f.env_width - 1u);
    uint row = min(uint(max(v, 0.0f) * float(f.env_height)), f.env_height - 1u);
    return LC_ENVIRONMENT_TEXEL(row * f.env_width + col);
}

// Radiance a triangle emits at barycentrics (b1, b2) towards -ray_dir: its
// material's emission (times its emissive texture, seen through
// `footprint`: lc_texture_sample) on the side its
// geometric normal (counter-clockwise winding) points to, or on both sides.
vec3 lc_surface_emission(uint tri_index, float b1, float b2, vec3 ray_dir, vec4 footprint) {
    Triangle tri = LC_TRIANGLE(tri_index);
    Material m = LC_MATERIAL(tri.material);
    if ((m.flags & kMaterialEmissive) == 0u) return vec3(0.0f);
    vec3 ng = cross(lc_tri_v1(tri) - lc_tri_v0(tri), lc_tri_v2(tri) - lc_tri_v0(tri));
    bool front = dot(ng, ray_dir) < 0.0f;
    if (!front && (m.flags & kMaterialEmitsBothSides) == 0u) return vec3(0.0f);
    vec3 e = vec3(m.emission_r, m.emission_g, m.emission_b);
    if (lc_has_texture(m, m.emissive_texture))
        e *= vec3(lc_texture_sample(m.emissive_texture, lc_triangle_uv(tri_index, b1, b2), true, footprint));
    return e;
}

// Sample `s` of pixel (x, y) traced into the scene: the triangle hit
// (kInvalidIndex when the ray leaves the scene), its distance and
// barycentrics, and the ray's direction.
uint lc_camera_trace(LC_IN(FrameParams) f, uint x, uint y, uint s, LC_OUT(vec3) dir, LC_OUT(float) t,
                     LC_OUT(float) b1, LC_OUT(float) b2) {
    dir = lc_camera_ray_dir(f, lc_pixel_sample(x, y, s, f.spp, f.seed));
    vec3 org = vec3(f.cam_pos_x, f.cam_pos_y, f.cam_pos_z);
#ifdef LC_TRACE_CLOSEST
    // The includer's own closest-hit query (the CPU's 8-wide BVH).
    return LC_TRACE_CLOSEST(org, dir, kRayInfinity, t, b1, b2);
#else
    return lc_trace_closest(org, dir, kRayInfinity, t, b1, b2);
#endif
}

// A camera sample's first hit as a shaded point; false when the ray leaves
// the scene.
bool lc_camera_hit(LC_IN(FrameParams) f, uint x, uint y, uint s, LC_OUT(SurfacePoint) sp) {
    vec3 dir;
    float t, b1, b2;
    uint tri = lc_camera_trace(f, x, y, s, dir, t, b1, b2);
    if (tri == kInvalidIndex) return false;
    sp = lc_surface_point(tri, b1, b2, dir, f.pixel_spread * t);
    return true;
}

// lc_camera_hit, and what the ray sees without any light in `seen`: the
// surface's emission, or the environment where the ray leaves the scene.
bool lc_camera_sample(LC_IN(FrameParams) f, uint x, uint y, uint s, LC_OUT(SurfacePoint) sp, LC_OUT(vec3) seen) {
    vec3 dir;
    float t, b1, b2;
    uint tri = lc_camera_trace(f, x, y, s, dir, t, b1, b2);
    if (tri == kInvalidIndex) {
        seen = lc_environment_radiance(f, dir);
        return false;
    }
    sp = lc_surface_point(tri, b1, b2, dir, f.pixel_spread * t);
    seen = lc_surface_emission(tri, b1, b2, dir, sp.footprint);
    return true;
}

// Statistics of one shaded point.
struct ShadeStats {
    uint cut_size;      // clusters in the final cut
    uint cut_indirect;  // ... of them virtual point lights (indirect light)
    uint shadow_rays;   // rays actually traced
    uint hit_max_cut;   // 1 if refinement stopped at max_cut, not at the threshold
    uint frozen;        // clusters frozen because the cut heap was full
    float frozen_error; // ... and the sum of their error bounds
};

// --- BRDF: Lambert kd/pi plus GGX with constant Fresnel ks and separable
// Smith shadowing. The returned value is f * cos(theta_i); the GGX term is
// written as D * G1(wi) * G1(wo) / (4 cos_o) so no division by cos_i occurs.
float lc_ggx_d(float cos_h, float sin2_h, float alpha) {
    float a2 = alpha * alpha;
    // 1 + (a2 - 1) c2 written as sin^2 + a2 cos^2: the textbook form rounds
    // (a2 - 1) + 1 at the peak, which for alpha = 1e-3 put the radiance at
    // normal incidence 2.6% low (tests/test_shading.cpp); this form is exact
    // there. The caller gives sin^2 (lc_half_angle).
    float denom = sin2_h + a2 * (cos_h * cos_h);
    return a2 / (kPi * denom * denom);
}

// The cosine of the angle between the unit normal n and the unit half
// vector h, and its sine squared, for lc_ggx_d and lc_gtr1_d. Near a
// sharp highlight's peak, where sin^2 is about alpha^2 (1e-6 at the floor),
// cos rounds to within an ulp of 1 or above it, and 1 - cos^2 was off by
// as much as sin^2 itself (D came out up to 3.65 times its peak at alpha =
// 1e-3): there sin^2 comes from the cross product. Below kHalfAngleCross
// 1 - cos^2 is off by at most about 2e-6 of itself, and the cross product
// is not worth its cost (brute force on the room 5% slower).
LC_KCONST float kHalfAngleCross = 0.125f;
vec2 lc_half_angle(vec3 n, vec3 h) {
    float c = clamp(dot(n, h), 0.0f, 1.0f);
    float s2 = 1.0f - c * c;
    if (s2 < kHalfAngleCross) {
        vec3 s = cross(n, h);
        s2 = dot(s, s);
    }
    return vec2(c, s2);
}

float lc_smith_g1(float cos_v, float alpha) {
    float a2 = alpha * alpha;
    return 2.0f * cos_v / (cos_v + sqrt(a2 + (1.0f - a2) * cos_v * cos_v));
}

vec3 lc_kd(LC_IN(Material) m) { return vec3(m.kd_r, m.kd_g, m.kd_b); }
vec3 lc_ks(LC_IN(Material) m) { return vec3(m.ks_r, m.ks_g, m.ks_b); }

// --- The Disney BRDF (Burley 2012, "Physically-Based Shading at Disney",
// and its BRDF Explorer's disney.brdf): isotropic, without subsurface and
// transmission. With cos_d = wi.h = wo.h and w(c) = (1 - c)^5 (Schlick's
// weight), f is the sum of
//   diffuse:   base/pi (1 - metallic) F_L F_V, F_x = 1 + (F_D90 - 1) w(cos_x),
//              F_D90 = 0.5 + 2 roughness cos_d^2 (retro-reflection);
//   sheen:     sheen mix(1, tint, sheen_tint) w(cos_d) (1 - metallic);
//   specular:  GGX(alpha) D G1(wi) G1(wo) / (4 cos_i cos_o) times Schlick's
//              Fresnel from Cspec0 = mix(0.08 specular mix(1, tint,
//              specular_tint), base, metallic);
//   clearcoat: 0.25 clearcoat GTR1(alpha_c) G1(wi; 0.25) G1(wo; 0.25) /
//              (4 cos_i cos_o) times Schlick's Fresnel from 0.04,
//              alpha_c = mix(0.1, 0.001, clearcoat_gloss);
// tint = base / luminance(base) (white for black). As in Burley's code the
// whole BRDF is zero when wo is below the shading normal.
float lc_schlick_weight(float cos_x) {
    float m = clamp(1.0f - cos_x, 0.0f, 1.0f);
    float m2 = m * m;
    return m2 * m2 * m;
}

vec3 lc_disney_tint(LC_IN(Material) m) {
    vec3 base = lc_kd(m);
    float lum = lc_luminance(base);
    return lum > 0.0f ? base / lum : vec3(1.0f);
}

// Reflectance of the specular lobe at normal incidence, at most 1: a
// saturated base colour's tint reaches 1 / 0.0722 (pure blue), which with
// specular and specular_tint 1 made 1.108 (lc_disney_bound takes Schlick's
// Fresnel to grow with its weight, true only up to 1).
vec3 lc_disney_spec0(LC_IN(Material) m) {
    vec3 tinted = mix(vec3(1.0f), lc_disney_tint(m), m.specular_tint);
    return min(mix(tinted * (0.08f * m.specular), lc_kd(m), m.metallic), vec3(1.0f));
}

vec3 lc_disney_sheen_color(LC_IN(Material) m) {
    return m.sheen * mix(vec3(1.0f), lc_disney_tint(m), m.sheen_tint) * (1.0f - m.metallic);
}

float lc_clearcoat_alpha(LC_IN(Material) m) { return mix(0.1f, 0.001f, m.clearcoat_gloss); }
LC_KCONST float kClearcoatSmithAlpha = 0.25f;

// Burley's GTR1 (Berry) distribution for alpha < 1; grows with cos_h like
// GGX. The denominator written as in lc_ggx_d.
float lc_gtr1_d(float cos_h, float sin2_h, float alpha) {
    float a2 = alpha * alpha;
    return (a2 - 1.0f) / (kPi * log(a2) * (sin2_h + a2 * (cos_h * cos_h)));
}

// The diffuse lobe times cos_i, for a given F_D90.
vec3 lc_disney_diffuse(LC_IN(Material) m, float fd90, float cos_i, float cos_o) {
    float fl = 1.0f + (fd90 - 1.0f) * lc_schlick_weight(cos_i);
    float fv = 1.0f + (fd90 - 1.0f) * lc_schlick_weight(cos_o);
    return lc_kd(m) * ((1.0f - m.metallic) * fl * fv * cos_i / kPi);
}

// The specular and clearcoat lobes share D G1 G1 / (4 cos_o) (times cos_i
// already); their Fresnel factors are applied by the caller.
float lc_microfacet_cos(float d, float cos_i, float cos_o, float alpha_g) {
    return d * lc_smith_g1(cos_i, alpha_g) * lc_smith_g1(cos_o, alpha_g) / (4.0f * cos_o);
}

// The microfacet lobes reflect wo into wi only where h = normalize(wi +
// wo) faces wo. Mathematically it always does (wo.(wi + wo) = 1 + wo.wi);
// in float, where wi is nearly -wo (a grazing view's mirror direction) h
// is the normalised sum of two nearly opposite vectors and can come out
// facing away. The path tracer's sampling density leaves the lobes out
// there, so these BRDFs must too: with them in, such samples weighed up to
// 1e12 (a white Disney floor at roughness 0 seen at cos_o 1e-5 came out a
// thousand times too bright; an audit). Walter et al. 2007's positivity
// factor on the microfacet terms.
bool lc_facets_reflect(vec3 wo, vec3 h) { return dot(wo, h) > 0.0f; }

vec3 lc_disney_brdf_cos(LC_IN(Material) m, vec3 n, vec3 wi, vec3 wo, float cos_i) {
    float cos_o = dot(n, wo);
    if (!(cos_o > 0.0f)) return vec3(0.0f);
    vec3 h = normalize(wi + wo);  // wi and wo are both above n, so wi + wo != 0
    vec2 half_angle = lc_half_angle(n, h);
    float cos_d = clamp(dot(wi, h), 0.0f, 1.0f);
    float w = lc_schlick_weight(cos_d);
    vec3 value = lc_disney_diffuse(m, 0.5f + 2.0f * m.roughness * cos_d * cos_d, cos_i, cos_o);
    bool facets = lc_facets_reflect(wo, h);
    if (facets)
        value += mix(lc_disney_spec0(m), vec3(1.0f), w) *
                 lc_microfacet_cos(lc_ggx_d(half_angle.x, half_angle.y, m.alpha), cos_i, cos_o, m.alpha);
    if (kEnableSheen && (m.flags & kMaterialHasSheen) != 0u) value += lc_disney_sheen_color(m) * (w * cos_i);
    if (facets && kEnableClearcoat && (m.flags & kMaterialHasClearcoat) != 0u) {
        float coat = lc_microfacet_cos(lc_gtr1_d(half_angle.x, half_angle.y, lc_clearcoat_alpha(m)), cos_i, cos_o,
                                       kClearcoatSmithAlpha);
        value += vec3(0.25f * m.clearcoat * mix(0.04f, 1.0f, w) * coat);
    }
    return value;
}

// f * cos(theta_i) of either kind of material; cos_i = n.wi > 0.
vec3 lc_brdf_cos(LC_IN(Material) m, vec3 n, vec3 wi, vec3 wo, float cos_i) {
    if (kEnableDisney && (m.flags & kMaterialDisney) != 0u) return lc_disney_brdf_cos(m, n, wi, wo, cos_i);
    vec3 value = lc_kd(m) * (cos_i / kPi);
    if (kEnableGgx && (m.flags & kMaterialHasSpecular) != 0u) {
        float cos_o = dot(n, wo);
        vec3 h = normalize(wi + wo);
        if (cos_o > 0.0f && lc_facets_reflect(wo, h)) {
            vec2 half_angle = lc_half_angle(n, h);
            float spec = lc_ggx_d(half_angle.x, half_angle.y, m.alpha) * lc_smith_g1(cos_i, m.alpha) *
                         lc_smith_g1(cos_o, m.alpha) / (4.0f * cos_o);
            value += lc_ks(m) * spec;
        }
    }
    return value;
}

// glTF KHR_lights_punctual's spot falloff: s = clamp((cos - cos_outer) /
// max(1e-3, cos_inner - cos_outer), 0, 1); the intensity is scaled by s^2.
// The cosine is taken as at most 1: in float the dot product of two unit
// vectors can round a few ulps above it, and a spot whose outer cosine
// rounds to 1 (a cone under about 0.014 degrees) would then emit on its axis
// where lc_emission_bound, rightly, says it emits nothing.
float lc_spot_falloff(LC_IN(Light) light, float cos_theta) {
    float s = clamp((min(cos_theta, 1.0f) - light.cos_outer) / max(1e-3f, light.cos_inner - light.cos_outer), 0.0f,
                    1.0f);
    return s * s;
}

// The clamp of the inverse-square falloff, 1/max(d^2, clamp), for a light of
// `type`: VPLs may have a larger one (render.indirect.clamp), which bounds
// what any one of them adds near its surface.
float lc_falloff_clamp2(float min_distance2, uint type) {
    return type == kLightVpl ? max(min_distance2, LC_VPL_MIN_DISTANCE2) : min_distance2;
}

// One light's contribution per unit intensity (material * geometry *
// emission), with the shadow ray it needs: direction, and length
// (kRayInfinity for directional lights). Zero when the light is behind the
// surface or emits nothing towards it.
// Walter 2005 §3: the one place where a light's type decides its emission;
// everything else reads the light tree's nodes.
vec3 lc_light_unit(LC_IN(SurfacePoint) sp, LC_IN(Light) light, float min_distance2, LC_OUT(vec3) wi,
                   LC_OUT(float) t_max) {
    uint type = light.type & kLightTypeMask;
    wi = sp.n;
    t_max = 0.0f;
    float factor = 1.0f;  // geometry times emission towards sp
    if (type == kLightDirectional) {
        wi = vec3(light.x, light.y, light.z);
        t_max = kRayInfinity;
    } else {
        vec3 to_light = vec3(light.x, light.y, light.z) - sp.p;
        float d2 = dot(to_light, to_light);
        float d = sqrt(d2);
        // A light exactly at the shaded point has no direction: it adds
        // nothing (the cosine bound of such a cluster is zero as well).
        if (!(d > 0.0f)) return vec3(0.0f);
        wi = to_light / d;
        t_max = d * (1.0f - kShadowEndRelative);
        factor = 1.0f / max(d2, lc_falloff_clamp2(min_distance2, type));
        // cos of the angle between the light's axis and the way to sp.
        float cos_axis = -dot(vec3(light.axis_x, light.axis_y, light.axis_z), wi);
        switch (kEnableOriented ? type : kLightPoint) {
            case kLightPoint:
                break;
            case kLightSpot:
                factor *= lc_spot_falloff(light, cos_axis);
                break;
            case kLightOriented:
            case kLightVpl:
                factor *= (light.type & kLightTwoSided) != 0u ? abs(cos_axis) : max(cos_axis, 0.0f);
                break;
            default:  // the loader and the tree builder admit no other type
                return vec3(0.0f);
        }
    }
    float cos_i = dot(sp.n, wi);
    if (cos_i <= 0.0f || !(factor > 0.0f)) return vec3(0.0f);
    return lc_brdf_cos(sp.mat, sp.n, wi, sp.wo, cos_i) * factor;
}

bool lc_visible(LC_IN(SurfacePoint) sp, vec3 wi, float t_max) {
#ifdef LC_ON_SHADOW_RAY
    LC_ON_SHADOW_RAY(sp.p, wi, t_max);  // the CPU's ray recorder (host/cpu_kernel.h)
#endif
#ifdef LC_TRACE_ANY
    // The includer's own any-hit query (the CPU's 4-wide BVH).
    return !kEnableShadows || !LC_TRACE_ANY(sp.p, wi, t_max);
#else
    return !kEnableShadows || !lc_trace_any(sp.p, wi, t_max);
#endif
}

// lc_light_unit times visibility: one shadow ray, counted in stats, where
// the light can contribute at all.
vec3 lc_light_unit_shadowed(LC_IN(SurfacePoint) sp, LC_IN(Light) light, float min_distance2,
                            LC_INOUT(ShadeStats) stats) {
    vec3 wi;
    float t_max;
    vec3 unit = lc_light_unit(sp, light, min_distance2, wi, t_max);
    if (!(unit.x + unit.y + unit.z > 0.0f)) return vec3(0.0f);
    stats.shadow_rays += 1u;
    return lc_visible(sp, wi, t_max) ? unit : vec3(0.0f);
}

vec3 lc_light_intensity(LC_IN(Light) light) { return vec3(light.r, light.g, light.b); }

// A cluster's summed RGB intensity.
vec3 lc_node_intensity(LC_IN(LightNode) node) {
    return vec3(node.intensity_r, node.intensity_g, node.intensity_b);
}

// --- Walter et al. 2005, section 4.1: upper bounds on a cluster's
// contribution per unit intensity at a shaded point.

float lc_min_abs_on_interval(float centre, float half_width) {
    return max(abs(centre) - half_width, 0.0f);
}

// Upper bound of cos(angle between n and q - x) over all q in the box.
// The box, relative to x, is expressed in the frame (t, b, n) and replaced by
// the axis-aligned box around it in that frame, which contains it; Walter's
// bound z_max / sqrt(min x^2 + min y^2 + z_max^2) over that box is then an
// upper bound over the original box. Zero when the box lies below the
// surface. (The seed report rotated a world-space box by a single angle,
// which is not conservative.) t and b complete n to a frame (lc_basis).
float lc_cosine_bound(vec3 box_min, vec3 box_max, vec3 x, vec3 n, vec3 t, vec3 b) {
    // The box relative to x first: the centre 0.5 * (box_min + box_max)
    // rounds at the box's magnitude (0.008 at 1e5), which shifted the box by
    // far more than the slack below and broke the bound by 0.3% far from
    // the origin (tests/stress, Transformed.*); box - x is exact there.
    vec3 lo = box_min - x;
    vec3 hi = box_max - x;
    vec3 c = 0.5f * (lo + hi);
    vec3 e = 0.5f * (hi - lo);
    // Near the tangent plane cos is tiny and the rounding of the exact term
    // is absolute, not relative: widen z_max by a few ulps of the magnitudes
    // it was computed from.
    float z_max = dot(n, c) + dot(abs(n), e) + kCosineAbsSlack * (dot(abs(n), abs(c)) + dot(abs(n), e));
    if (z_max <= 0.0f) return 0.0f;
    float min_x = lc_min_abs_on_interval(dot(t, c), dot(abs(t), e));
    float min_y = lc_min_abs_on_interval(dot(b, c), dot(abs(b), e));
    float bound = z_max * inversesqrt(min_x * min_x + min_y * min_y + z_max * z_max);
    return min(bound * kBoundSlack, 1.0f);
}

// Squared distance from x to the box (0 inside).
float lc_box_distance2(vec3 box_min, vec3 box_max, vec3 x) {
    vec3 d = max(max(box_min - x, x - box_max), vec3(0.0f));
    return dot(d, d);
}

// The bounds below work with the cosines and sines of angles, never the
// angles: a sine from its cosine, sqrt(1 - cos^2), is off by up to ~3.5e-4
// rad near 0 and pi, where the cosine's own rounding is amplified (as an
// angle from acos would be), so they take each angle kAngleSlack wider.
LC_KCONST float kAngleSlack = 1e-3f;
LC_KCONST float kAngleSlackCos = 0.9999995f;     // cos(kAngleSlack)
LC_KCONST float kAngleSlackSin = 9.9999983e-4f;  // sin(kAngleSlack)

// A point counts as outside a bounding sphere only when it is this much
// farther from the centre than the radius. Nearer, float rounding cannot
// tell inside from outside, and from a point within rounding of the sphere
// a light on it close by can lie well outside the cone computed for it:
// 0.47 degrees outside, for a point 7e-8 inside the sphere that the floats
// put outside and a light 10^-5 from it, where GGX at the alpha floor was
// 9.4 times its bound (a helper's search, docs/disney-bounds.md). Past the
// margin sin(theta_c) <= 1 / 1.0001, so cos(theta_c) >= 0.014, and the
// few ulps of rounding in the radius and the distance move theta_c by at
// most ~3e-5 rad, inside kAngleSlack.
LC_KCONST float kOutsideSphere = 1.0001f;

// The cone of directions from x towards the box, from the box's bounding
// sphere: unit axis a (xyz) and the sine of its half-angle theta_c (w); w < 0
// when x is inside the sphere (or within kOutsideSphere of it), where the
// directions can be any. The sine, not the angle: the bounds below work
// with sines and cosines, without asin, acos or cos on the way.
vec4 lc_box_cone(vec3 box_min, vec3 box_max, vec3 x) {
    vec3 c = 0.5f * ((box_min - x) + (box_max - x));  // see lc_cosine_bound
    float radius = 0.5f * length(box_max - box_min);
    float dist = length(c);
    if (!(dist > radius * kOutsideSphere)) return vec4(0.0f, 0.0f, 1.0f, -1.0f);
    return vec4(c / dist, min(radius / dist, 1.0f));
}

// Upper bound of the GGX term D * G1(wi) * G1(wo) / (4 cos_o) over all
// directions wi towards the box (relative to x). G1(wi) <= 1. D grows with
// cos(theta_h), so it is bounded by D at the smallest possible angle between
// the half vector and n. The directions to the box lie in a cone (axis a,
// half-angle theta_c, from the box's bounding sphere). For fixed wo the map
// h -> wi = reflect(-wo, h) is 2-Lipschitz in angle and sends n to the mirror
// direction wr, so angle(h, n) >= max(0, angle(wr, a) - theta_c) / 2.
// The largest cos(theta_h) of any wi in the cone, for the view wo
// (cos_o = n.wo > 0); the argument is lc_ggx_bound's. With delta =
// angle(wr, a) - theta_c: cos(delta) = cos_r cos_c + sin_r sin_c, and
// cos(delta / 2) = sqrt((1 + cos(delta)) / 2). theta_c is taken
// kAngleSlack wider, as lc_cos_d_range takes it, for the rounding of its
// cosine from its sine (near a sharp GGX peak D changes by several times
// over 10^-4 rad); sin_r comes from the cross product, accurate for small
// angles where sqrt(1 - cos^2) is not; the sum is widened by
// kCosineAbsSlack for the rounding of the products.
float lc_cos_h_max(vec4 cone, vec3 n, vec3 wo, float cos_o) {
    if (cone.w < 0.0f) return 1.0f;
    vec3 wr = 2.0f * cos_o * n - wo;
    vec3 a = vec3(cone);
    float cos_r = dot(wr, a);
    float sin_c0 = cone.w;
    float cos_c0 = sqrt(max(1.0f - sin_c0 * sin_c0, 0.0f));
    float cos_c = cos_c0 * kAngleSlackCos - sin_c0 * kAngleSlackSin;
    float sin_c = sin_c0 * kAngleSlackCos + cos_c0 * kAngleSlackSin;
    if (cos_r >= cos_c) return 1.0f;  // the mirror direction lies in the cone
    float sin_r = length(cross(wr, a));
    float cos_delta = min(cos_r * cos_c + sin_r * sin_c + kCosineAbsSlack, 1.0f);
    return min(sqrt(max(0.5f + 0.5f * cos_delta, 0.0f)) * kBoundSlack, 1.0f);
}

float lc_ggx_bound(LC_IN(Material) m, vec3 box_min, vec3 box_max, vec3 x, vec3 n, vec3 wo) {
    float cos_o = dot(n, wo);
    if (cos_o <= 0.0f) return 0.0f;
    float cos_h_max = lc_cos_h_max(lc_box_cone(box_min, box_max, x), n, wo, cos_o);
    return lc_ggx_d(cos_h_max, 1.0f - cos_h_max * cos_h_max, m.alpha) * lc_smith_g1(cos_o, m.alpha) / (4.0f * cos_o) *
           kBoundSlack;
}

uint lc_node_type(LC_IN(LightNode) node) { return (node.flags >> kNodeTypeShift) & kNodeTypeMask; }


// sin of an angle in [0, pi] from its cosine.
float lc_sin_of(float cos_a) { return sqrt(max(1.0f - cos_a * cos_a, 0.0f)); }

// cos(theta_e + kAngleSlack) of a cluster whose lights emit up to theta_e,
// a little below the stored cosine, which went through cos on the host.
float lc_spot_edge(float cos_theta_e) {
    float cos_e = clamp(cos_theta_e, -1.0f, 1.0f);
    return cos_e * kAngleSlackCos - lc_sin_of(cos_e) * kAngleSlackSin;
}

// Upper bound of the emission factor towards x over every light of the
// cluster (pbrt-v4's LightBounds::Importance): a light at p with axis a
// emits towards x at the angle (a, x - p), which is at least theta' =
// theta_w - theta_o - theta_b by the triangle inequality on the sphere,
// where theta_w is the angle between the cluster's axis and the way from
// the box centre to x, theta_o the spread of the lights' axes and theta_b
// the half-angle the box's bounding sphere subtends at x. Nothing is
// emitted past theta_e; cosine emitters emit at most cos(theta') before,
// and a spot at most s^2 with s = (cos theta' - cos theta_e) / w, w the
// cluster's narrowest falloff (each light's s is below that: its outer
// cosine is at least cos theta_e, its width at least w).
// The angles are never formed: theta' is taken kAngleSlack smaller, and
// its cosine comes from the cosines and sines of the others by the
// angle-sum formulas, as pbrt-v4 does (acos, asin and cos made this
// function and its calls into libm most of the render on scenes of spots
// and VPLs).
float lc_emission_bound(LC_IN(LightNode) node, vec3 x) {
    if (node.cos_theta_o <= -1.0f) return 1.0f;  // emits everywhere
    vec3 lo = vec3(node.min_x, node.min_y, node.min_z) - x;
    vec3 hi = vec3(node.max_x, node.max_y, node.max_z) - x;
    vec3 to_centre = 0.5f * (lo + hi);
    float radius = 0.5f * length(hi - lo);
    float d = length(to_centre);
    if (!(d > radius * kOutsideSphere)) return 1.0f;  // x inside the bounding sphere: any direction
    float cos_w = clamp(-dot(lc_decode_axis(node.axis_oct), to_centre) / d, -1.0f, 1.0f);
    if ((node.flags & kNodeTwoSided) != 0u) cos_w = abs(cos_w);
    // cos theta', 1 where theta' <= 0: theta_w at most the sum s = theta_o +
    // theta_b + kAngleSlack, or s at least pi (then cos_o <= -cos_b, or the
    // slack takes the sum's sine below zero).
    float sin_b = min(radius / d, 1.0f);
    float cos_b = lc_sin_of(sin_b);
    float cos_o = min(node.cos_theta_o, 1.0f);
    float sin_o = lc_sin_of(cos_o);
    float cos_t = 1.0f;
    if (cos_o + cos_b > 0.0f) {
        float cos_ob = cos_o * cos_b - sin_o * sin_b;
        float sin_ob = sin_o * cos_b + cos_o * sin_b;
        float cos_s = cos_ob * kAngleSlackCos - sin_ob * kAngleSlackSin;
        float sin_s = sin_ob * kAngleSlackCos + cos_ob * kAngleSlackSin;
        if (sin_s > 0.0f && cos_w < cos_s) cos_t = min(cos_w * cos_s + lc_sin_of(cos_w) * sin_s, 1.0f);
    }
    if (cos_t <= node.cos_theta_e) return 0.0f;  // theta' >= theta_e
    uint type = lc_node_type(node);
    if (type == kLightOriented || type == kLightVpl) return min(cos_t * kBoundSlack, 1.0f);
    if (type != kLightSpot) return 1.0f;
    float s = (cos_t - lc_spot_edge(node.cos_theta_e)) / node.falloff_width;
    s = min(s * kBoundSlack, 1.0f);
    return s * s;
}

// The range (min, max) of cos_d = wi.h = cos(angle(wi, wo) / 2) over the
// directions wi in the cone: by the triangle inequality on the sphere,
// angle(wi, wo) lies within angle(wo, a) -+ theta_c, widened by kAngleSlack
// for the rounding (docs/disney-bounds.md). In cosines and sines, as
// lc_emission_bound: cos(angle_o -+ (theta_c + slack)) by the angle-sum
// formulas, then the half angle's cosine sqrt((1 + cos) / 2). sin of
// angle_o from the cross product, accurate for small angles.
vec2 lc_cos_d_range(vec4 cone, vec3 wo) {
    if (cone.w < 0.0f) return vec2(0.0f, 1.0f);
    vec3 a = vec3(cone);
    float cos_o = clamp(dot(wo, a), -1.0f, 1.0f);
    float sin_o = min(length(cross(wo, a)), 1.0f);
    // theta_c + kAngleSlack: at most pi / 2 + 10^-3, so its sine is positive.
    float sin_c = min(cone.w, 1.0f);
    float cos_c = lc_sin_of(sin_c);
    float cos_cs = cos_c * kAngleSlackCos - sin_c * kAngleSlackSin;
    float sin_cs = sin_c * kAngleSlackCos + cos_c * kAngleSlackSin;
    // nearest = max(angle_o - (theta_c + slack), 0): 0 where angle_o is no larger.
    float cos_near = cos_o >= cos_cs ? 1.0f : min(cos_o * cos_cs + sin_o * sin_cs, 1.0f);
    // farthest = min(angle_o + theta_c + slack, pi): pi where the sum is no smaller.
    float cos_far = cos_o <= -cos_cs ? -1.0f : max(cos_o * cos_cs - sin_o * sin_cs, -1.0f);
    return vec2(max(sqrt(0.5f + 0.5f * cos_far) / kBoundSlack - kCosineAbsSlack, 0.0f),
                min(sqrt(0.5f + 0.5f * cos_near) * kBoundSlack, 1.0f));
}

// Bound of the Disney BRDF times cos(theta_i) over every wi towards the box
// (relative to x), lobe by lobe (docs/disney-bounds.md): the diffuse lobe's
// F_D90 at the largest cos_d, Schlick's weight (sheen, both Fresnel factors)
// at the smallest cos_d, GGX and GTR1 at the largest cos_h. cos_bound bounds
// cos(theta_i).
vec3 lc_disney_bound(LC_IN(Material) m, vec3 box_min, vec3 box_max, vec3 x, vec3 n, vec3 wo, float cos_bound) {
    float cos_o = dot(n, wo);
    if (!(cos_o > 0.0f)) return vec3(0.0f);
    vec4 cone = lc_box_cone(box_min, box_max, x);
    vec2 cos_d = lc_cos_d_range(cone, wo);
    // F_L lies between 1 and F_D90; F_V grows with F_D90.
    float fd90 = 0.5f + 2.0f * m.roughness * cos_d.y * cos_d.y;
    float retro = max(fd90, 1.0f) * (1.0f + (fd90 - 1.0f) * lc_schlick_weight(cos_o));
    vec3 bound = lc_kd(m) * ((1.0f - m.metallic) * retro * cos_bound / kPi);
#ifdef LC_SEED_LOBE_BOUND
    // The seed report's bound of 1 for every other lobe (benchmarks only).
    if (LC_SEED_LOBE_BOUND) return bound * kBoundSlack + vec3(1.0f);
#endif
    float w = lc_schlick_weight(cos_d.x);
    float cos_h_max = lc_cos_h_max(cone, n, wo, cos_o);
    float sin2_h_min = 1.0f - cos_h_max * cos_h_max;
    float ggx = lc_ggx_d(cos_h_max, sin2_h_min, m.alpha) * lc_smith_g1(cos_o, m.alpha) / (4.0f * cos_o);
    bound += mix(lc_disney_spec0(m), vec3(1.0f), w) * ggx;
    if (kEnableSheen && (m.flags & kMaterialHasSheen) != 0u) bound += lc_disney_sheen_color(m) * (w * cos_bound);
    if (kEnableClearcoat && (m.flags & kMaterialHasClearcoat) != 0u) {
        float coat = lc_gtr1_d(cos_h_max, sin2_h_min, lc_clearcoat_alpha(m)) * lc_smith_g1(cos_o, kClearcoatSmithAlpha) /
                     (4.0f * cos_o);
        bound += vec3(0.25f * m.clearcoat * mix(0.04f, 1.0f, w) * coat);
    }
    return bound * kBoundSlack;
}

// Bound of material * geometry * emission (per unit intensity, RGB) over
// every light of a cluster, read from its node. Positional lights: the box
// holds positions, G <= 1/d_min^2 with the same clamp as the exact term.
// Directional lights: the box holds unit directions, so x is the origin and
// G = 1.
// The CPU evaluates the common case for two clusters at once with the same
// arithmetic (host/pair_bound.h): a change here must be made there too.
vec3 lc_cluster_bound(LC_IN(SurfacePoint) sp, LC_IN(Material) m, LC_IN(LightNode) node, float min_distance2) {
    vec3 box_min = vec3(node.min_x, node.min_y, node.min_z);
    vec3 box_max = vec3(node.max_x, node.max_y, node.max_z);
    bool positional = lc_node_type(node) != kLightDirectional;
    vec3 x = positional ? sp.p : vec3(0.0f);
    float cos_bound = lc_cosine_bound(box_min, box_max, x, sp.n, sp.t, sp.b);
    if (cos_bound <= 0.0f) return vec3(0.0f);
    float factor = 1.0f;
    if (positional) {
        if (kEnableOriented) factor = lc_emission_bound(node, sp.p);
        if (factor <= 0.0f) return vec3(0.0f);
        factor *= kBoundSlack / max(lc_box_distance2(box_min, box_max, sp.p),
                                    lc_falloff_clamp2(min_distance2, lc_node_type(node)));
    }
    if (kEnableDisney && (m.flags & kMaterialDisney) != 0u)
        return lc_disney_bound(m, box_min, box_max, x, sp.n, sp.wo, cos_bound) * factor;
    vec3 bound = lc_kd(m) * (cos_bound / kPi);
    if (kEnableGgx && (m.flags & kMaterialHasSpecular) != 0u)
        bound += lc_ks(m) * lc_ggx_bound(m, box_min, box_max, x, sp.n, sp.wo);
    return bound * factor;
}
