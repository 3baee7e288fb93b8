// Textures: lookups with glTF's samplers (repeated, clamped or mirrored;
// bilinear or nearest) and uv transforms, sRGB decoding, and the material
// at a shaded point (its factors times its textures). Shared by the CPU
// reference and the Vulkan kernels (see glsl_compat.h).
//
// The includer defines LC_MATERIAL(i) -> Material, LC_UVS(i) -> TriangleUvs,
// LC_TEXTURE(i) -> TextureInfo, LC_TEXEL(i) -> uint (RGBA8, R in the low
// byte), and the switch kEnableTextures (a specialization constant on the
// GPU: a scene without textures gets kernels without this code).
// No include guard: see shading.h.
//
// Texture coordinates follow glTF: (0, 0) is the top-left corner of the
// image and v grows downwards; outside [0, 1] the sampler's wrapping
// decides (the default repeats the image).

// The sRGB transfer function undone (IEC 61966-2-1).
float lc_srgb_to_linear(float c) {
    return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

// Texel (x, y) of texture t, 0 <= x < width, 0 <= y < height, in [0, 1];
// colour textures decoded from sRGB, alpha always linear.
vec4 lc_texel(TextureInfo t, uint x, uint y, bool srgb) {
    uint packed = LC_TEXEL(t.offset + y * t.width + x);
    vec4 c = vec4(float(packed & 0xFFu), float((packed >> 8u) & 0xFFu), float((packed >> 16u) & 0xFFu),
                  float(packed >> 24u)) *
             (1.0f / 255.0f);
    if (srgb) c = vec4(lc_srgb_to_linear(c.x), lc_srgb_to_linear(c.y), lc_srgb_to_linear(c.z), c.w);
    return c;
}

// Texture coordinate c (u or v) brought into one period of its wrapping,
// where the texel coordinates it makes stay small: [0, 1] for repeat and
// clamp, [0, 2] for mirror (the image, then its mirror image; a period's
// end may round up to it, which wraps to the same texels as its start). A
// coordinate that is not finite (an overflowing transform) reads as 0.
float lc_wrap_coordinate(float c, uint wrap) {
    if (wrap == kTextureWrapClamp) return c >= 0.0f ? min(c, 1.0f) : 0.0f;
    float period = wrap == kTextureWrapMirror ? 2.0f : 1.0f;
    float w = c - period * floor(c / period);
    return w >= 0.0f && w <= period ? w : 0.0f;
}

// Texel column (or row) i of n, from -1 to one period (n, or 2n mirrored)
// as lc_wrap_coordinate leaves it, mapped into [0, n) by the wrapping. (GLSL
// leaves % of negative numbers undefined: every operand here is >= 0.)
uint lc_wrap_texel(int i, uint n, uint wrap) {
    if (wrap == kTextureWrapClamp) return uint(clamp(i, 0, int(n) - 1));
    if (wrap == kTextureWrapMirror) {
        uint m = uint(i + 2 * int(n)) % (2u * n);
        return m < n ? m : 2u * n - 1u - m;
    }
    return uint(i + int(n)) % n;
}

// Texture `index` at uv: transformed where the texture says so, wrapped as
// its sampler says, and the nearest texel or a bilinear blend of four.
// Texel centres sit at (i + 0.5) / width; colour textures are decoded
// before they are filtered, so the filter blends linear values.
vec4 lc_texture_sample(uint index, vec2 uv, bool srgb) {
    TextureInfo t = LC_TEXTURE(index);
    if ((t.sampling & kTextureTransformed) != 0u)
        uv = vec2(t.uv_transform[0] * uv.x + t.uv_transform[1] * uv.y + t.uv_transform[2],
                  t.uv_transform[3] * uv.x + t.uv_transform[4] * uv.y + t.uv_transform[5]);
    uint wrap_u = t.sampling & 3u;
    uint wrap_v = (t.sampling >> kTextureWrapVShift) & 3u;
    // Wrap first, so the integer texel coordinates below stay small.
    float u = lc_wrap_coordinate(uv.x, wrap_u);
    float v = lc_wrap_coordinate(uv.y, wrap_v);
    if ((t.sampling & kTextureNearest) != 0u)
        return lc_texel(t, lc_wrap_texel(int(floor(u * float(t.width))), t.width, wrap_u),
                        lc_wrap_texel(int(floor(v * float(t.height))), t.height, wrap_v), srgb);
    float x = u * float(t.width) - 0.5f;
    float y = v * float(t.height) - 0.5f;
    float fx = floor(x);
    float fy = floor(y);
    float ax = x - fx;
    float ay = y - fy;
    uint x0 = lc_wrap_texel(int(fx), t.width, wrap_u);
    uint y0 = lc_wrap_texel(int(fy), t.height, wrap_v);
    uint x1 = lc_wrap_texel(int(fx) + 1, t.width, wrap_u);
    uint y1 = lc_wrap_texel(int(fy) + 1, t.height, wrap_v);
    vec4 top = mix(lc_texel(t, x0, y0, srgb), lc_texel(t, x1, y0, srgb), ax);
    vec4 bottom = mix(lc_texel(t, x0, y1, srgb), lc_texel(t, x1, y1, srgb), ax);
    return mix(top, bottom, ay);
}

// Whether material m has texture `index` (one of its *_texture fields).
bool lc_has_texture(LC_IN(Material) m, uint index) {
    return kEnableTextures && (m.flags & kMaterialTextured) != 0u && index != kInvalidIndex;
}

// Texture coordinates of a point of triangle tri_index at barycentrics (b1, b2).
vec2 lc_triangle_uv(uint tri_index, float b1, float b2) {
    TriangleUvs t = LC_UVS(tri_index);
    float b0 = 1.0f - b1 - b2;
    return b0 * vec2(t.u0, t.v0) + b1 * vec2(t.u1, t.v1) + b2 * vec2(t.u2, t.v2);
}

// Material `index` at texture coordinates uv: its factors times its
// textures. Base colour scales kd (both kinds); metallic-roughness scales
// roughness by G and metallic by B (glTF), and alpha follows roughness;
// the emissive texture scales emission. The normal map is applied where the
// shading normal is made (lc_surface_point).
Material lc_material_at(uint index, vec2 uv) {
    Material m = LC_MATERIAL(index);
    if (!kEnableTextures || (m.flags & kMaterialTextured) == 0u) return m;
    if (lc_has_texture(m, m.base_color_texture)) {
        vec4 c = lc_texture_sample(m.base_color_texture, uv, true);
        m.kd_r *= c.x;
        m.kd_g *= c.y;
        m.kd_b *= c.z;
    }
    if (lc_has_texture(m, m.metallic_roughness_texture)) {
        vec4 c = lc_texture_sample(m.metallic_roughness_texture, uv, false);
        m.roughness *= c.y;
        m.metallic *= c.z;
        m.alpha = max(m.roughness * m.roughness, kMinGgxAlpha);
    }
    if (lc_has_texture(m, m.emissive_texture)) {
        vec4 c = lc_texture_sample(m.emissive_texture, uv, true);
        m.emission_r *= c.x;
        m.emission_g *= c.y;
        m.emission_b *= c.z;
    }
    return m;
}

// The shading normal ns bent by material m's tangent-space normal map at
// uv, on the triangle with vertices v0, v1, v2 and texture coordinates
// `t`. The tangent frame is the triangle's: T along +u and B towards -v
// (glTF's +Y, image up; v grows downwards), both made orthogonal to ns. A
// triangle whose UVs are degenerate keeps ns.
vec3 lc_normal_mapped(LC_IN(Material) m, vec2 uv, vec3 ns, vec3 v0, vec3 v1, vec3 v2, LC_IN(TriangleUvs) t) {
    if (!lc_has_texture(m, m.normal_texture)) return ns;
    vec3 dp1 = v1 - v0;
    vec3 dp2 = v2 - v0;
    vec2 duv1 = vec2(t.u1 - t.u0, t.v1 - t.v0);
    vec2 duv2 = vec2(t.u2 - t.u0, t.v2 - t.v0);
    float det = duv1.x * duv2.y - duv1.y * duv2.x;
    if (!(abs(det) > 1e-20f)) return ns;
    vec3 dpdu = (dp1 * duv2.y - dp2 * duv1.y) / det;
    vec3 dpdv = (dp2 * duv1.x - dp1 * duv2.x) / det;
    vec3 tangent = dpdu - ns * dot(ns, dpdu);
    float tangent_len = length(tangent);
    if (!(tangent_len > 0.0f)) return ns;
    tangent /= tangent_len;
    vec3 bitangent = cross(ns, tangent);
    if (dot(bitangent, -dpdv) < 0.0f) bitangent = -bitangent;
    vec4 c = lc_texture_sample(m.normal_texture, uv, false);
    vec3 tn = vec3((2.0f * c.x - 1.0f) * m.normal_scale, (2.0f * c.y - 1.0f) * m.normal_scale, 2.0f * c.z - 1.0f);
    vec3 bent = tn.x * tangent + tn.y * bitangent + tn.z * ns;
    float bent_len = length(bent);
    return bent_len > 1e-12f ? bent / bent_len : ns;
}
