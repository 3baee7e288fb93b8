// Lightcuts with one cut per 2x2 quad of pixels (cut_sharing "quad"), the
// cut the CPU's QuadCut (host/quad_cut.h) selects, step for step: a cluster
// is refined while its error bound exceeds relative_error times the
// estimate of any of the four points, in passes while the cut's list has
// room and largest bound first through a heap once it is full. Each point
// keeps its own estimate, shadow rays and sums.
//
// The four points are the four lanes of a subgroup quad. Each lane keeps
// the whole list (or heap) in its own slots: the nodes, their places, the
// pass's marks and the `key` (the largest ratio of a cluster's bound to a
// point's estimate over the quad, exchanged with subgroupQuadSwap*) are the
// same in all four, the error bound and the representative's visibility
// the lane's own. So the four make the same moves in step, and each traces
// its own shadow rays. A lane whose pixel sees no surface, or lies past the tile, keeps
// the heap with the others, with zero bounds. Quad sums are added (0 + 1) +
// (2 + 3), as on the CPU, so every lane has the same bits.
//
// As lightcuts.comp, one dispatch runs every cut to the end, or (lavapipe)
// a budget of refinements per dispatch, the cut paused in CutState and the
// heap in the heap-save buffer, both indexed by invocation.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_quad : require

#include "kernel.glsl"
#define LC_HEAP_ENTRY QuadCutEntry
#define LC_HEAP_ORDER key
#include "heap.glsl"
#define LC_LIGHT(i) lc_light(i)
#include "lc_shared/sampling.h"
#include "lc_shared/lightcuts.h"

layout(std430, binding = kBindingCutState) buffer CutStates { CutState cut_states[]; };

const float kFloatMin = 1.17549435082228750797e-38;  // FLT_MIN, 2^-126
const float kFloatMax = 3.40282346638528859812e+38;  // FLT_MAX

// The lane's point and its part of the quad's cut (host/quad_cut.h's
// members of the same names, for this lane's point).
bool q_active;      // this lane shades a surface
SurfacePoint q_sp;  // ... this one
uint q_size;        // entries in the heap
vec3 q_fixed;       // final estimates: leaves and frozen clusters
vec3 q_heap_sum;    // running sum of the heap's estimates
float q_weight;     // 1 / estimate (update_weights)
float q_root_bounds;  // the roots' finite bounds summed over the quad, times 1/4
bool q_heap_mode;   // the list is a heap (lc_quad_add), refined largest first
bool q_fresh_keys;  // heap mode: the keys are from the current weights
bool q_pass;        // list mode: a pass is under way, its marked entries still to refine
uint q_frozen;      // clusters frozen out of a full heap
ShadeStats q_stats;
// QuadCut::refine_all's marks, a bit per place in the list: the entries
// the pass under way refines. Kept here during a dispatch; at a pause they
// go into the saved entries' keys, as the sign bit (a key is never
// negative).
const uint kMarkWords = (kHeapSlots + 31u) / 32u;
uint q_marks[kMarkWords];

float lc_quad_sum(float v) {
    v += subgroupQuadSwapHorizontal(v);
    return v + subgroupQuadSwapVertical(v);
}

float lc_quad_max(float v) {
    v = max(v, subgroupQuadSwapHorizontal(v));
    return max(v, subgroupQuadSwapVertical(v));
}

bool lc_quad_any(bool b) {
    uint v = b ? 1u : 0u;
    v |= subgroupQuadSwapHorizontal(v);
    v |= subgroupQuadSwapVertical(v);
    return v != 0u;
}

// QuadCut::update_weights: 1 / estimate, the estimate taken as at least
// 2^-20 of the quad's summed estimates (of its summed root bounds while
// those are all zero).
void lc_quad_update_weights() {
    float estimate = lc_luminance(q_fixed + q_heap_sum);
    bool counts = estimate > 0.0f && !isinf(estimate);
    float total = lc_quad_sum(counts ? estimate * 0.25f : 0.0f);
    if (!lc_quad_any(counts)) total = q_root_bounds;
    float floor_estimate = clamp(total * (1.0f / 262144.0f), kFloatMin, kFloatMax);
    q_weight = 1.0f / (estimate < floor_estimate ? floor_estimate : estimate);
}

// QuadCut::key_of: the largest ratio of bound to estimate over the quad,
// at most FLT_MAX; a NaN bound is passed over.
float lc_quad_key(float error) {
    float ratio = error > 0.0f ? error * q_weight : 0.0f;
    if (!(ratio >= 0.0f)) ratio = 0.0f;
    return min(lc_quad_max(ratio), kFloatMax);
}

