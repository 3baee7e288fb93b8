// Textures: lookups with glTF's samplers (repeated, clamped or mirrored;
// bilinear or nearest; trilinear in mipmaps where a ray cone's footprint
// covers several texels) and uv transforms, sRGB decoding, and the material
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

// A lookup's footprint is an ellipse in texture coordinates, the section of
// a ray cone by the surface (lc_uv_footprint): xy its long axis, zw its
// short one, each from one side to the other. It is zero where no ray cone
// comes with the lookup (the points that paths and virtual point lights
// bounce off, the area lights' emission): full resolution. Along a long
// axis of up to kMaxAnisotropy times the short one, that many lookups in
// the level the short axis picks are averaged (as a GPU's anisotropic
// filter does); a longer one reads a coarser level.
LC_KCONST uint kMaxAnisotropy = 8u;

// How many levels texture t's mipmap chain has, level 0 included: down to
// 1 x 1 texels.
uint lc_texture_levels(LC_IN(TextureInfo) t) { return uint(findMSB(max(t.width, t.height))) + 1u; }

// Level `level` of texture t's chain as a texture of its own (its offset,
// width and height; level 0 is t).
TextureInfo lc_texture_level(TextureInfo t, uint level) {
    if (level == 0u) return t;
    uint w = max(t.width >> 1u, 1u);
    uint h = max(t.height >> 1u, 1u);
    uint offset = t.mip_offset;
    for (uint l = 1u; l < level; ++l) {
        offset += w * h;
        w = max(w >> 1u, 1u);
        h = max(h >> 1u, 1u);
    }
    t.offset = offset;
    t.width = w;
    t.height = h;
    return t;
}

