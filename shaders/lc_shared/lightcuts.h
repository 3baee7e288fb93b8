// The Lightcuts cut selection (Walter et al. 2005, section 4). Shared by the
// CPU reference and the Vulkan kernels; needs trace.h and shading.h first.
//
// The includer defines:
//   LC_LIGHT_NODE(i)        -> LightNode
//   HeapEntry               the heap's entry: CutEntry, or (with
//                           LC_HEAP_KEEPS_UNITS) a record with the same
//                           node and error and the unit contribution `unit`
//   LC_HEAP_LOAD(i)         -> HeapEntry       (heap slot i of this point)
//   LC_HEAP_STORE(i, e)     stores HeapEntry e in slot i
//   LC_HEAP_CAPACITY        K, the heap's capacity (see lc_heap_push)
//   LC_HEAP_ORDER (optional) the entry's field that orders the heap: `error`
//                           unless defined (a quad's shared cut orders by
//                           `key`, quadcuts.comp)
//   LC_PREFETCH_LIGHT_NODES(i) (optional) starts loading nodes i and i + 1
//   LC_HEAP_SMALLEST(from, to, bound) (optional) lc_heap_smallest's answer,
//                           found the includer's way
//   LC_CHILD_ERRORS(sp, m, left, right, min_distance2) (optional) -> vec2,
//                           both children's lc_cluster_error at once
// In the Vulkan kernels the K slots are each invocation's own array or in
// workgroup shared memory (shaders/heap.glsl); on the CPU a per-thread
// array.
// No include guard: each kernel context (a GLSL shader, a C++ kernel
// struct in host/cpu_kernel.h) includes it exactly once.

// Unscaled contribution of a cluster's representative (material * geometry
// * visibility): the cluster's estimate is this times its RGB intensity.
// `visible` is what the shadow ray found (false when no ray was needed
// because the light cannot reach the point).
vec3 lc_rep_unit(LC_IN(SurfacePoint) sp, uint light_index, float min_distance2, LC_OUT(bool) visible,
                 LC_INOUT(ShadeStats) stats) {
    vec3 wi;
    float t_max;
    vec3 unit = lc_light_unit(sp, LC_LIGHT(light_index), min_distance2, wi, t_max);
    visible = false;
    if (!(unit.x + unit.y + unit.z > 0.0f)) return vec3(0.0f);
    stats.shadow_rays += 1u;
    visible = lc_visible(sp, wi, t_max);
    return visible ? unit : vec3(0.0f);
}

// The same contribution again, from the visibility an earlier ray found:
// the same function of the same inputs, without the ray.
vec3 lc_rep_unit_known(LC_IN(SurfacePoint) sp, uint light_index, float min_distance2, bool visible) {
    if (!visible) return vec3(0.0f);
    vec3 wi;
    float t_max;
    return lc_light_unit(sp, LC_LIGHT(light_index), min_distance2, wi, t_max);
}

#ifndef LC_HEAP_ORDER
#define LC_HEAP_ORDER error
#endif

uint lc_entry_node(HeapEntry e) { return e.node & kCutEntryNodeMask; }
bool lc_entry_visible(HeapEntry e) { return (e.node & kCutEntryVisible) != 0u; }

// An entry's representative's unit contribution. The GPU evaluates it again
// from the visibility bit (its heap must stay small); the CPU, which has
// the memory, keeps it beside the entry (LC_HEAP_KEEPS_UNITS). Both are the
// same function of the same inputs.
vec3 lc_entry_unit(LC_IN(SurfacePoint) sp, HeapEntry e, LC_IN(LightNode) node, float min_distance2) {
#ifdef LC_HEAP_KEEPS_UNITS
    (void)sp;
    (void)node;
    (void)min_distance2;
    return e.unit;
#else
    return lc_rep_unit_known(sp, node.rep_light, min_distance2, lc_entry_visible(e));
#endif
}

// An entry's estimate: its representative's contribution times the
// cluster's intensity.
vec3 lc_entry_estimate(LC_IN(SurfacePoint) sp, HeapEntry e, float min_distance2) {
    LightNode node = LC_LIGHT_NODE(lc_entry_node(e));
    return lc_entry_unit(sp, e, node, min_distance2) * lc_node_intensity(node);
}

void lc_heap_sift_up(uint i, HeapEntry e) {
    while (i > 0u) {
        uint parent = (i - 1u) / 2u;
        HeapEntry p = LC_HEAP_LOAD(parent);
        if (p.LC_HEAP_ORDER >= e.LC_HEAP_ORDER) break;
        LC_HEAP_STORE(i, p);
        i = parent;
    }
    LC_HEAP_STORE(i, e);
}