// QuadCut::enter: a leaf goes to the fixed sum; an interior cluster whose
// bound is above zero at some point of the quad enters the heap (true),
// with zero contribution where its bound is not.
bool lc_quad_enter(uint index, LightNode node, float error, vec3 unit, bool visible, out QuadCutEntry e) {
    vec3 intensity = lc_node_intensity(node);
    e.node = index;
    e.error = error;
    e.key = 0.0f;
    if ((node.flags & kNodeLeaf) != 0u) {
        q_fixed += unit * intensity;
        return false;
    }
    bool mine = error > 0.0f;
    if (!mine) {
        unit = vec3(0.0f);
        visible = false;
    }
    if (!lc_quad_any(mine)) return false;
    q_heap_sum += unit * intensity;
    e.node = index | (visible ? kCutEntryVisible : 0u);
    return true;
}

// QuadCut::push: into a full heap, the entry with the smallest key (this
// one included) is frozen.
// One sift after both cases, as in lc_heap_push.
void lc_quad_push(QuadCutEntry e) {
    uint slot = q_size;  // where e rises from; kInvalidIndex where e is frozen
    if (q_size < kHeapSlots) {
        q_size += 1u;
    } else {
        q_frozen += 1u;
        slot = lc_heap_smallest(q_size / 2u, q_size, e.key);
        QuadCutEntry leaving = slot == kInvalidIndex ? e : LC_HEAP_LOAD(slot);
        q_stats.frozen_error += leaving.error;
        vec3 estimate = lc_entry_estimate(q_sp, leaving, frame.min_distance2);
        q_heap_sum -= estimate;
        q_fixed += estimate;
    }
    if (slot != kInvalidIndex) lc_heap_sift_up(slot, e);
}

// Every key again from the current estimates, and the heap rebuilt.
void lc_quad_rekey() {
    lc_quad_update_weights();
    for (uint i = 0u; i < q_size; ++i) {
        QuadCutEntry e = LC_HEAP_LOAD(i);
        e.key = lc_quad_key(e.error);
        LC_HEAP_STORE(i, e);
    }
    for (uint i = q_size / 2u; i > 0u; --i) lc_heap_sift_down(i - 1u, q_size, LC_HEAP_LOAD(i - 1u));
}

bool lc_quad_marked(uint i) { return (q_marks[i >> 5u] >> (i & 31u) & 1u) != 0u; }

void lc_quad_set_mark(uint i, bool on) {
    q_marks[i >> 5u] = (q_marks[i >> 5u] & ~(1u << (i & 31u))) | ((on ? 1u : 0u) << (i & 31u));
}

// QuadCut::add: appended, unmarked, while the list has room (a list's
// keys are not kept: a pass marks from the errors); the first entry to
// find it full turns it into a heap (every key from the current estimates)
// and is pushed with its key, as is every later one.
void lc_quad_add(QuadCutEntry e) {
    if (!q_heap_mode && q_size < kHeapSlots) {
        LC_HEAP_STORE(q_size, e);
        q_size += 1u;
        return;
    }
    if (!q_heap_mode) {
        q_heap_mode = true;
        lc_quad_rekey();
    }
    e.key = lc_quad_key(e.error);
    lc_quad_push(e);
}

float lc_quad_error(LightNode node) {
    return q_active ? lc_cluster_error(q_sp, q_sp.mat, node, frame.min_distance2) : 0.0f;
}

void lc_quad_start() {
    q_size = 0u;
    q_fixed = vec3(0.0f);
    q_heap_sum = vec3(0.0f);
    q_root_bounds = 0.0f;
    q_heap_mode = false;
    q_fresh_keys = false;
    q_pass = false;
    q_frozen = 0u;
    q_stats.cut_size = 0u;
    q_stats.cut_indirect = frame.roots[kLightVpl] != kInvalidIndex ? 1u : 0u;
    float root_sum = 0.0f;
    for (uint type = 0u; type < kLightTypeCount; ++type) {
        uint index = frame.roots[type];
        if (index == kInvalidIndex) continue;
        LightNode root = LC_LIGHT_NODE(index);
        float error = lc_quad_error(root);
        vec3 unit = vec3(0.0f);
        bool visible = false;
        if (q_active && lc_cluster_needs_unit(root, error))
            unit = lc_rep_unit(q_sp, root.rep_light, frame.min_distance2, visible, q_stats);
        if (error > 0.0f && !isinf(error)) root_sum += error * 0.25f;
        q_root_bounds = lc_quad_sum(root_sum);
        QuadCutEntry e;
        if (lc_quad_enter(index, root, error, unit, visible, e)) {
            lc_quad_update_weights();
            lc_quad_add(e);
        }
        q_stats.cut_size += 1u;
    }
    lc_quad_update_weights();
}

