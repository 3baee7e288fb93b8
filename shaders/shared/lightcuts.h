// The Lightcuts cut selection (Walter et al. 2005, section 4). Shared by the
// CPU reference and the Vulkan kernels; needs trace.h and shading.h first.
//
// The includer defines:
//   LC_LIGHT_NODE(i)        -> LightNode
//   LC_HEAP_LOAD(i)         -> CutEntry        (heap slot i of this point)
//   LC_HEAP_STORE(i, e)     stores CutEntry e in slot i
//   LC_PREFETCH_LIGHT_NODES(i) (optional) starts loading nodes i and i + 1
// On the GPU the first slots live in workgroup shared memory and the rest
// spill to a global buffer; on the CPU they are a per-thread array.
// No include guard: each kernel context (a GLSL shader, a C++ kernel
// struct in host/cpu_kernel.h) includes it exactly once.

// Unscaled contribution of a light (material * geometry * visibility):
// the representative's estimate is this times the cluster's RGB intensity.
vec3 lc_rep_unit(LC_IN(SurfacePoint) sp, uint light_index, float min_distance2,
                 LC_INOUT(ShadeStats) stats) {
    return lc_light_unit_shadowed(sp, LC_LIGHT(light_index), min_distance2, stats);
}

void lc_heap_push(LC_INOUT(uint) size, CutEntry e) {
    uint i = size;
    size += 1u;
    while (i > 0u) {
        uint parent = (i - 1u) / 2u;
        CutEntry p = LC_HEAP_LOAD(parent);
        if (p.error >= e.error) break;
        LC_HEAP_STORE(i, p);
        i = parent;
    }
    LC_HEAP_STORE(i, e);
}

// Removes the largest entry (slot 0).
void lc_heap_pop(LC_INOUT(uint) size) {
    size -= 1u;
    if (size == 0u) return;
    CutEntry last = LC_HEAP_LOAD(size);
    uint i = 0u;
    while (true) {
        uint child = 2u * i + 1u;
        if (child >= size) break;
        CutEntry c = LC_HEAP_LOAD(child);
        if (child + 1u < size) {
            CutEntry r = LC_HEAP_LOAD(child + 1u);
            if (r.error > c.error) {
                child += 1u;
                c = r;
            }
        }
        if (c.error <= last.error) break;
        LC_HEAP_STORE(i, c);
        i = child;
    }
    LC_HEAP_STORE(i, last);
}

// Adds one cluster to the cut: its bound decides whether it needs a ray at
// all; leaves are final (exact, zero error) and go to leaf_sum, refinable
// interior nodes go to the heap. `inherited` is true when the caller already
// knows the representative's unit contribution (shared with the parent).
void lc_add_cluster(LC_IN(SurfacePoint) sp, LC_IN(Material) m, uint node_index, bool inherited,
                    vec3 inherited_unit, float min_distance2, LC_INOUT(uint) heap_size, LC_INOUT(vec3) leaf_sum,
                    LC_INOUT(vec3) heap_sum, LC_INOUT(ShadeStats) stats) {
    LightNode node = LC_LIGHT_NODE(node_index);
    vec3 intensity = lc_node_intensity(node);
    bool leaf = (node.flags & kNodeLeaf) != 0u;
    float error = 0.0f;
    if (!leaf) {
        vec3 bound = lc_cluster_bound(sp, m, node, min_distance2);
        error = lc_luminance(bound * intensity);
        // A cluster whose bound is zero contributes exactly zero: no ray.
        if (!(error > 0.0f)) return;
    }
    vec3 unit = inherited ? inherited_unit : lc_rep_unit(sp, node.rep_light, min_distance2, stats);
    if (leaf) {
        leaf_sum += unit * intensity;
        return;
    }
    CutEntry e;
    e.node = node_index;
    e.error = error;
    e.unit_r = unit.x;
    e.unit_g = unit.y;
    e.unit_b = unit.z;
#ifdef LC_PREFETCH_LIGHT_NODES
    // The children are read when this entry is refined, if ever: start
    // loading them now (the CPU; a no-op where the includer has no prefetch).
    LC_PREFETCH_LIGHT_NODES(node.left);
#endif
    lc_heap_push(heap_size, e);
    heap_sum += unit * intensity;
}