// Puts e in slot i of a heap of `size` entries and lets it sink to its
// place.
void lc_heap_sift_down(uint i, uint size, HeapEntry e) {
    while (true) {
        uint child = 2u * i + 1u;
        if (child >= size) break;
        // The larger child by its error alone, as arithmetic rather than a
        // branch (which way it goes is a coin toss, so a branch would be
        // mispredicted at every other level); the entry is read once chosen
        // (on the CPU, copying whole entries to compare them made the
        // compiler write one field and read the entry back, a stalled
        // store-to-load forward per level), and its error is the one already
        // read, not read again (on llvmpipe each read of the heap at an
        // index that differs between lanes is a loop over the lanes).
        float child_error = LC_HEAP_LOAD(child).LC_HEAP_ORDER;
        if (child + 1u < size) {
            float right_error = LC_HEAP_LOAD(child + 1u).LC_HEAP_ORDER;
            child += uint(right_error > child_error);
            child_error = right_error > child_error ? right_error : child_error;
        }
        if (child_error <= e.LC_HEAP_ORDER) break;
        HeapEntry c = LC_HEAP_LOAD(child);
        c.LC_HEAP_ORDER = child_error;
        LC_HEAP_STORE(i, c);
        i = child;
    }
    LC_HEAP_STORE(i, e);
}

// Puts e in place of the largest entry (slot 0) and lets it sink to its
// place: a pop and a push in one pass.
void lc_heap_replace_top(uint size, HeapEntry e) { lc_heap_sift_down(0u, size, e); }

// Removes the largest entry (slot 0).
void lc_heap_pop(LC_INOUT(uint) size) {
    size -= 1u;
    if (size > 0u) lc_heap_replace_top(size, LC_HEAP_LOAD(size));
}

// The slot in [from, to) with the smallest error, the first of equals,
// if that error is below `bound`; kInvalidIndex if none is.
uint lc_heap_smallest_scan(uint from, uint to, float bound) {
    uint smallest = kInvalidIndex;
    float smallest_error = bound;
    for (uint i = from; i < to; ++i) {
        float error = LC_HEAP_LOAD(i).LC_HEAP_ORDER;
        if (error < smallest_error) {
            smallest_error = error;
            smallest = i;
        }
    }
    return smallest;
}

uint lc_heap_smallest(uint from, uint to, float bound) {
#ifdef LC_HEAP_SMALLEST
    // The includer's own search (the CPU's SSE one, the GPU's unrolled
    // one), the same answer.
    return LC_HEAP_SMALLEST(from, to, bound);
#else
    return lc_heap_smallest_scan(from, to, bound);
#endif
}

// Stochastic Lightcuts' estimate of one cluster: the mean of `draws` fresh
// representatives (lc_shade_cluster_stochastic), summed apart from
// everything else and then scaled (added one by one into the pixel's sum,
// 65,536 draws of each of a hundred clusters put the plane 0.9% off, in
// relative RMSE, by rounding). Two
// nested loops of at most 256 trips: llvmpipe stops a loop after 65,535.
vec3 lc_cluster_fresh_estimate(LC_IN(SurfacePoint) sp, uint node_index, float min_distance2, uint stream, uint draws,
                               LC_INOUT(ShadeStats) stats) {
    vec3 sum = vec3(0.0f);
    for (uint first = 0u; first < draws; first += 256u)
        for (uint d = first; d < min(draws, first + 256u); ++d)
            sum += lc_shade_cluster_stochastic(sp, node_index, min_distance2, stream, d, stats);
    return sum * (1.0f / float(draws));
}

