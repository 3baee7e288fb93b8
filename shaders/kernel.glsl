// Common part of the compute kernels: buffers, frame constants, feature
// switches, and the shared kernel headers compiled as GLSL over them.
// Included once at the top of every *.comp file.
#ifndef LC_KERNEL_GLSL
#define LC_KERNEL_GLSL

// The chunks of a split scene array are read through device addresses,
// made from the two 32-bit words in the ChunkTable (no shaderInt64 needed).
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require

#include "bindings.glsl"

layout(local_size_x_id = kSpecWorkgroupSize) in;

// Switched off for scenes that do not need them, so the compiler drops the
// GGX lobe, the shadow-ray traversal, the Disney BRDF or its sheen and
// clearcoat lobes (lc_shared/shading.h reads these).
layout(constant_id = kSpecEnableGgx) const bool kEnableGgx = true;
layout(constant_id = kSpecEnableShadows) const bool kEnableShadows = true;
layout(constant_id = kSpecEnableOriented) const bool kEnableOriented = true;
layout(constant_id = kSpecEnableTextures) const bool kEnableTextures = true;
layout(constant_id = kSpecEnableDisney) const bool kEnableDisney = true;
layout(constant_id = kSpecEnableSheen) const bool kEnableSheen = true;
layout(constant_id = kSpecEnableClearcoat) const bool kEnableClearcoat = true;

// PushConstants of bindings.glsl: this dispatch's tile, sample and split.
layout(push_constant) uniform Push { PushConstants push; };
layout(std430, binding = kBindingFrame) readonly buffer Frame { FrameParams frame; };

// The scene arrays. Each is read through lc_<name>(i): element i of the
// array, which is at the array's binding when the array fits one buffer (or
// i lies in its first chunk), else in chunk i >> shift, read through the
// chunk's buffer device address (docs/vulkan.md, "Scene arrays larger than a
// buffer"). With no array split, kSplitScene folds the second path away.
layout(constant_id = kSpecSplitScene) const bool kSplitScene = false;
layout(std430, binding = kBindingChunkTable) readonly buffer ChunkTable {
    uint chunk_first[kChunkTableFirstWords];
    uvec2 chunk_addr[];
};
#define LC_SCENE_ARRAY(Type, name, binding_index)                                                      \
    layout(std430, binding = binding_index) readonly buffer name##_block { Type name[]; };            \
    layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer name##_chunk {       \
        Type v[];                                                                                      \
    };                                                                                                 \
    layout(constant_id = kSpecChunkShift + binding_index) const uint name##_shift = 31u;               \
    Type lc_##name(uint i) {                                                                           \
        const uint chunk = i >> name##_shift;                                                          \
        if (!kSplitScene || chunk == 0u) return name[i];                                               \
        return name##_chunk(chunk_addr[chunk_first[binding_index] + chunk]).v[i & ((1u << name##_shift) - 1u)]; \
    }
LC_SCENE_ARRAY(BvhNode, bvh_nodes, kBindingBvhNodes)
LC_SCENE_ARRAY(Triangle, triangles, kBindingTriangles)
LC_SCENE_ARRAY(TriangleNormals, normals, kBindingNormals)
LC_SCENE_ARRAY(TriangleUvs, uvs, kBindingUvs)
LC_SCENE_ARRAY(Material, materials, kBindingMaterials)
LC_SCENE_ARRAY(TextureInfo, textures, kBindingTextures)
LC_SCENE_ARRAY(uint, texels, kBindingTexels)
LC_SCENE_ARRAY(Light, lights, kBindingLights)
LC_SCENE_ARRAY(LightNode, light_nodes, kBindingLightNodes)
LC_SCENE_ARRAY(float, environment, kBindingEnvironment)
LC_SCENE_ARRAY(uvec4, wide_bvh_nodes, kBindingWideBvhNodes)
layout(std430, binding = kBindingGBuffer) buffer GBuffer { GBufferTexel gbuffer[]; };
layout(std430, binding = kBindingRadiance) buffer Radiance { float radiance[]; };
layout(std430, binding = kBindingPixelStats) buffer Stats { PixelStats pixel_stats[]; };

// The same five arrays as 16-byte texels (kBindingBvhNodeTexels ..),
// storage texel buffers read with imageLoad. On llvmpipe a storage-buffer
// load whose address differs between lanes is a loop over the lanes, an
// image load one gather in the kernel's own code (a texelFetch from a
// uniform texel buffer was the same gather in a function of the driver's,
// called once per fetch: 1.00 to 1.13 times the time;
// docs/results/lavapipe.md, §26);
// the host sets kTexelReads where it measured that to pay and every array
// fits a texel buffer's limit. The fields are unpacked in struct order.
layout(constant_id = kSpecTexelReads) const bool kTexelReads = false;
layout(binding = kBindingBvhNodeTexels, rgba32ui) uniform readonly restrict uimageBuffer bvh_node_texels;
layout(binding = kBindingTriangleTexels, rgba32ui) uniform readonly restrict uimageBuffer triangle_texels;
layout(binding = kBindingLightTexels, rgba32ui) uniform readonly restrict uimageBuffer light_texels;
layout(binding = kBindingLightNodeTexels, rgba32ui) uniform readonly restrict uimageBuffer light_node_texels;
layout(binding = kBindingWideBvhNodeTexels, rgba32ui) uniform readonly restrict uimageBuffer wide_bvh_node_texels;

BvhNode lc_bvh_node(uint i) {
    if (!kTexelReads) return lc_bvh_nodes(i);
    const uvec4 a = imageLoad(bvh_node_texels, int(2u * i));
    const uvec4 b = imageLoad(bvh_node_texels, int(2u * i + 1u));
    return BvhNode(uintBitsToFloat(a.x), uintBitsToFloat(a.y), uintBitsToFloat(a.z), a.w,
                   uintBitsToFloat(b.x), uintBitsToFloat(b.y), uintBitsToFloat(b.z), b.w);
}

