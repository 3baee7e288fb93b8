// Light sampling (--method sampled): light samples
// [push.light_first, push.light_first + push.light_count) of the
// frame.light_samples drawn at the G-buffer point of every tile pixel
// (lc_shared/sampling.h), one shadow ray each; their sum, each divided by
// frame.light_samples, is added to the pixel's sum. The host covers all
// light samples in one dispatch, or in several ranges where the driver
// limits the loop iterations.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "kernel.glsl"
#define LC_LIGHT(i) lc_light(i)
#include "lc_shared/sampling.h"

void main() {
    uint i = lc_tile_pixel();
    if (i == kInvalidIndex) return;
    GBufferTexel g = gbuffer[i];
    if (g.material == kInvalidIndex) return;  // the camera ray left the scene: black

    ShadeStats stats;
    stats.cut_size = 0u;
    stats.shadow_rays = 0u;
    stats.hit_max_cut = 0u;
    stats.cut_indirect = 0u;
    uint stream = lc_sample_stream(frame.seed, lc_tile_x(i), lc_tile_y(i), push.sample_index);
    vec3 c = lc_shade_sampled(lc_texel_surface(g), frame, stream, push.light_first, push.light_count, stats);
    lc_accumulate(i, c);
    lc_count_add(pixel_stats[i].shadow_rays_lo, pixel_stats[i].shadow_rays_hi, stats.shadow_rays);
    if (lc_loops_were_cut_short()) pixel_stats[i].flags |= kPixelLoopLimit;
}