// The bounded heap: at most LC_HEAP_CAPACITY entries. A push into a full
// heap freezes the entry with the smallest bound, the new one included (the
// new one on a tie): it stays in the cut with its current estimate, which
// moves from heap_sum into the frozen part of the sum, `fixed_sum`, and is
// never refined. The smallest entry of a max-heap is one of its leaves,
// slots size/2 and up; the new entry takes its slot and rises.
// One sift for both cases, after them: llvmpipe runs every branch for all
// the lanes of a SIMD group, so a sift in each would be two loops a push.
//
// fresh_draws > 0 (Stochastic Lightcuts): a frozen cluster is shaded with
// that many fresh representatives from `stream` as it freezes, since it
// will not be in the heap when the cut's clusters are shaded afresh; the
// fresh estimate goes into fixed_sum and the difference from the fixed one
// into heap_sum, so that the criterion's sum (fixed_sum + heap_sum), and
// with it the cut, stays what the fixed representatives make it.
void lc_heap_push(LC_IN(SurfacePoint) sp, float min_distance2, LC_INOUT(uint) size, HeapEntry e, vec3 estimate,
                  LC_INOUT(vec3) fixed_sum, LC_INOUT(vec3) heap_sum, LC_INOUT(ShadeStats) stats, uint stream,
                  uint fresh_draws) {
    uint slot = size;  // where e rises from; kInvalidIndex where e is frozen
    if (size < uint(LC_HEAP_CAPACITY)) {
        size += 1u;
        heap_sum += estimate;
    } else {
        stats.frozen += 1u;
        slot = lc_heap_smallest(size / 2u, size, e.error);
        HeapEntry leaving = e;
        vec3 frozen = estimate;
        if (slot == kInvalidIndex) {
            stats.frozen_error += e.error;
        } else {
            leaving = LC_HEAP_LOAD(slot);
            stats.frozen_error += leaving.error;
            frozen = lc_entry_estimate(sp, leaving, min_distance2);
            heap_sum += estimate - frozen;
        }
        if (fresh_draws > 0u) {
            vec3 fresh = lc_cluster_fresh_estimate(sp, lc_entry_node(leaving), min_distance2, stream, fresh_draws, stats);
            heap_sum += frozen - fresh;
            frozen = fresh;
        }
        fixed_sum += frozen;
    }
    if (slot != kInvalidIndex) lc_heap_sift_up(slot, e);
}

// A cluster's error bound at the point: the luminance of its bound on
// material * geometry * emission times its intensity; zero for a leaf,
// which is exact.
float lc_cluster_error(LC_IN(SurfacePoint) sp, LC_IN(Material) m, LC_IN(LightNode) node, float min_distance2) {
    if ((node.flags & kNodeLeaf) != 0u) return 0.0f;
    return lc_luminance(lc_cluster_bound(sp, m, node, min_distance2) * lc_node_intensity(node));
}

// Whether a cluster with this lc_cluster_error needs its representative's
// contribution: a leaf always; an interior node whose bound is zero
// contributes exactly zero, and needs no ray.
bool lc_cluster_needs_unit(LC_IN(LightNode) node, float error) {
    return (node.flags & kNodeLeaf) != 0u || error > 0.0f;
}

// One cluster (`node`, at node_index, with its lc_cluster_error) entering
// the cut, with its representative's unit contribution `unit` and the
// visibility behind it, as lc_rep_unit found them (or anything, where
// lc_cluster_needs_unit is false). A leaf is final (exact, zero error) and
// goes to fixed_sum. True for a refinable interior node, whose heap entry
// and estimate are then in `e` and `estimate` for the caller to place in
// the heap.
// The ray is the caller's: a kernel compiled for a GPU or lavapipe inlines
// every call, and one call site of the ray per caller keeps one copy of the
// traversal loop there.
bool lc_cluster_entry(uint node_index, LC_IN(LightNode) node, float error, vec3 unit, bool visible,
                      LC_OUT(HeapEntry) e, LC_OUT(vec3) estimate, LC_INOUT(vec3) fixed_sum) {
    // Defined on every path (the caller reads them only after a true).
    e.node = kInvalidIndex;
    e.error = 0.0f;
#ifdef LC_HEAP_KEEPS_UNITS
    e.unit = vec3(0.0f);
#endif
    estimate = vec3(0.0f);
    vec3 intensity = lc_node_intensity(node);
    bool leaf = (node.flags & kNodeLeaf) != 0u;
    if (!lc_cluster_needs_unit(node, error)) return false;
    if (leaf) {
        fixed_sum += unit * intensity;
        return false;
    }
    e.node = node_index | (visible ? kCutEntryVisible : 0u);
    e.error = error;
#ifdef LC_HEAP_KEEPS_UNITS
    e.unit = unit;
#endif
#ifdef LC_PREFETCH_LIGHT_NODES
    // The children are read when this entry is refined, if ever: start
    // loading them now (the CPU; the GLSL kernels have no prefetch).
    LC_PREFETCH_LIGHT_NODES(node.left);
#endif
    estimate = unit * intensity;
    return true;
}

// Adds one cluster to the cut (lc_cluster_entry), into the heap if it can
// be refined.
void lc_add_cluster(LC_IN(SurfacePoint) sp, uint node_index, LC_IN(LightNode) node, float error, float min_distance2,
                    LC_INOUT(uint) heap_size, LC_INOUT(vec3) fixed_sum, LC_INOUT(vec3) heap_sum,
                    LC_INOUT(ShadeStats) stats, uint stream, uint fresh_draws) {
    HeapEntry e;
    vec3 estimate;
    bool visible = false;
    vec3 unit = vec3(0.0f);
    if (lc_cluster_needs_unit(node, error)) unit = lc_rep_unit(sp, node.rep_light, min_distance2, visible, stats);
    if (lc_cluster_entry(node_index, node, error, unit, visible, e, estimate, fixed_sum))
        lc_heap_push(sp, min_distance2, heap_size, e, estimate, fixed_sum, heap_sum, stats, stream, fresh_draws);
}

