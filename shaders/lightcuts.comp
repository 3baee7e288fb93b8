// Lightcuts (Walter et al. 2005, section 4): cut selection and shading at the
// G-buffer point of every tile pixel; the result is added to the pixel's sum.
// With kStochastic (--method stochastic, Yuksel 2019) the cut is selected
// the same way and then each of its clusters that is not a single light is
// shaded again with a representative drawn afresh (lc_shared/lightcuts.h,
// lc_shade_stochastic).
//
// One dispatch normally runs each cut from the roots to the end. Where the
// driver limits how long an invocation may loop (lavapipe), the host gives
// each dispatch a budget of steps instead (a refinement, or one fresh draw
// of a stochastic cluster) and dispatches until every cut is done; a cut
// that is not done yet waits in CutState and the heap buffer.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "kernel.glsl"
#include "heap.glsl"
#define LC_LIGHT(i) lc_light(i)
#include "lc_shared/sampling.h"
#include "lc_shared/lightcuts.h"

layout(constant_id = kSpecStochastic) const bool kStochastic = false;

layout(std430, binding = kBindingCutState) buffer CutStates { CutState cut_states[]; };

void main() {
    uint i = lc_tile_pixel();
    if (i == kInvalidIndex) return;
    GBufferTexel g = gbuffer[i];
    if (g.material == kInvalidIndex) return;  // the camera ray left the scene: black
    SurfacePoint sp = lc_texel_surface(g);
    Material m = sp.mat;

    ShadeStats stats;
    stats.cut_size = 0u;
    stats.shadow_rays = 0u;
    stats.hit_max_cut = 0u;
    stats.cut_indirect = 0u;
    stats.frozen = 0u;
    stats.frozen_error = 0.0f;
    uint heap_size = 0u;
    vec3 fixed_sum = vec3(0.0f);
    vec3 heap_sum = vec3(0.0f);
    bool selected = false;  // stochastic: the cut is final; heap_sum is the fresh sum
    uint shaded = 0u;       // stochastic: heap slots shaded afresh so far
    uint draw = 0u;         // ... and draws of slot `shaded` (frame.light_samples per slot)
    uint stream = kStochastic ? lc_sample_stream(frame.seed, lc_tile_x(i), lc_tile_y(i), push.sample_index) : 0u;
    // Stochastic: the clusters that freeze are shaded afresh as they freeze.
    uint fresh_draws = kStochastic ? frame.light_samples : 0u;
    if ((push.cut_flags & kCutFirstDispatch) != 0u) {
        lc_cut_start(sp, m, frame, heap_size, fixed_sum, heap_sum, stats, stream, fresh_draws);
    } else {
        CutState s = cut_states[i];
        if ((s.flags & kCutDone) != 0u) return;
        heap_size = s.heap_size;
        stats.cut_size = s.cut_size;
        stats.cut_indirect = s.cut_indirect;
        stats.shadow_rays = s.shadow_rays;
        stats.frozen = (s.flags & kCutFroze) != 0u ? 1u : 0u;
        stats.hit_max_cut = (s.flags & kCutHitMaxCut) != 0u ? 1u : 0u;
        selected = (s.flags & kCutSelected) != 0u;
        shaded = s.shaded;
        draw = s.draw;
        fixed_sum = vec3(s.fixed_r, s.fixed_g, s.fixed_b);
        heap_sum = vec3(s.heap_r, s.heap_g, s.heap_b);
        lc_heap_restore(heap_size);
    }

    bool done = false;
    for (uint r = 0u; r < push.refine_budget && !done; ++r) {
        if (!selected) {
            if (lc_cut_refine(sp, m, frame, heap_size, fixed_sum, heap_sum, stats, stream, fresh_draws)) continue;
            selected = true;
            if (kStochastic) {
                heap_sum = fixed_sum;    // the fresh sum starts from the single lights and frozen clusters
                fixed_sum = vec3(0.0f);  // from here the sum of slot `shaded`'s draws so far
            }
            done = !kStochastic;
        } else if (kStochastic && shaded < heap_size) {
            // kStochastic written into the condition lets the host's
            // specialization drop this branch, and the ray and light
            // sampling code under it, from Lightcuts' kernel: the loop state
            // alone does not show the compiler that it is dead there.
            // A cluster's draws are summed apart and then scaled, as
            // lc_cluster_fresh_estimate sums them on the CPU.
            fixed_sum += lc_shade_cluster_stochastic(sp, lc_entry_node(LC_HEAP_LOAD(shaded)), frame.min_distance2,
                                                     stream, draw, stats);
            draw += 1u;
            if (draw == frame.light_samples) {
                heap_sum += fixed_sum * (1.0f / float(frame.light_samples));
                fixed_sum = vec3(0.0f);
                draw = 0u;
                shaded += 1u;
            }
        } else {
            done = true;
        }
    }
    // A stochastic cut whose last cluster was shaded in the last step is done.
    if (kStochastic && selected && shaded >= heap_size) done = true;
    bool cut_short = lc_loops_were_cut_short();

    if (!done) {
        PixelStats ps = pixel_stats[i];
        if ((push.cut_flags & kCutLastDispatch) != 0u) ps.flags |= kPixelCutUnfinished;
        if (cut_short) ps.flags |= kPixelLoopLimit;
        // Counted once per sample, at its first pause.
        if ((push.cut_flags & kCutFirstDispatch) != 0u) ps.paused_samples += 1u;
        pixel_stats[i] = ps;
        lc_heap_save(heap_size);
        CutState s;
        s.heap_size = heap_size;
        s.cut_size = stats.cut_size;
        s.cut_indirect = stats.cut_indirect;
        s.shadow_rays = stats.shadow_rays;
        s.flags = (stats.frozen > 0u ? kCutFroze : 0u) | (selected ? kCutSelected : 0u) |
                  (stats.hit_max_cut > 0u ? kCutHitMaxCut : 0u);
        s.fixed_r = fixed_sum.x; s.fixed_g = fixed_sum.y; s.fixed_b = fixed_sum.z;
        s.heap_r = heap_sum.x; s.heap_g = heap_sum.y; s.heap_b = heap_sum.z;
        s.shaded = shaded;
        s.draw = draw;
        cut_states[i] = s;
        return;
    }

    lc_accumulate(i, kStochastic ? heap_sum : lc_cut_result(sp, frame.min_distance2, heap_size, fixed_sum));
    PixelStats ps = pixel_stats[i];
    lc_count_add(ps.cut_size_lo, ps.cut_size_hi, stats.cut_size);
    lc_count_add(ps.cut_indirect_lo, ps.cut_indirect_hi, stats.cut_indirect);
    lc_count_add(ps.shadow_rays_lo, ps.shadow_rays_hi, stats.shadow_rays);
    ps.max_cut_samples += stats.hit_max_cut;
    ps.frozen_samples += stats.frozen > 0u ? 1u : 0u;
    if (cut_short || lc_loops_were_cut_short()) ps.flags |= kPixelLoopLimit;
    pixel_stats[i] = ps;
    if ((push.cut_flags & kCutLastDispatch) == 0u) cut_states[i].flags = kCutDone;
}
