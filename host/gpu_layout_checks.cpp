// Compile-time checks that the shared structs have the std430 layout the
// GLSL kernels expect: sizes and offsets of every field the shaders read.
#include <cstddef>

#include "lc_shared/types.h"

namespace lc::gpu {

static_assert(sizeof(BvhNode) == 32);
static_assert(offsetof(BvhNode, first_or_left) == 12);
static_assert(offsetof(BvhNode, max_x) == 16);
static_assert(offsetof(BvhNode, tri_count) == 28);

// kBvh4NodeWords uvec4 words, read as such (shaders/kernel.glsl, lc_shared/trace.h's lc_bvh4_node).
static_assert(sizeof(Bvh4Node) == 16 * kBvh4NodeWords);
static_assert(offsetof(Bvh4Node, scale_x) == 12);
static_assert(offsetof(Bvh4Node, scale_y) == 16);
static_assert(offsetof(Bvh4Node, lo_x) == 24);
static_assert(offsetof(Bvh4Node, lo_z) == 32);
static_assert(offsetof(Bvh4Node, hi_z) == 44);
static_assert(offsetof(Bvh4Node, entry) == 48);
// A leaf's triangle count - 1 fits the two bits of its entry.
static_assert(kBvhMaxLeafTriangles <= 4u);

static_assert(sizeof(Triangle) == 48);
static_assert(offsetof(Triangle, v1_x) == 12);
static_assert(offsetof(Triangle, v2_x) == 24);
static_assert(offsetof(Triangle, material) == 36);

static_assert(sizeof(TriangleNormals) == 48);
static_assert(offsetof(TriangleNormals, n2_z) == 32);

static_assert(sizeof(TriangleUvs) == 24);
static_assert(offsetof(TriangleUvs, v2) == 20);

static_assert(sizeof(Material) == 96);
static_assert(offsetof(Material, roughness) == 44);
static_assert(offsetof(Material, sheen) == 60);
static_assert(offsetof(Material, normal_scale) == 76);
static_assert(offsetof(Material, base_color_texture) == 80);
static_assert(offsetof(Material, normal_texture) == 92);

static_assert(sizeof(TextureInfo) == 44);
static_assert(offsetof(TextureInfo, height) == 8);
static_assert(offsetof(TextureInfo, sampling) == 12);
static_assert(offsetof(TextureInfo, uv_transform) == 16);
static_assert(offsetof(TextureInfo, mip_offset) == 40);
static_assert(offsetof(Material, emission_r) == 32);
static_assert(offsetof(Material, ks_r) == 12);
static_assert(offsetof(Material, alpha) == 24);
static_assert(offsetof(Material, flags) == 28);

static_assert(sizeof(Light) == 48);
static_assert(offsetof(Light, axis_x) == 24);
static_assert(offsetof(Light, cos_inner) == 36);
static_assert(offsetof(Light, type) == 44);
static_assert(offsetof(Light, r) == 12);

static_assert(sizeof(LightNode) == 64);
static_assert(offsetof(LightNode, axis_oct) == 48);
static_assert(offsetof(LightNode, cos_theta_e) == 56);
static_assert(offsetof(LightNode, max_x) == 12);
static_assert(offsetof(LightNode, intensity_r) == 24);
static_assert(offsetof(LightNode, rep_light) == 36);
static_assert(offsetof(LightNode, left) == 40);
static_assert(offsetof(LightNode, flags) == 44);

static_assert(sizeof(GBufferTexel) == 64);
static_assert(offsetof(GBufferTexel, nx) == 12);
static_assert(offsetof(GBufferTexel, wo_x) == 24);
static_assert(offsetof(GBufferTexel, material) == 36);
static_assert(offsetof(GBufferTexel, v) == 44);
static_assert(offsetof(GBufferTexel, footprint_minor_v) == 60);

static_assert(sizeof(CutEntry) == 8);
static_assert(offsetof(CutEntry, error) == 4);

static_assert(sizeof(FrameParams) == 128);
static_assert(offsetof(FrameParams, light_samples) == 112);
static_assert(offsetof(FrameParams, env_width) == 104);
static_assert(offsetof(FrameParams, vpl_min_distance2) == 120);
static_assert(offsetof(FrameParams, min_distance2) == 12);
static_assert(offsetof(FrameParams, relative_error) == 28);
static_assert(offsetof(FrameParams, max_cut) == 44);
static_assert(offsetof(FrameParams, spp) == 60);
static_assert(offsetof(FrameParams, width) == 64);
static_assert(offsetof(FrameParams, roots) == 80);
static_assert(sizeof(FrameParams::roots) == 4 * kLightTypeCount);
static_assert(offsetof(FrameParams, loop_probe_rounds) == 100);

}  // namespace lc::gpu