// Walter 2005, section 4: start from the roots, repeatedly replace the
// cluster with the largest error bound by its children while that bound
// exceeds relative_error times the current estimate (both as luminance) and
// the cut is smaller than max_cut.
//
// In three steps (start, one refinement, result) so that the GPU can spread
// a long refinement over several dispatches; lc_shade_lightcuts runs them
// back to back. fixed_sum holds the estimates that are final (leaves and
// frozen clusters), heap_sum the running sum of the heap's. `stream` and
// `fresh_draws`: lc_heap_push's (Stochastic Lightcuts; 0 draws otherwise).
void lc_cut_start(SurfacePoint sp, Material m, FrameParams f, LC_OUT(uint) heap_size,
                  LC_OUT(vec3) fixed_sum, LC_OUT(vec3) heap_sum, LC_INOUT(ShadeStats) stats, uint stream,
                  uint fresh_draws) {
    heap_size = 0u;
    fixed_sum = vec3(0.0f);
    heap_sum = vec3(0.0f);
    stats.cut_size = 0u;
    uint root_count = 0u;
    for (uint type = 0u; type < kLightTypeCount; ++type) {
        if (f.roots[type] == kInvalidIndex) continue;
        LightNode root = LC_LIGHT_NODE(f.roots[type]);
        lc_add_cluster(sp, f.roots[type], root, lc_cluster_error(sp, m, root, f.min_distance2), f.min_distance2,
                       heap_size, fixed_sum, heap_sum, stats, stream, fresh_draws);
        root_count += 1u;
    }
    stats.cut_size = root_count;
    // A tree holds one type, so a refinement changes the count of VPL
    // clusters by one exactly where it splits a VPL node.
    stats.cut_indirect = f.roots[kLightVpl] != kInvalidIndex ? 1u : 0u;
}

// Refines the cluster with the largest bound; false (cut unchanged) once the
// cut is final.
bool lc_cut_refine(SurfacePoint sp, Material m, FrameParams f, LC_INOUT(uint) heap_size,
                   LC_INOUT(vec3) fixed_sum, LC_INOUT(vec3) heap_sum, LC_INOUT(ShadeStats) stats, uint stream,
                   uint fresh_draws) {
    if (heap_size == 0u) return false;
    HeapEntry top = LC_HEAP_LOAD(0u);
    float estimate = lc_luminance(fixed_sum + heap_sum);
    if (!(top.error > f.relative_error * estimate)) return false;
    if (stats.cut_size >= f.max_cut) {
        stats.hit_max_cut = 1u;
        return false;
    }
    LightNode node = LC_LIGHT_NODE(lc_entry_node(top));
    bool visible = lc_entry_visible(top);
    vec3 unit = lc_entry_unit(sp, top, node, f.min_distance2);
    heap_sum -= unit * lc_node_intensity(node);
    bool right_shares = (node.flags & kNodeRepFromRight) != 0u;
    LightNode left = LC_LIGHT_NODE(node.left);
    LightNode right = LC_LIGHT_NODE(node.left + 1u);
#ifdef LC_CHILD_ERRORS
    // The includer's evaluation of both bounds at once (the CPU's SSE one).
    vec2 errors = LC_CHILD_ERRORS(sp, m, left, right, f.min_distance2);
#else
    vec2 errors = vec2(lc_cluster_error(sp, m, left, f.min_distance2), lc_cluster_error(sp, m, right, f.min_distance2));
#endif
    // One child keeps the parent's representative; the other has a new one,
    // whose contribution (one shadow ray) is found here, once, where that
    // child enters the cut (lc_cluster_needs_unit: a leaf, or a bound above
    // zero). One call for whichever child it is, not one per child: lanes
    // of a SIMD group refining different nodes then trace their rays
    // together instead of in two rounds.
    uint fresh_rep = right_shares ? left.rep_light : right.rep_light;
    bool fresh_leaf = ((right_shares ? left.flags : right.flags) & kNodeLeaf) != 0u;
    float fresh_error = right_shares ? errors.x : errors.y;
    vec3 fresh_unit = vec3(0.0f);
    bool fresh_visible = false;
    if (fresh_leaf || fresh_error > 0.0f)
        fresh_unit = lc_rep_unit(sp, fresh_rep, f.min_distance2, fresh_visible, stats);
    HeapEntry a, b;
    vec3 estimate_a, estimate_b;
    bool has_a = lc_cluster_entry(node.left, left, errors.x, right_shares ? fresh_unit : unit,
                                  right_shares ? fresh_visible : visible, a, estimate_a, fixed_sum);
    bool has_b = lc_cluster_entry(node.left + 1u, right, errors.y, right_shares ? unit : fresh_unit,
                                  right_shares ? visible : fresh_visible, b, estimate_b, fixed_sum);
    // The parent leaves the heap and its children enter it: the larger
    // child takes the parent's slot and sinks from there, one pass where a
    // pop and a push take two; the smaller one is pushed (and may freeze
    // the heap's smallest entry).
    if (has_a && has_b && b.error > a.error) {
        HeapEntry swap_entry = a;
        vec3 swap_estimate = estimate_a;
        a = b;
        estimate_a = estimate_b;
        b = swap_entry;
        estimate_b = swap_estimate;
    } else if (has_b && !has_a) {
        a = b;
        estimate_a = estimate_b;
        has_a = true;
        has_b = false;
    }
    // A pop where neither child enters (the last entry sinks from the top
    // instead), in the same sift: one loop on llvmpipe, not one a case.
    if (has_a) {
        heap_sum += estimate_a;
    } else {
        heap_size -= 1u;
        a = LC_HEAP_LOAD(heap_size);
    }
    if (heap_size > 0u) lc_heap_replace_top(heap_size, a);
    if (has_b)
        lc_heap_push(sp, f.min_distance2, heap_size, b, estimate_b, fixed_sum, heap_sum, stats, stream, fresh_draws);
    stats.cut_size += 1u;
    if (lc_node_type(node) == kLightVpl) stats.cut_indirect += 1u;
    return true;
}