// QuadCut::split: the cluster `top` is replaced by its children, a (the
// child with the parent's representative, which keeps its visibility) and
// b (whose contribution comes from one new shadow ray per lane); has_a and
// has_b say which of them enter the heap's list (lc_quad_enter).
void lc_quad_split(QuadCutEntry top, out QuadCutEntry a, out QuadCutEntry b, out bool has_a, out bool has_b) {
    LightNode node = LC_LIGHT_NODE(lc_entry_node(top));
    vec3 kept_unit = lc_entry_unit(q_sp, top, node, frame.min_distance2);  // the kept child's too
    q_heap_sum -= kept_unit * lc_node_intensity(node);
    bool right_shares = (node.flags & kNodeRepFromRight) != 0u;
    uint kept_index = right_shares ? node.left + 1u : node.left;
    uint fresh_index = right_shares ? node.left : node.left + 1u;
    LightNode kept_node = LC_LIGHT_NODE(kept_index);
    LightNode fresh_node = LC_LIGHT_NODE(fresh_index);
    float kept_error = lc_quad_error(kept_node);
    float fresh_error = lc_quad_error(fresh_node);
    bool fresh_leaf = (fresh_node.flags & kNodeLeaf) != 0u;
    vec3 fresh_unit = vec3(0.0f);
    bool fresh_visible = false;
    if (q_active && (fresh_leaf || fresh_error > 0.0f))
        fresh_unit = lc_rep_unit(q_sp, fresh_node.rep_light, frame.min_distance2, fresh_visible, q_stats);
    has_a = lc_quad_enter(kept_index, kept_node, kept_error, kept_unit, lc_entry_visible(top), a);
    has_b = lc_quad_enter(fresh_index, fresh_node, fresh_error, fresh_unit, fresh_visible, b);
    q_stats.cut_size += 1u;
    if (lc_node_type(node) == kLightVpl) q_stats.cut_indirect += 1u;
}

// QuadCut::refine_at: the cluster at place `at` of the list is replaced
// by its children (lc_quad_split); the kept child keeps the place
// (unmarked), the other is added. Where the kept child leaves the cut, the
// list's last entry takes its place, mark and all.
void lc_quad_refine_at(uint at) {
    QuadCutEntry a, b;
    bool has_a, has_b;
    lc_quad_split(LC_HEAP_LOAD(at), a, b, has_a, has_b);
    if (has_a) {
        LC_HEAP_STORE(at, a);
    } else {
        q_size -= 1u;
        if (at != q_size) {
            LC_HEAP_STORE(at, LC_HEAP_LOAD(q_size));
            lc_quad_set_mark(at, lc_quad_marked(q_size));
            lc_quad_set_mark(q_size, false);
        }
    }
    if (has_b) lc_quad_add(b);
}

// QuadCut::refine_top: the cluster at the top of the heap is replaced by
// its children (lc_quad_split).
void lc_quad_refine_top() {
    QuadCutEntry a, b;
    bool has_a, has_b;
    lc_quad_split(LC_HEAP_LOAD(0u), a, b, has_a, has_b);
    lc_quad_update_weights();
    a.key = has_a ? lc_quad_key(a.error) : 0.0f;
    b.key = has_b ? lc_quad_key(b.error) : 0.0f;
    // The larger child takes the parent's place and sinks; the smaller one
    // is pushed.
    if (has_b && (!has_a || b.key > a.key)) {
        QuadCutEntry swap_entry = a;
        a = b;
        b = swap_entry;
        bool swap_has = has_a;
        has_a = has_b;
        has_b = swap_has;
    }
    // Where neither child enters, the last entry sinks from the top
    // instead: one sift for both cases (llvmpipe runs both sides of a
    // branch, loops included, for all the lanes).
    if (!has_a) {
        q_size -= 1u;
        a = LC_HEAP_LOAD(q_size);
    }
    if (q_size > 0u) lc_heap_sift_down(0u, q_size, a);
    if (has_b) lc_quad_push(b);
}