// Word k (16 bytes) of Bvh4Node i.
uvec4 lc_bvh4_word(uint i, uint k) {
    if (!kTexelReads) return lc_wide_bvh_nodes(kBvh4NodeWords * i + k);
    return imageLoad(wide_bvh_node_texels, int(kBvh4NodeWords * i + k));
}

Triangle lc_triangle(uint i) {
    if (!kTexelReads) return lc_triangles(i);
    const vec4 a = uintBitsToFloat(imageLoad(triangle_texels, int(3u * i)));
    const vec4 b = uintBitsToFloat(imageLoad(triangle_texels, int(3u * i + 1u)));
    const uvec4 c = imageLoad(triangle_texels, int(3u * i + 2u));
    return Triangle(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, uintBitsToFloat(c.x), c.y, c.z, c.w);
}

Light lc_light(uint i) {
    if (!kTexelReads) return lc_lights(i);
    const vec4 a = uintBitsToFloat(imageLoad(light_texels, int(3u * i)));
    const vec4 b = uintBitsToFloat(imageLoad(light_texels, int(3u * i + 1u)));
    const uvec4 c = imageLoad(light_texels, int(3u * i + 2u));
    return Light(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, uintBitsToFloat(c.x), uintBitsToFloat(c.y),
                 uintBitsToFloat(c.z), c.w);
}

LightNode lc_light_node(uint i) {
    if (!kTexelReads) return lc_light_nodes(i);
    const vec4 a = uintBitsToFloat(imageLoad(light_node_texels, int(4u * i)));
    const vec4 b = uintBitsToFloat(imageLoad(light_node_texels, int(4u * i + 1u)));
    const uvec4 c = imageLoad(light_node_texels, int(4u * i + 2u));
    const uvec4 d = imageLoad(light_node_texels, int(4u * i + 3u));
    return LightNode(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, uintBitsToFloat(c.x), c.y, c.z, c.w, d.x,
                     uintBitsToFloat(d.y), uintBitsToFloat(d.z), uintBitsToFloat(d.w));
}

#define LC_BVH_NODE(i) lc_bvh_node(i)
#define LC_BVH4_WORD(i, k) lc_bvh4_word(i, k)
#define LC_TRIANGLE(i) lc_triangle(i)
#define LC_MATERIAL(i) lc_materials(i)
#define LC_UVS(i) lc_uvs(i)
#define LC_TEXTURE(i) lc_textures(i)
#define LC_TEXEL(i) lc_texels(i)
#define LC_NORMALS(i) lc_normals(i)
#define LC_LIGHT_NODE(i) lc_light_node(i)
#define LC_VPL_MIN_DISTANCE2 frame.vpl_min_distance2
#define LC_ENVIRONMENT_TEXEL(i) vec3(lc_environment(3u * (i)), lc_environment(3u * (i) + 1u), lc_environment(3u * (i) + 2u))
// LC_LIGHT is defined by each kernel (brute force offsets it by light_first).

#include "lc_shared/glsl_compat.h"
#include "lc_shared/color.h"
#include "lc_shared/octahedral.h"
#include "lc_shared/trace.h"
#include "lc_shared/textures.h"
#include "lc_shared/shading.h"

// Index of this invocation's pixel inside the tile, or kInvalidIndex for the
// invocations of the last block that lie past the tile. Workgroups take the
// tile's blocks of gl_WorkGroupSize.x pixels in the order of
// push.group_stride.
uint lc_tile_pixel() {
    uint block = (gl_WorkGroupID.x * push.group_stride) % gl_NumWorkGroups.x;
    uint i = block * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
    return i < push.tile_width * push.tile_height ? i : kInvalidIndex;
}

// Image coordinates of tile pixel i.
uint lc_tile_x(uint i) { return push.tile_x + lc_tile_column(i, push.tile_width, push.tile_height); }
uint lc_tile_y(uint i) { return push.tile_y + lc_tile_row(i, push.tile_width, push.tile_height); }

SurfacePoint lc_texel_surface(GBufferTexel g) {
    return lc_make_surface(vec3(g.px, g.py, g.pz), vec3(g.nx, g.ny, g.nz), vec3(g.wo_x, g.wo_y, g.wo_z), g.material,
                           vec2(g.u, g.v),
                           vec4(g.footprint_major_u, g.footprint_major_v, g.footprint_minor_u, g.footprint_minor_v));
}

// llvmpipe (lavapipe) ends every loop of a shader invocation for good once
// the invocation has run 65535 loop iterations in all (gallivm's loop
// limiter), silently truncating long brute-force sums and deep cuts. A loop
// that must run 2 rounds, and does not, shows it happened.
bool lc_loops_were_cut_short() {
    // The round count comes from the push constants so that the compiler
    // cannot unroll the loop; it is always 2 and independent of spp.
    uint rounds = 0u;
    for (uint k = 0u; k < frame.loop_probe_rounds; ++k) rounds += 1u;
    return rounds != frame.loop_probe_rounds;
}

// Samples are added in sample order, each divided by spp first, the way
// the CPU reference adds them: a sum of spp samples near FLT_MAX each
// would overflow before a division at the end (a sky of radiance 1e37 at
// 64 spp came out infinite).
void lc_accumulate(uint pixel, vec3 c) {
    c *= 1.0f / float(frame.spp);
    radiance[3u * pixel + 0u] += c.x;
    radiance[3u * pixel + 1u] += c.y;
    radiance[3u * pixel + 2u] += c.z;
}

#endif