// The running heap_sum drifts by the additions and subtractions of the
// refinements; the result is summed afresh from the final cut.
vec3 lc_cut_result(SurfacePoint sp, float min_distance2, uint heap_size, vec3 fixed_sum) {
    vec3 result = fixed_sum;
    for (uint i = 0u; i < heap_size; ++i) result += lc_entry_estimate(sp, LC_HEAP_LOAD(i), min_distance2);
    return result;
}

// Runs the cut selection from the roots to the final cut.
void lc_select_cut(SurfacePoint sp, Material m, FrameParams f, LC_OUT(uint) heap_size, LC_OUT(vec3) fixed_sum,
                   LC_INOUT(ShadeStats) stats, uint stream, uint fresh_draws) {
    vec3 heap_sum = vec3(0.0f);
    lc_cut_start(sp, m, f, heap_size, fixed_sum, heap_sum, stats, stream, fresh_draws);
    while (lc_cut_refine(sp, m, f, heap_size, fixed_sum, heap_sum, stats, stream, fresh_draws)) {
    }
}

vec3 lc_shade_lightcuts(SurfacePoint sp, FrameParams f, LC_INOUT(ShadeStats) stats) {
    Material m = sp.mat;
    uint heap_size = 0u;
    vec3 fixed_sum = vec3(0.0f);
    lc_select_cut(sp, m, f, heap_size, fixed_sum, stats, 0u, 0u);
    return lc_cut_result(sp, f.min_distance2, heap_size, fixed_sum);
}

// Stochastic Lightcuts (Yuksel 2019): the cut is selected exactly as above,
// with the fixed representatives, so it depends on the shaded point only;
// then every cluster of the cut that is not a single light is shaded again
// with representatives drawn afresh from the sample's `stream`
// (lc_cluster_fresh_estimate, f.light_samples draws of one shadow ray
// each, averaged): the clusters left in the heap here, the clusters frozen
// out of a full heap as they freeze (lc_heap_push). Single lights are exact
// already. Each cluster's estimate is unbiased given the cut, so the pixel
// is, and the mean over samples converges to the exact image.
vec3 lc_shade_stochastic(SurfacePoint sp, FrameParams f, uint stream, LC_INOUT(ShadeStats) stats) {
    Material m = sp.mat;
    uint heap_size = 0u;
    vec3 result = vec3(0.0f);  // the cut's fixed_sum: single lights and frozen clusters
    lc_select_cut(sp, m, f, heap_size, result, stats, stream, f.light_samples);
    for (uint i = 0u; i < heap_size; ++i)
        result += lc_cluster_fresh_estimate(sp, lc_entry_node(LC_HEAP_LOAD(i)), f.min_distance2, stream,
                                            f.light_samples, stats);
    return result;
}
