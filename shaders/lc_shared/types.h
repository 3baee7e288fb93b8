// Structs and constants shared by the C++ host and the GLSL kernels.
//
// This file compiles both as C++ (host/) and as GLSL (shaders/). Every struct
// is made of 4-byte scalars only, so its std430 layout is the C layout: no
// vec3 padding rules, no bool, no matrices. The C++ side checks every size
// and offset in host/gpu_layout_checks.cpp.
#ifndef LC_SHARED_TYPES_H
#define LC_SHARED_TYPES_H

#ifdef __cplusplus
#include <cstdint>
namespace lc::gpu {
using uint = std::uint32_t;
#define LC_CONST constexpr
// A function the C++ compiler must inline (GLSL compilers inline every one).
#define LC_ALWAYS_INLINE [[gnu::always_inline]]
#else
#define LC_CONST const
#define LC_ALWAYS_INLINE
#endif

// ---------------------------------------------------------------------------
// Limits and flags
// ---------------------------------------------------------------------------
LC_CONST uint kInvalidIndex = 0xFFFFFFFFu;
LC_CONST uint kBvhStackSize = 32u;    // build caps the BVH depth below this
LC_CONST uint kBvhMaxLeafTriangles = 4u;

// Light types. Each type has its own light tree (FrameParams.roots[type]);
// the type is also stored in every node (LightNode.flags), so the cut code
// never needs to know which tree a node came from. docs/lightcuts.md says
// how to add a type.
LC_CONST uint kLightPoint = 0u;        // position, radiant intensity (W/sr)
LC_CONST uint kLightDirectional = 1u;  // unit direction towards the light, irradiance (W/m^2)
LC_CONST uint kLightSpot = 2u;         // position, axis, intensity on the axis, glTF cone falloff
LC_CONST uint kLightOriented = 3u;     // position, normal, intensity along the normal, cosine falloff
LC_CONST uint kLightVpl = 4u;          // virtual point light: an oriented light left by a light path
                                       // (indirect light); its falloff has its own clamp
LC_CONST uint kLightTypeCount = 5u;

// Light.type: the type in bits 0-7, and:
LC_CONST uint kLightTypeMask = 0xFFu;
LC_CONST uint kLightTwoSided = 0x100u;  // oriented: emits on both sides of its normal

// LightNode.flags: bits 0-2 as below, bits 8-15 the light type.
LC_CONST uint kNodeLeaf = 1u;          // node is a single light
LC_CONST uint kNodeRepFromRight = 2u;  // representative is the right child's
LC_CONST uint kNodeTwoSided = 4u;      // some light of the cluster emits on both sides
LC_CONST uint kNodeTypeShift = 8u;
LC_CONST uint kNodeTypeMask = 0xFFu;

// The smallest GGX alpha a material gets, from the loader or a roughness
// texture: below it the fp32 NDF peak (1 / (pi alpha^2)) gets large enough
// that single point-light highlights turn into isolated fireflies.
LC_CONST float kMinGgxAlpha = 1e-3f;

// Material.flags
LC_CONST uint kMaterialHasSpecular = 1u;     // Lambert + GGX: the GGX lobe is on
LC_CONST uint kMaterialEmissive = 2u;        // emission is not black
LC_CONST uint kMaterialEmitsBothSides = 4u;  // emits on both sides of the triangle
LC_CONST uint kMaterialDisney = 8u;          // the Disney BRDF (else Lambert + GGX)
LC_CONST uint kMaterialHasSheen = 16u;       // Disney: sheen > 0
LC_CONST uint kMaterialHasClearcoat = 32u;   // Disney: clearcoat > 0
LC_CONST uint kMaterialTextured = 64u;       // some *_texture is not kInvalidIndex

// ---------------------------------------------------------------------------
// BVH over triangles (32 bytes). Interior: child0 = first_or_left,
// child1 = first_or_left + 1. Leaf (tri_count > 0): triangles
// [first_or_left, first_or_left + tri_count) of the reordered triangle array.
// ---------------------------------------------------------------------------
struct BvhNode {
    float min_x, min_y, min_z;
    uint first_or_left;
    float max_x, max_y, max_z;
    uint tri_count;
};

// The same tree four wide, as the kernels' shadow rays read it: 64 bytes,
// four 16-byte words. Made from the binary tree by pulling grandchildren up
// (collapse_bvh), so its leaves are the binary leaves. The four children's
// boxes are quantized to 8 bits a plane in a grid over the node (Ylitie,
// Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs Through
// Compressed Wide BVHs", HPG 2017): plane q of axis a lies at
// origin_a + q * scale_a, with scale_a a power of two, so that the product
// is exact and the sum rounds the same way everywhere; bvh4_nodes rounds
// every box outwards, so a decoded box holds the child's true box. Half
// the size of a node with float boxes (128 bytes), so half the texel reads
// a node (docs/results/lavapipe.md, section 11). The kernels read it as
// uvec4 words (shaders/kernel.glsl, lc_bvh4_node).
struct Bvh4Node {
    float origin_x, origin_y, origin_z;
    float scale_x, scale_y, scale_z;  // powers of two
    // Byte s of each word: child slot s's lower or upper plane, 0 .. 255.
    uint lo_x, lo_y, lo_z;
    uint hi_x, hi_y, hi_z;
    // Each child slot as lc_trace_any's stack entry: an inner child's
    // Bvh4Node index; a leaf (kBvh4LeafEntry) with its triangle count - 1 in
    // bits 29 and 30 and its first triangle below; kInvalidIndex: no child.
    uint entry[4];
};
LC_CONST uint kBvh4NodeWords = 4u;
LC_CONST uint kBvh4LeafEntry = 0x80000000u;
// A leaf's first triangle shares a stack word with its count and a flag in
// the kernels' traversal (lc_trace_any), so triangles are fewer than 2^29.
LC_CONST uint kBvh4MaxTriangles = 0x20000000u;

// Triangle positions for ray intersection, in BVH leaf order (48 bytes).
struct Triangle {
    float v0_x, v0_y, v0_z;
    float v1_x, v1_y, v1_z;
    float v2_x, v2_y, v2_z;
    uint material;
    uint pad0, pad1;
};

// Shading normals, one per vertex, same order as Triangle (48 bytes).
// Face normals are stored three times when the OBJ has none.
struct TriangleNormals {
    float n0_x, n0_y, n0_z;
    float n1_x, n1_y, n1_z;
    float n2_x, n2_y, n2_z;
    uint pad0, pad1, pad2;
};

// Texture coordinates (UV set 0), one pair per vertex, same order as
// Triangle (24 bytes); zero where the mesh has none.
struct TriangleUvs {
    float u0, v0, u1, v1, u2, v2;
};

// A material is one of two kinds (flags & kMaterialDisney):
//   Lambert + GGX: albedo kd (kd_*) plus an optional GGX lobe with
//     reflectance ks and GGX alpha (kMaterialHasSpecular);
//   Disney (Burley 2012, isotropic, no transmission): base colour in kd_*,
//     roughness, metallic, specular, specular_tint, sheen, sheen_tint,
//     clearcoat, clearcoat_gloss; alpha = roughness^2 (ks_* unused).
// Both emit `emission` (W/(sr m^2)) on the side of the geometric normal, or
// on both sides with kMaterialEmitsBothSides. Textures (indices into the
// TextureInfo array, kInvalidIndex for none) multiply the factors at the
// shaded point's UV: base colour (sRGB) scales kd, metallic-roughness (glTF:
// roughness in G, metallic in B) scales roughness and metallic, emissive
// (sRGB) scales emission; the normal map (tangent space, scaled in x and y
// by normal_scale) bends the shading normal. 96 bytes.
struct Material {
    float kd_r, kd_g, kd_b;
    float ks_r, ks_g, ks_b;
    float alpha;
    uint flags;
    float emission_r, emission_g, emission_b;
    float roughness;
    float metallic, specular, specular_tint, sheen;
    float sheen_tint, clearcoat, clearcoat_gloss, normal_scale;
    uint base_color_texture;
    uint metallic_roughness_texture;
    uint emissive_texture;
    uint normal_texture;
};

// One texture as a material samples it (40 bytes): an image of width x
// height texels, row 0 at the top (v = 0), RGBA8 packed one per uint (R in
// the low byte) from texel `offset` of the texel buffer, and how it is
// sampled (`sampling`, below; lc_shared/textures.h). Textures that sample one
// image in different ways share its texels.
//
// sampling: bits 0-1 the wrapping along u, bits 2-3 along v (kTextureWrap*),
// kTextureNearest for the nearest texel instead of a bilinear blend, and
// kTextureTransformed where the texture coordinates are first transformed
// (glTF's KHR_texture_transform, MTL's -o and -s):
//   u' = uv_transform[0] u + uv_transform[1] v + uv_transform[2]
//   v' = uv_transform[3] u + uv_transform[4] v + uv_transform[5]
// and kTextureMipmapped where the image has a mipmap chain: level l
// (1 <= l < lc_texture_levels) is max(width >> l, 1) x max(height >> l, 1)
// texels, the levels one after another from texel `mip_offset`.
struct TextureInfo {
    uint offset;
    uint width, height;
    uint sampling;
    float uv_transform[6];
    uint mip_offset;
};
LC_CONST uint kTextureWrapRepeat = 0u;     // the image repeats (glTF's REPEAT, the default)
LC_CONST uint kTextureWrapClamp = 1u;      // the edge texels continue (CLAMP_TO_EDGE)
LC_CONST uint kTextureWrapMirror = 2u;     // every other repeat mirrored (MIRRORED_REPEAT)
LC_CONST uint kTextureWrapVShift = 2u;     // the v wrapping's bits: (sampling >> kTextureWrapVShift) & 3
LC_CONST uint kTextureNearest = 16u;
LC_CONST uint kTextureTransformed = 32u;
LC_CONST uint kTextureMipmapped = 64u;
LC_CONST uint kTextureNoMipmaps = 128u;  // the host's: a sampler that asks for none (add_mipmaps)

// One light (48 bytes).
//   point:        position, radiant intensity (W/sr)
//   directional:  unit vector *towards* the light, irradiance (W/m^2)
//   spot:         position, unit axis it shines along, intensity on the axis
//                 (W/sr), cosines of the inner and outer half-angles
//   oriented:     position, unit normal, intensity along the normal (W/sr);
//                 I(w) = I * max(0, cos) (|cos| when two-sided): one point
//                 sample of an emissive surface
//   vpl:          as oriented, one-sided: the light a diffuse surface
//                 reflects where a light path hit it (host/vpls.h)
struct Light {
    float x, y, z;
    float r, g, b;
    float axis_x, axis_y, axis_z;
    float cos_inner, cos_outer;
    uint type;        // kLight* type and kLightTwoSided
};

// Light tree node (64 bytes); one array of 2n-1 nodes per light type, root
// first. Interior: children are left and left + 1. Leaf: light == rep_light.
// The box bounds the positions (directional lights: the unit directions) of
// the cluster's lights; the cone bounds the directions they emit into
// (pbrt-v4's LightBounds): every light's axis lies within theta_o of `axis`
// and emits only within theta_e of its own axis. cos_theta_o = -1 means the
// lights emit everywhere (point and directional lights).
struct LightNode {
    float min_x, min_y, min_z;
    float max_x, max_y, max_z;
    float intensity_r, intensity_g, intensity_b;  // sum over the cluster
    uint rep_light;   // index into the leaf-ordered light array
    uint left;        // first child index; kInvalidIndex for leaves
    uint flags;       // kNode* bits and the light type
    uint axis_oct;    // cone axis, octahedral, two snorm16 (lc_decode_axis)
    float cos_theta_o;
    float cos_theta_e;
    // Spots: the smallest cos(inner) - cos(outer) of the cluster's lights
    // (at least 1e-3, as in lc_spot_falloff), for a bound on the falloff.
    float falloff_width;
};

// Per-pixel surface record written by the camera-ray kernel (64 bytes).
// material == kInvalidIndex means the ray left the scene (black).
struct GBufferTexel {
    float px, py, pz;        // hit point, already offset off the surface
    float nx, ny, nz;        // shading normal, flipped to face the camera
    float wo_x, wo_y, wo_z;  // unit direction towards the camera
    uint material;
    float u, v;              // texture coordinates of the hit
    float footprint_major_u, footprint_major_v;  // the camera ray's footprint in them
    float footprint_minor_u, footprint_minor_v;  // (SurfacePoint, textures.h)
};

// One entry of the per-pixel cut heap (8 bytes): a refinable interior node
// and its error bound. The representative's unscaled contribution
// (material * geometry * visibility) is not stored: bit 31 of `node` keeps
// the visibility its shadow ray found, and the contribution is evaluated
// again from it when needed (lc_entry_unit, lc_shared/lightcuts.h), which costs
// no ray. The child with the same representative inherits the bit.
struct CutEntry {
    uint node;    // light-node index in bits 0-30, kCutEntryVisible
    float error;
};
LC_CONST uint kCutEntryVisible = 0x80000000u;
LC_CONST uint kCutEntryNodeMask = 0x7FFFFFFFu;

// One entry of a quad's shared cut heap as each of the quad's four lanes
// keeps it (quadcuts.comp, 12 bytes): the node and this lane's visibility
// bit as in CutEntry, this lane's own error bound, and the heap's order
// `key`, the largest ratio of the cluster's bound to a point's estimate over
// the quad, the same in all four lanes (host/quad_cut.h computes the same
// on the CPU).
struct QuadCutEntry {
    uint node;
    float error;
    float key;
};

// How --method sampled draws its lights (FrameParams.light_pick):
// through the light tree by importance at the shaded point, with the same
// probability for every light, or in proportion to each light's power.
LC_CONST uint kLightPickTree = 0u;
LC_CONST uint kLightPickUniform = 1u;
LC_CONST uint kLightPickPower = 2u;

// Everything a frame's kernels need besides the buffers (128 bytes); one
// storage buffer on the GPU, the same for every tile and sample. The camera
// basis vectors are pre-scaled by tan(fov/2) (and aspect for right).
struct FrameParams {
    float cam_pos_x, cam_pos_y, cam_pos_z;
    float min_distance2;          // inverse-square falloff is clamped here
    float cam_right_x, cam_right_y, cam_right_z;
    float relative_error;
    float cam_up_x, cam_up_y, cam_up_z;
    uint max_cut;
    float cam_fwd_x, cam_fwd_y, cam_fwd_z;
    uint spp;
    uint width, height, seed, light_count;
    uint roots[kLightTypeCount];  // root node of each type's tree; kInvalidIndex if absent
    uint loop_probe_rounds;       // always 2: see lc_loops_were_cut_short (shaders/kernel.glsl)
    uint env_width, env_height;   // environment map seen by rays that leave; 0 x 0: black
    uint light_samples;           // sampled: lights per camera sample; stochastic: draws per cluster
    uint light_pick;              // --method sampled: kLightPick*
    float vpl_min_distance2;      // VPLs' inverse-square clamp: min_distance2 or render.indirect.clamp^2
    float pixel_spread;           // angle of a sample's stratum at the image's centre (radians): camera rays' cones
};

#ifdef __cplusplus
}  // namespace lc::gpu
#endif
#endif