// Walter 2005, section 4: start from the roots, repeatedly replace the
// cluster with the largest error bound by its children while that bound
// exceeds relative_error times the current estimate (both as luminance) and
// the cut is smaller than max_cut.
//
// In three steps (start, one refinement, result) so that the GPU can spread
// a long refinement over several dispatches; lc_shade_lightcuts runs them
// back to back.
void lc_cut_start(SurfacePoint sp, Material m, FrameParams f, LC_OUT(uint) heap_size,
                  LC_OUT(vec3) leaf_sum, LC_OUT(vec3) heap_sum, LC_INOUT(ShadeStats) stats) {
    heap_size = 0u;
    leaf_sum = vec3(0.0f);
    heap_sum = vec3(0.0f);
    stats.cut_size = 0u;
    uint root_count = 0u;
    for (uint type = 0u; type < kLightTypeCount; ++type) {
        if (f.roots[type] == kInvalidIndex) continue;
        lc_add_cluster(sp, m, f.roots[type], false, vec3(0.0f), f.min_distance2, heap_size,
                       leaf_sum, heap_sum, stats);
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
                   LC_INOUT(vec3) leaf_sum, LC_INOUT(vec3) heap_sum, LC_INOUT(ShadeStats) stats) {
    if (heap_size == 0u) return false;
    CutEntry top = LC_HEAP_LOAD(0u);
    float estimate = lc_luminance(leaf_sum + heap_sum);
    if (!(top.error > f.relative_error * estimate)) return false;
    if (stats.cut_size >= f.max_cut) {
        stats.hit_max_cut = 1u;
        return false;
    }
    lc_heap_pop(heap_size);
    LightNode node = LC_LIGHT_NODE(top.node);
    vec3 unit = vec3(top.unit_r, top.unit_g, top.unit_b);
    heap_sum -= unit * lc_node_intensity(node);
    bool right_shares = (node.flags & kNodeRepFromRight) != 0u;
    lc_add_cluster(sp, m, node.left, !right_shares, unit, f.min_distance2, heap_size, leaf_sum,
                   heap_sum, stats);
    lc_add_cluster(sp, m, node.left + 1u, right_shares, unit, f.min_distance2, heap_size,
                   leaf_sum, heap_sum, stats);
    stats.cut_size += 1u;
    if (lc_node_type(node) == kLightVpl) stats.cut_indirect += 1u;
    return true;
}

// The running heap_sum drifts by the additions and subtractions of the
// refinements; the result is summed afresh from the final cut.
vec3 lc_cut_result(uint heap_size, vec3 leaf_sum) {
    vec3 result = leaf_sum;
    for (uint i = 0u; i < heap_size; ++i) {
        CutEntry e = LC_HEAP_LOAD(i);
        result += vec3(e.unit_r, e.unit_g, e.unit_b) * lc_node_intensity(LC_LIGHT_NODE(e.node));
    }
    return result;
}

// Runs the cut selection from the roots to the final cut.
void lc_select_cut(SurfacePoint sp, Material m, FrameParams f, LC_OUT(uint) heap_size, LC_OUT(vec3) leaf_sum,
                   LC_INOUT(ShadeStats) stats) {
    vec3 heap_sum = vec3(0.0f);
    lc_cut_start(sp, m, f, heap_size, leaf_sum, heap_sum, stats);
    while (lc_cut_refine(sp, m, f, heap_size, leaf_sum, heap_sum, stats)) {
    }
}

vec3 lc_shade_lightcuts(SurfacePoint sp, FrameParams f, LC_INOUT(ShadeStats) stats) {
    Material m = sp.mat;
    uint heap_size = 0u;
    vec3 leaf_sum = vec3(0.0f);
    lc_select_cut(sp, m, f, heap_size, leaf_sum, stats);
    return lc_cut_result(heap_size, leaf_sum);
}

// Stochastic Lightcuts (Yuksel 2019): the cut is selected exactly as above,
// with the fixed representatives, so it depends on the shaded point only;
// then every cluster of the cut that is not a single light is shaded again
// with a representative drawn afresh from the sample's `stream`
// (lc_shade_cluster_stochastic, f.light_samples draws of one shadow ray
// each, averaged). Single lights are exact already. Each cluster's estimate
// is unbiased given the cut, so the pixel is, and the mean over samples
// converges to the exact image.
vec3 lc_shade_stochastic(SurfacePoint sp, FrameParams f, uint stream, LC_INOUT(ShadeStats) stats) {
    Material m = sp.mat;
    uint heap_size = 0u;
    vec3 result = vec3(0.0f);
    lc_select_cut(sp, m, f, heap_size, result, stats);
    float weight = 1.0f / float(f.light_samples);
    for (uint i = 0u; i < heap_size; ++i)
        for (uint d = 0u; d < f.light_samples; ++d)
            result += lc_shade_cluster_stochastic(sp, LC_HEAP_LOAD(i).node, f.min_distance2, stream, d, stats) *
                      weight;
    return result;
}