// Texture t at coordinates (u, v) already wrapped (lc_wrap_coordinate): the
// nearest texel, or a bilinear blend of four. Texel centres sit at
// (i + 0.5) / width; colour textures are decoded before they are filtered,
// so the filter blends linear values.
vec4 lc_texture_filtered(LC_IN(TextureInfo) t, float u, float v, uint wrap_u, uint wrap_v, bool nearest, bool srgb) {
    if (nearest)
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

// Texture `index` at uv, seen through `footprint`: transformed where the
// texture says so (its axes too) and wrapped as its sampler says. Where the
// footprint's long axis is under a texel (or the image has no mipmaps), the
// nearest texel or a bilinear blend of four at full resolution, as the
// sampler says; where it is longer, the mean of lookups spread along it,
// each a trilinear blend of the two levels whose texels are nearest the
// footprint's width over their count (at full resolution, as the sampler
// says, where that is under a texel).
vec4 lc_texture_sample(uint index, vec2 uv, bool srgb, vec4 footprint) {
    TextureInfo t = LC_TEXTURE(index);
    vec2 major = vec2(footprint.x, footprint.y);
    vec2 minor = vec2(footprint.z, footprint.w);
    if ((t.sampling & kTextureTransformed) != 0u) {
        vec2 tu = vec2(t.uv_transform[0], t.uv_transform[1]);
        vec2 tv = vec2(t.uv_transform[3], t.uv_transform[4]);
        uv = vec2(dot(tu, uv) + t.uv_transform[2], dot(tv, uv) + t.uv_transform[5]);
        major = vec2(dot(tu, major), dot(tv, major));
        minor = vec2(dot(tu, minor), dot(tv, minor));
    }
    uint wrap_u = t.sampling & 3u;
    uint wrap_v = (t.sampling >> kTextureWrapVShift) & 3u;
    vec2 size = vec2(float(t.width), float(t.height));
    float major_texels = length(major * size);
    float minor_texels = length(minor * size);
    if (major_texels < minor_texels) {  // a transform or the image's aspect turned them
        vec2 a = major;
        major = minor;
        minor = a;
        float l = major_texels;
        major_texels = minor_texels;
        minor_texels = l;
    }
    // Under a texel (NaN too: a cone met edge-on on a triangle without uv
    // area), one lookup at full resolution as the sampler says.
    uint taps = 1u;
    float lod = 0.0f;
    bool nearest = (t.sampling & kTextureNearest) != 0u;
    if ((t.sampling & kTextureMipmapped) != 0u && major_texels > 1.0f) {
        float ratio = major_texels / max(minor_texels, 1.0f);
        taps = ratio < float(kMaxAnisotropy) ? uint(ceil(ratio)) : kMaxAnisotropy;
        lod = log2(major_texels / float(taps));
        // Taps under a texel apart magnify: full resolution, as the
        // sampler's magFilter says (a GPU's rule, level of detail <= 0).
        nearest = nearest && !(lod > 0.0f);
        lod = min(max(lod, 0.0f), float(lc_texture_levels(t) - 1u));
    } else {
        major = vec2(0.0f);
    }
    float level = floor(lod);
    float blend = lod - level;
    uint levels = blend > 0.0f ? 2u : 1u;
    TextureInfo fine = lc_texture_level(t, uint(level));
    TextureInfo coarse = fine;
    if (levels == 2u) coarse = lc_texture_level(t, uint(level) + 1u);
    // One loop over the taps and their levels, so that the kernels hold one
    // copy of the bilinear lookup for each texture they read (lavapipe
    // compiles every copy for every pipeline).
    vec4 sum = vec4(0.0f);
    for (uint k = 0u; k < taps * levels; ++k) {
        bool second = k % levels == 1u;
        vec2 p = uv + major * ((float(k / levels) + 0.5f) / float(taps) - 0.5f);
        TextureInfo at = fine;
        if (second) at = coarse;
        float weight = levels == 1u ? 1.0f : (second ? blend : 1.0f - blend);
        sum += weight * lc_texture_filtered(at, lc_wrap_coordinate(p.x, wrap_u), lc_wrap_coordinate(p.y, wrap_v),
                                            wrap_u, wrap_v, nearest, srgb);
    }
    return sum / float(taps);
}

// Texture `index` at uv at full resolution (no footprint).
vec4 lc_texture_sample(uint index, vec2 uv, bool srgb) { return lc_texture_sample(index, uv, srgb, vec4(0.0f)); }

// The footprint (above) of a ray cone `cone_width` wide, along ray_dir,
// where it meets the triangle with vertices v0, v1, v2 and texture
// coordinates `t` (ray cones: Akenine-Moller et al., "Texture Level of
// Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems, 2019,
// with the ellipse's two axes kept apart): across the ray's direction the
// cone's width, along it that over the cosine (at most 1000 times), each
// mapped into texture coordinates by the triangle's gradients of u and v.
vec4 lc_uv_footprint(float cone_width, vec3 ray_dir, vec3 v0, vec3 v1, vec3 v2, LC_IN(TriangleUvs) t) {
    // The edges in units of their largest coordinate: n2 below goes with
    // the fourth power of their length, past the float range for edges of
    // 1e10 and under it for 1e-10.
    vec3 e1 = v1 - v0;
    vec3 e2 = v2 - v0;
    vec3 a = max(abs(e1), abs(e2));
    float unit = max(a.x, max(a.y, a.z));
    e1 /= unit;
    e2 /= unit;
    vec3 n = cross(e1, e2);
    float n2 = dot(n, n);
    // A vector w in the plane is s e1 + r e2 with s = dot(w, cross(e2, n)) / n2
    // and r = dot(w, cross(n, e1)) / n2 (here per unit).
    vec3 gs = cross(e2, n) / (n2 * unit);
    vec3 gr = cross(n, e1) / (n2 * unit);
    vec3 grad_u = (t.u1 - t.u0) * gs + (t.u2 - t.u0) * gr;
    vec3 grad_v = (t.v1 - t.v0) * gs + (t.v2 - t.v0) * gr;
    float cos_theta = abs(dot(ray_dir, n)) / sqrt(n2);
    vec3 across = cross(n, ray_dir);
    // Head-on, every direction in the plane is as good.
    if (!(dot(across, across) > 1e-12f * n2)) across = e1;
    across = normalize(across);
    vec3 along = normalize(cross(across, n)) * (cone_width / max(cos_theta, 1e-3f));
    across *= cone_width;
    return vec4(dot(grad_u, along), dot(grad_v, along), dot(grad_u, across), dot(grad_v, across));
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

// Material `index` as it reflects light at texture coordinates uv, its
// textures seen through `footprint` (lc_texture_sample): its factors times
// its textures. Base colour scales kd (both kinds); metallic-roughness
// scales roughness by G and metallic by B (glTF), and alpha follows
// roughness. The normal map is applied where the shading normal is made
// (lc_surface_point). The emission is left as the record has it: what a
// surface emits is lc_surface_emission's, which reads the emissive
// texture itself, and nothing that takes a material from here reads its
// emission. (This looked the emissive texture up too, for nothing; the
// renders of the textured glTF scene took as long without it, on both
// devices, and gave the same images.)
Material lc_material_at(uint index, vec2 uv, vec4 footprint) {
    Material m = LC_MATERIAL(index);
    if (!kEnableTextures || (m.flags & kMaterialTextured) == 0u) return m;
    if (lc_has_texture(m, m.base_color_texture)) {
        vec4 c = lc_texture_sample(m.base_color_texture, uv, true, footprint);
        m.kd_r *= c.x;
        m.kd_g *= c.y;
        m.kd_b *= c.z;
    }
    if (lc_has_texture(m, m.metallic_roughness_texture)) {
        vec4 c = lc_texture_sample(m.metallic_roughness_texture, uv, false, footprint);
        m.roughness *= c.y;
        m.metallic *= c.z;
        m.alpha = max(m.roughness * m.roughness, kMinGgxAlpha);
    }
    return m;
}

// The shading normal ns bent by material m's tangent-space normal map at
// uv (seen through `footprint`), on the triangle with vertices v0, v1, v2 and texture coordinates
// `t`. The tangent frame is the triangle's: T along +u and B towards -v
// (glTF's +Y, image up; v grows downwards), both made orthogonal to ns. A
// triangle whose UVs are degenerate keeps ns.
vec3 lc_normal_mapped(LC_IN(Material) m, vec2 uv, vec4 footprint, vec3 ns, vec3 v0, vec3 v1, vec3 v2, LC_IN(TriangleUvs) t) {
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
    vec4 c = lc_texture_sample(m.normal_texture, uv, false, footprint);
    vec3 tn = vec3((2.0f * c.x - 1.0f) * m.normal_scale, (2.0f * c.y - 1.0f) * m.normal_scale, 2.0f * c.z - 1.0f);
    vec3 bent = tn.x * tangent + tn.y * bitangent + tn.z * ns;
    float bent_len = length(bent);
    return bent_len > 1e-12f ? bent / bent_len : ns;
}