// QuadCut::refine_all, one refinement at a time: false once the cut is
// final or at max_cut. In passes while the list has room (a pass takes the
// weights once, marks the entries whose key is above relative_error, and
// refines them lowest place first; final when a pass marks none), then
// largest first through the heap (final when every key is at most
// relative_error, checked with fresh keys).
bool lc_quad_refine() {
    while (!q_heap_mode) {
        if (!q_pass) {
            lc_quad_update_weights();
            // An entry's key is above relative_error where its ratio is at
            // some lane: each lane's tests of 32 entries, one word, ORed
            // over the quad (two exchanges a word, where the keys took two
            // an entry).
            bool any = false;
            for (uint w = 0u; w < kMarkWords; ++w) {
                uint bits = 0u;
                for (uint j = 0u; j < 32u && 32u * w + j < q_size; ++j) {
                    float error = LC_HEAP_LOAD(32u * w + j).error;
                    bool above = error > 0.0f && error * q_weight > frame.relative_error;
                    bits |= (above ? 1u : 0u) << j;
                }
                bits |= subgroupQuadSwapHorizontal(bits);
                bits |= subgroupQuadSwapVertical(bits);
                q_marks[w] = bits;
                any = any || bits != 0u;
            }
            if (!any) return false;
            q_pass = true;
        }
        uint at = kInvalidIndex;
        for (uint w = 0u; w < kMarkWords && at == kInvalidIndex; ++w)
            if (q_marks[w] != 0u) at = 32u * w + uint(findLSB(q_marks[w]));
        if (at == kInvalidIndex) {
            q_pass = false;
            continue;
        }
        lc_quad_set_mark(at, false);
        if (q_stats.cut_size >= frame.max_cut) {
            q_stats.hit_max_cut = 1u;
            return false;
        }
        lc_quad_refine_at(at);
        // QuadCut::refine_heap starts from the current estimates.
        if (q_heap_mode) {
            lc_quad_update_weights();
            q_fresh_keys = false;
        }
        return true;
    }
    while (q_size > 0u) {
        float top_key = lc_quad_key(LC_HEAP_LOAD(0u).error);
        if (!(top_key > frame.relative_error)) {
            if (q_fresh_keys) return false;
            lc_quad_rekey();
            q_fresh_keys = true;
            continue;
        }
        if (q_stats.cut_size >= frame.max_cut) {
            q_stats.hit_max_cut = 1u;
            return false;
        }
        q_fresh_keys = false;
        lc_quad_refine_top();
        return true;
    }
    return false;
}

