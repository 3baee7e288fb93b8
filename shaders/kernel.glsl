// Common part of the compute kernels: buffers, frame constants, feature
// switches, and the shared kernel headers compiled as GLSL over them.
// Included once at the top of every *.comp file.
#ifndef LC_KERNEL_GLSL
#define LC_KERNEL_GLSL

#include "bindings.glsl"

layout(local_size_x_id = kSpecWorkgroupSize) in;

// Switched off for scenes that do not need them, so the compiler drops the
// GGX lobe, the shadow-ray traversal, the Disney BRDF or its sheen and
// clearcoat lobes (shared/shading.h reads these).
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

layout(std430, binding = kBindingBvhNodes) readonly buffer BvhNodes { BvhNode bvh_nodes[]; };
layout(std430, binding = kBindingTriangles) readonly buffer Triangles { Triangle triangles[]; };
layout(std430, binding = kBindingNormals) readonly buffer Normals { TriangleNormals normals[]; };
layout(std430, binding = kBindingUvs) readonly buffer Uvs { TriangleUvs uvs[]; };
layout(std430, binding = kBindingMaterials) readonly buffer Materials { Material materials[]; };
layout(std430, binding = kBindingTextures) readonly buffer Textures { TextureInfo textures[]; };
layout(std430, binding = kBindingTexels) readonly buffer Texels { uint texels[]; };
layout(std430, binding = kBindingLights) readonly buffer Lights { Light lights[]; };
layout(std430, binding = kBindingLightNodes) readonly buffer LightNodes { LightNode light_nodes[]; };
layout(std430, binding = kBindingEnvironment) readonly buffer Environment { float environment[]; };
layout(std430, binding = kBindingGBuffer) buffer GBuffer { GBufferTexel gbuffer[]; };
layout(std430, binding = kBindingRadiance) buffer Radiance { float radiance[]; };
layout(std430, binding = kBindingPixelStats) buffer Stats { PixelStats pixel_stats[]; };

#define LC_BVH_NODE(i) bvh_nodes[i]
#define LC_TRIANGLE(i) triangles[i]
#define LC_MATERIAL(i) materials[i]
#define LC_UVS(i) uvs[i]
#define LC_TEXTURE(i) textures[i]
#define LC_TEXEL(i) texels[i]
#define LC_NORMALS(i) normals[i]
#define LC_LIGHT_NODE(i) light_nodes[i]
#define LC_VPL_MIN_DISTANCE2 frame.vpl_min_distance2
#define LC_ENVIRONMENT_TEXEL(i) vec3(environment[3u * (i)], environment[3u * (i) + 1u], environment[3u * (i) + 2u])
// LC_LIGHT is defined by each kernel (brute force offsets it by light_first).

#include "shared/glsl_compat.h"
#include "shared/color.h"
#include "shared/octahedral.h"
#include "shared/trace.h"
#include "shared/textures.h"
#include "shared/shading.h"

// Index of this invocation's pixel inside the tile, or kInvalidIndex for the
// invocations of the last workgroup that lie past the tile.
uint lc_tile_pixel() {
    uint i = gl_GlobalInvocationID.x;
    return i < push.tile_width * push.tile_height ? i : kInvalidIndex;
}

// Image coordinates of tile pixel i.
uint lc_tile_x(uint i) { return push.tile_x + i % push.tile_width; }
uint lc_tile_y(uint i) { return push.tile_y + i / push.tile_width; }

SurfacePoint lc_texel_surface(GBufferTexel g) {
    return lc_make_surface(vec3(g.px, g.py, g.pz), vec3(g.nx, g.ny, g.nz), vec3(g.wo_x, g.wo_y, g.wo_z), g.material,
                           vec2(g.u, g.v));
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

// Samples are summed in sample order, the way the CPU reference sums them;
// the host divides by spp.
void lc_accumulate(uint pixel, vec3 c) {
    radiance[3u * pixel + 0u] += c.x;
    radiance[3u * pixel + 1u] += c.y;
    radiance[3u * pixel + 2u] += c.z;
}

#endif
