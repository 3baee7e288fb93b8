// Brute force: lights [push.light_first, push.light_first + push.light_count), one
// shadow ray each, at the G-buffer point of every tile pixel; the result is
// added to the pixel's sum. The host covers all lights in one dispatch, or
// in several ranges where the driver limits the loop iterations.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "kernel.glsl"
#define LC_LIGHT(i) lc_light(push.light_first + (i))
#include "lc_shared/brute.h"

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
    vec3 c = lc_shade_brute(lc_texel_surface(g), push.light_count, frame.min_distance2, stats);
    lc_accumulate(i, c);
    lc_count_add(pixel_stats[i].shadow_rays_lo, pixel_stats[i].shadow_rays_hi, stats.shadow_rays);
    if (lc_loops_were_cut_short()) pixel_stats[i].flags |= kPixelLoopLimit;
}