void main() {
    // Invocation `invocation` is lane invocation % 4 of quad invocation / 4
    // of the tile; the lane order of a subgroup quad (0 top left, 1 top
    // right, 2 bottom left, 3 bottom right) is host/quad_cut.h's.
    uint block = (gl_WorkGroupID.x * push.group_stride) % gl_NumWorkGroups.x;
    uint invocation = block * gl_WorkGroupSize.x + gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
    uint quad = invocation / 4u, lane = invocation % 4u;
    uint quads_x = (push.tile_width + 1u) / 2u;
    if (quad >= quads_x * ((push.tile_height + 1u) / 2u)) return;  // the whole quad
    uint x = 2u * (quad % quads_x) + (lane & 1u), y = 2u * (quad / quads_x) + (lane >> 1u);
    uint i = kInvalidIndex;  // this lane's tile pixel
    GBufferTexel g;
    g.material = kInvalidIndex;
    if (x < push.tile_width && y < push.tile_height) {
        i = lc_tile_index(x, y, push.tile_width, push.tile_height);
        g = gbuffer[i];
    }
    q_active = g.material != kInvalidIndex;
    // A lane without a surface reads nothing of its point; it gets a valid
    // one all the same (material 0), so that no read can go astray.
    q_sp = q_active ? lc_texel_surface(g)
                    : lc_make_surface(vec3(0.0f), vec3(0.0f, 0.0f, 1.0f), vec3(0.0f, 0.0f, 1.0f), 0u, vec2(0.0f),
                                      vec4(0.0f));
    if (!lc_quad_any(q_active)) return;  // no surface in the quad

    q_stats.cut_size = 0u;
    q_stats.shadow_rays = 0u;
    q_stats.hit_max_cut = 0u;
    q_stats.cut_indirect = 0u;
    q_stats.frozen = 0u;
    q_stats.frozen_error = 0.0f;
    if ((push.cut_flags & kCutFirstDispatch) != 0u) {
        lc_quad_start();
    } else {
        CutState s = cut_states[invocation];
        if ((s.flags & kCutDone) != 0u) return;  // the whole quad
        q_size = s.heap_size;
        q_stats.cut_size = s.cut_size;
        q_stats.cut_indirect = s.cut_indirect;
        q_stats.shadow_rays = s.shadow_rays;
        q_frozen = (s.flags & kCutFroze) != 0u ? 1u : 0u;
        q_fresh_keys = (s.flags & kCutFreshKeys) != 0u;
        q_heap_mode = (s.flags & kCutHeapMode) != 0u;
        q_pass = (s.flags & kCutPassUnderWay) != 0u;
        q_fixed = vec3(s.fixed_r, s.fixed_g, s.fixed_b);
        q_heap_sum = vec3(s.heap_r, s.heap_g, s.heap_b);
        q_root_bounds = uintBitsToFloat(s.shaded);
        q_weight = uintBitsToFloat(s.draw);
        lc_heap_restore(q_size);
        // A pass's marks, from the saved keys' sign bits.
        for (uint w = 0u; w < kMarkWords; ++w) q_marks[w] = 0u;
        if (q_pass) {
            for (uint i = 0u; i < q_size; ++i) {
                QuadCutEntry e = LC_HEAP_LOAD(i);
                uint bits = floatBitsToUint(e.key);
                lc_quad_set_mark(i, (bits & 0x80000000u) != 0u);
                e.key = uintBitsToFloat(bits & 0x7FFFFFFFu);
                LC_HEAP_STORE(i, e);
            }
        }
    }

    bool done = false;
    for (uint r = 0u; r < push.refine_budget && !done; ++r) done = !lc_quad_refine();
    bool cut_short = lc_loops_were_cut_short();

    if (!done) {
        if (i != kInvalidIndex && q_active) {
            PixelStats ps = pixel_stats[i];
            if ((push.cut_flags & kCutLastDispatch) != 0u) ps.flags |= kPixelCutUnfinished;
            if (cut_short) ps.flags |= kPixelLoopLimit;
            if ((push.cut_flags & kCutFirstDispatch) != 0u) ps.paused_samples += 1u;
            pixel_stats[i] = ps;
        }
        if (q_pass) {
            for (uint i = 0u; i < q_size; ++i)
                if (lc_quad_marked(i)) {
                    QuadCutEntry e = LC_HEAP_LOAD(i);
                    e.key = uintBitsToFloat(floatBitsToUint(e.key) | 0x80000000u);
                    LC_HEAP_STORE(i, e);
                }
        }
        lc_heap_save(q_size);
        CutState s;
        s.heap_size = q_size;
        s.cut_size = q_stats.cut_size;
        s.cut_indirect = q_stats.cut_indirect;
        s.shadow_rays = q_stats.shadow_rays;
        s.flags = (q_frozen > 0u ? kCutFroze : 0u) | (q_fresh_keys ? kCutFreshKeys : 0u) |
                  (q_heap_mode ? kCutHeapMode : 0u) | (q_pass ? kCutPassUnderWay : 0u);
        s.fixed_r = q_fixed.x; s.fixed_g = q_fixed.y; s.fixed_b = q_fixed.z;
        s.heap_r = q_heap_sum.x; s.heap_g = q_heap_sum.y; s.heap_b = q_heap_sum.z;
        s.shaded = floatBitsToUint(q_root_bounds);
        s.draw = floatBitsToUint(q_weight);
        cut_states[invocation] = s;
        return;
    }

    if ((push.cut_flags & kCutLastDispatch) == 0u) cut_states[invocation].flags = kCutDone;
    if (!q_active) return;
    lc_accumulate(i, lc_cut_result(q_sp, frame.min_distance2, q_size, q_fixed));
    PixelStats ps = pixel_stats[i];
    lc_count_add(ps.cut_size_lo, ps.cut_size_hi, q_stats.cut_size);
    lc_count_add(ps.cut_indirect_lo, ps.cut_indirect_hi, q_stats.cut_indirect);
    lc_count_add(ps.shadow_rays_lo, ps.shadow_rays_hi, q_stats.shadow_rays);
    ps.max_cut_samples += q_stats.hit_max_cut;
    ps.frozen_samples += q_frozen > 0u ? 1u : 0u;
    if (cut_short || lc_loops_were_cut_short()) ps.flags |= kPixelLoopLimit;
    pixel_stats[i] = ps;
}
