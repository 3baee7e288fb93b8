// Ray/triangle intersection and BVH traversal, shared by the CPU tracer and
// the Vulkan kernels (see glsl_compat.h for how it compiles as C++).
//
// The includer defines:
//   LC_BVH_NODE(i)   -> BvhNode
//   LC_TRIANGLE(i)   -> Triangle
//   LC_BVH4_WORD(i, k) (optional) -> uvec4, word k of Bvh4Node i: shadow
//                       rays then go through the 4-wide tree (lc_trace_any)
//   LC_ON_TRIP()     (optional) called at each trip round that tree's loop
//                       (the benchmarks count them)
// No include guard: each kernel context (a GLSL shader, a C++ kernel
// struct in host/cpu_kernel.h) includes it exactly once.

// Shadow rays stop this fraction of the distance short of the light, so a
// light mounted on a surface is not shadowed by that surface.
LC_KCONST float kShadowEndRelative = 1e-4f;
LC_KCONST float kRayInfinity = 1e30f;

vec3 lc_tri_v0(Triangle t) { return vec3(t.v0_x, t.v0_y, t.v0_z); }
vec3 lc_tri_v1(Triangle t) { return vec3(t.v1_x, t.v1_y, t.v1_z); }
vec3 lc_tri_v2(Triangle t) { return vec3(t.v2_x, t.v2_y, t.v2_z); }

// Watertight ray/triangle test (Woop, Benthin, Wald, JCGT 2013): rays through
// a shared edge or vertex hit at least one of the triangles, so nothing leaks
// between neighbours. In two parts: the ray's axis permutation and shear,
// made once per ray (lc_shear_ray), and the test of one triangle with them.
struct ShearedRay {
    int kx, ky, kz;  // the permuted axes: kz where |dir| is largest
    float sx, sy, sz;
};

// Inlined into the CPU's walks (host/wide_trace.h sets every ray up with
// it): called out of line it made brute force 7 to 11% slower.
LC_ALWAYS_INLINE ShearedRay lc_shear_ray(vec3 dir) {
    vec3 ad = abs(dir);
    ShearedRay r;
    r.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
    r.kx = r.kz == 2 ? 0 : r.kz + 1;
    r.ky = r.kx == 2 ? 0 : r.kx + 1;
    if (dir[r.kz] < 0.0f) {
        int tmp = r.kx;
        r.kx = r.ky;
        r.ky = tmp;
    }
    r.sz = 1.0f / dir[r.kz];
    r.sx = dir[r.kx] * r.sz;
    r.sy = dir[r.ky] * r.sz;
    return r;
}

// Returns t in (0, t_max), or -1 for a miss; b1 and b2 are the barycentric
// weights of v1 and v2.
float lc_intersect_sheared(vec3 org, LC_IN(ShearedRay) r, LC_IN(Triangle) tri, float t_max, LC_OUT(float) b1,
                           LC_OUT(float) b2) {
    b1 = 0.0f;
    b2 = 0.0f;
    vec3 a = lc_tri_v0(tri) - org;
    vec3 b = lc_tri_v1(tri) - org;
    vec3 c = lc_tri_v2(tri) - org;
    float ax = a[r.kx] - r.sx * a[r.kz];
    float ay = a[r.ky] - r.sy * a[r.kz];
    float bx = b[r.kx] - r.sx * b[r.kz];
    float by = b[r.ky] - r.sy * b[r.kz];
    float cx = c[r.kx] - r.sx * c[r.kz];
    float cy = c[r.ky] - r.sy * c[r.kz];

    // `precise` (LC_PRECISE): a shared edge's function in the two triangles beside it
    // must come out exactly negated (Woop et al.'s watertightness), which
    // a multiply-add fused in one and not the other breaks; the CPU build
    // fuses none (-ffp-contract=off), a GPU compiler may.
    LC_PRECISE float u = cx * by - cy * bx;
    LC_PRECISE float v = ax * cy - ay * cx;
    LC_PRECISE float w = bx * ay - by * ax;
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return -1.0f;
    float det = u + v + w;
    if (det == 0.0f) return -1.0f;

    float t_scaled = (u * a[r.kz] + v * b[r.kz] + w * c[r.kz]) * r.sz;
    float t = t_scaled / det;
    if (!(t > 0.0f && t < t_max)) return -1.0f;
    b1 = v / det;
    b2 = w / det;
    return t;
}

// The test of one ray against one triangle.
float lc_intersect_triangle(vec3 org, vec3 dir, LC_IN(Triangle) tri, float t_max, LC_OUT(float) b1,
                            LC_OUT(float) b2) {
    return lc_intersect_sheared(org, lc_shear_ray(dir), tri, t_max, b1, b2);
}

// The CPU's 4-wide traversal (host/wide_trace.h) runs this slab test and
// lc_intersect_sheared four lanes at a time: a change here must be made
// there too.
//
// Slab test. The far distance is widened by 2*gamma(3) (Ize, "Robust BVH Ray
// Traversal", JCGT 2013) so rounding never culls a box the ray touches.
bool lc_hit_box(LC_IN(BvhNode) node, vec3 org, vec3 inv_dir, float t_max, LC_OUT(float) t_entry) {
    vec3 t0 = (vec3(node.min_x, node.min_y, node.min_z) - org) * inv_dir;
    vec3 t1 = (vec3(node.max_x, node.max_y, node.max_z) - org) * inv_dir;
    vec3 tn = min(t0, t1);
    vec3 tf = max(t0, t1);
    float t_near = max(max(tn.x, tn.y), max(tn.z, 0.0f));
    float t_far = min(min(tf.x, tf.y), min(tf.z, t_max)) * 1.0000004f;
    t_entry = t_near;
    return t_near <= t_far;
}

vec3 lc_safe_inverse(vec3 d) {
    // A zero component would give 0 * inf = NaN in the slab test.
    LC_KCONST float tiny = 1e-30f;
    return vec3(1.0f / (abs(d.x) > tiny ? d.x : (d.x < 0.0f ? -tiny : tiny)),
                1.0f / (abs(d.y) > tiny ? d.y : (d.y < 0.0f ? -tiny : tiny)),
                1.0f / (abs(d.z) > tiny ? d.z : (d.z < 0.0f ? -tiny : tiny)));
}

// Closest hit along org + t*dir, t in (0, t_max). Returns the triangle index
// (in BVH order) or kInvalidIndex; t, b1, b2 describe the hit.
uint lc_trace_closest(vec3 org, vec3 dir, float t_max, LC_OUT(float) t_hit, LC_OUT(float) b1,
                      LC_OUT(float) b2) {
    vec3 inv_dir = lc_safe_inverse(dir);
    ShearedRay sheared = lc_shear_ray(dir);
    uint hit = kInvalidIndex;
    t_hit = t_max;
    b1 = 0.0f;
    b2 = 0.0f;
    uint stack[kBvhStackSize];
    uint sp = 0u;
    uint node_index = 0u;
    float t_entry;
    if (!lc_hit_box(LC_BVH_NODE(0u), org, inv_dir, t_hit, t_entry)) return hit;
    while (true) {
        BvhNode node = LC_BVH_NODE(node_index);
        if (node.tri_count > 0u) {
            for (uint i = node.first_or_left; i < node.first_or_left + node.tri_count; ++i) {
                float u, v;
                float t = lc_intersect_sheared(org, sheared, LC_TRIANGLE(i), t_hit, u, v);
                if (t > 0.0f) {
                    t_hit = t;
                    b1 = u;
                    b2 = v;
                    hit = i;
                }
            }
        } else {
            // Visit the nearer child first; push the other.
            uint left = node.first_or_left;
            float t_left, t_right;
            bool hit_left = lc_hit_box(LC_BVH_NODE(left), org, inv_dir, t_hit, t_left);
            bool hit_right = lc_hit_box(LC_BVH_NODE(left + 1u), org, inv_dir, t_hit, t_right);
            if (hit_left && hit_right) {
                uint near_child = t_left <= t_right ? left : left + 1u;
                uint far_child = t_left <= t_right ? left + 1u : left;
                stack[sp++] = far_child;
                node_index = near_child;
                continue;
            }
            if (hit_left || hit_right) {
                node_index = hit_left ? left : left + 1u;
                continue;
            }
        }
        // Pop, skipping nodes that now lie beyond the closest hit.
        bool found = false;
        while (sp > 0u && !found) {
            node_index = stack[--sp];
            found = lc_hit_box(LC_BVH_NODE(node_index), org, inv_dir, t_hit, t_entry);
        }
        if (!found) break;
    }
    return hit;
}

#ifdef LC_BVH4_WORD
// A Bvh4Node unpacked: the four children's boxes as vectors, slot by slot,
// and their stack entries.
struct Bvh4Boxes {
    vec4 lo_x, lo_y, lo_z;
    vec4 hi_x, hi_y, hi_z;
    uvec4 entry;
};

// The four planes in the bytes of w, as floats (exact: at most 255).
vec4 lc_bvh4_planes(uint w) { return vec4((uvec4(w) >> uvec4(0u, 8u, 16u, 24u)) & uvec4(255u)); }

Bvh4Boxes lc_bvh4_node(uint i) {
    uvec4 w0 = LC_BVH4_WORD(i, 0u);
    uvec4 w1 = LC_BVH4_WORD(i, 1u);
    uvec4 w2 = LC_BVH4_WORD(i, 2u);
    float origin_x = uintBitsToFloat(w0.x), origin_y = uintBitsToFloat(w0.y), origin_z = uintBitsToFloat(w0.z);
    float scale_x = uintBitsToFloat(w0.w), scale_y = uintBitsToFloat(w1.x), scale_z = uintBitsToFloat(w1.y);
    Bvh4Boxes n;
    // plane * scale is exact (a power of two times at most 255), so a fused
    // multiply-add gives the same sums as bvh4_nodes, which rounded them.
    n.lo_x = origin_x + lc_bvh4_planes(w1.z) * scale_x;
    n.lo_y = origin_y + lc_bvh4_planes(w1.w) * scale_y;
    n.lo_z = origin_z + lc_bvh4_planes(w2.x) * scale_z;
    n.hi_x = origin_x + lc_bvh4_planes(w2.y) * scale_x;
    n.hi_y = origin_y + lc_bvh4_planes(w2.z) * scale_y;
    n.hi_z = origin_z + lc_bvh4_planes(w2.w) * scale_z;
    n.entry = LC_BVH4_WORD(i, 3u);
    return n;
}

// lc_trace_any's stack holds groups: the children of a node that the ray
// enters and that are still to visit, as the node's index times 16 plus a
// bit for each of those child slots (bvh_build keeps the 4-wide nodes fewer
// than 2^28). A node's children that are not visited at once go on the
// stack as one group, so it holds at most one group per level, and no wide
// node is deeper than the binary tree's deepest.
LC_KCONST uint kBvh4StackSize = kBvhStackSize;
LC_KCONST uint kBvh4GroupSlots = 15u;

// The entry of the slot whose bit (1, 2, 4 or 8) `bit` is.
uint lc_bvh4_slot(uvec4 entries, uint bit) {
    return bit == 1u ? entries.x : (bit == 2u ? entries.y : (bit == 4u ? entries.z : entries.w));
}

// Takes from a group's children still to visit (`left`: a bit for each
// slot of the node's `entries`) the first inner child as the next node
// where none is set, and the first leaf as the pending leaf where none is
// pending. Returns the children left. In bit arithmetic, not a loop over
// the slots: it runs twice a trip, and llvmpipe runs each operation for
// all the lanes of a SIMD group (the loop's took 6% more of the Lightcuts
// kernel's time on lavapipe: docs/results/lavapipe.md, §25).
uint lc_bvh4_take(uvec4 entries, uint left, LC_INOUT(uint) node, LC_INOUT(uint) leaf) {
    // kBvh4LeafEntry is an entry's top bit.
    uint leaves = left & ((entries.x >> 31u) | (entries.y >> 31u) << 1u | (entries.z >> 31u) << 2u |
                          (entries.w >> 31u) << 3u);
    uint inner = left & ~leaves;
    uint first_inner = node == kInvalidIndex ? inner & (0u - inner) : 0u;  // the lowest bit, or none
    uint first_leaf = leaf == kInvalidIndex ? leaves & (0u - leaves) : 0u;
    node = first_inner != 0u ? lc_bvh4_slot(entries, first_inner) : node;
    leaf = first_leaf != 0u ? lc_bvh4_slot(entries, first_leaf) : leaf;
    return left & ~(first_inner | first_leaf);
}
#endif

// Any hit with t in (0, t_max): true if something blocks the segment.
//
// Through the 4-wide tree where the includer provides it (LC_BVH4_WORD,
// the Vulkan kernels). Each trip round the loop tests one triangle of the
// pending leaf and one node's four boxes (lc_hit_box's operations slot by
// slot); of the children the ray enters, the first inner one is the next
// node, the first leaf the next pending leaf if none is, and the rest go
// on the stack. On SIMD hardware a trip costs the group of lanes its
// node test and its triangle test whichever of them each lane needs:
// llvmpipe runs both sides of every branch under a lane mask, and GPUs
// run a divergent branch's sides one after the other. Testing a whole
// leaf per trip (four triangle tests, or a loop) or visiting leaves in
// trips of their own costs more on lavapipe; this loop takes 6.3 trips per
// lightcuts ray on the shipped room (6.1 before the boxes were quantized),
// the binary tree 12.0 (docs/results/lavapipe.md, §10 and §11;
// bench/embree_rays counts them).
//
// Otherwise through the binary tree:
// both children's boxes are tested at their parent, and only those the ray
// enters are visited: the first of them next, the other from the stack
// (which then holds at most one node per level). The GPU's loop thus runs
// once per node the ray enters rather than once per node tested, and the
// stack, an array each invocation indexes its own way (a loop over the
// lanes on llvmpipe), is touched only where the ray enters both children.
// Each loop iteration also counts against llvmpipe's limit on an
// invocation's loop iterations (kernel.glsl, lc_loops_were_cut_short), and
// so does each of a leaf's triangles unless the loop over them is
// unrolled: it runs over the kBvhMaxLeafTriangles slots of a leaf, a
// constant the compiler unrolls.
bool lc_trace_any(vec3 org, vec3 dir, float t_max) {
    vec3 inv_dir = lc_safe_inverse(dir);
    ShearedRay sheared = lc_shear_ray(dir);
#ifdef LC_BVH4_WORD
    uint stack[kBvh4StackSize + 1u]; // + 1: stack[sp] is written where nothing is pushed
    stack[0] = 0u;                    // so that every slot read holds a node's index
    uint sp = 0u;
    uint node = 0u;            // the node to test this trip, or kInvalidIndex
    uint leaf = kInvalidIndex; // the leaf to test this trip (a node entry), or kInvalidIndex
    while (true) {
#ifdef LC_ON_TRIP
        LC_ON_TRIP();
#endif
        if (leaf != kInvalidIndex) {
            float u, v;
            if (lc_intersect_sheared(org, sheared, LC_TRIANGLE(leaf & (kBvh4MaxTriangles - 1u)), t_max, u, v) > 0.0f)
                return true;
            // The leaf's next triangle: one fewer left, the first one on.
            leaf = (leaf & (3u << 29u)) != 0u ? leaf - (1u << 29u) + 1u : kInvalidIndex;
        }
        // This trip's group: the children of `node` that the ray enters.
        uint group = 0u;
        uvec4 entries = uvec4(kInvalidIndex);
        if (node != kInvalidIndex) {
            Bvh4Boxes n = lc_bvh4_node(node);
            vec4 t0x = (n.lo_x - org.x) * inv_dir.x;
            vec4 t1x = (n.hi_x - org.x) * inv_dir.x;
            vec4 t0y = (n.lo_y - org.y) * inv_dir.y;
            vec4 t1y = (n.hi_y - org.y) * inv_dir.y;
            vec4 t0z = (n.lo_z - org.z) * inv_dir.z;
            vec4 t1z = (n.hi_z - org.z) * inv_dir.z;
            vec4 t_near = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4(0.0f)));
            vec4 t_far = min(min(max(t0x, t1x), max(t0y, t1y)), min(max(t0z, t1z), vec4(t_max))) * 1.0000004f;
            uint enters = 0u;
            for (uint s = 0u; s < 4u; ++s)
                enters |= n.entry[s] != kInvalidIndex && t_near[s] <= t_far[s] ? 1u << s : 0u;
            group = node << 4u | enters;
            entries = n.entry;
            node = kInvalidIndex;
        }
        uint left = lc_bvh4_take(entries, group & kBvh4GroupSlots, node, leaf);
        // With no node yet and nothing left of this trip's group, the group
        // on top of the stack gives the next node or leaf (a leaf there
        // waits while one is pending); otherwise what is left of this trip's
        // group goes on the stack.
        // One store a trip, made whatever the case, and one read of the top
        // whatever the case (the entries of the stack's first slot where it
        // is empty, unused then): llvmpipe turns each access to the stack,
        // an array each lane indexes its own way, into a branch per lane,
        // and pushing each child (up to four stores a trip, each under its
        // own test) took 23 to 40% of the Lightcuts kernel's profile
        // samples on a Zen 4 host (docs/results/lavapipe.md, section 15).
        uint top = stack[max(sp, 1u) - 1u];
        bool from_top = node == kInvalidIndex && left == 0u && sp > 0u;
        uvec4 top_entries = LC_BVH4_WORD(top >> 4u, 3u);
        uint top_left = lc_bvh4_take(top_entries, from_top ? top & kBvh4GroupSlots : 0u, node, leaf);
        stack[from_top ? sp - 1u : sp] = from_top ? (top & ~kBvh4GroupSlots) | top_left : (group & ~kBvh4GroupSlots) | left;
        sp = from_top ? (top_left != 0u ? sp : sp - 1u) : (left != 0u ? sp + 1u : sp);
        if (node == kInvalidIndex && leaf == kInvalidIndex) break;
    }
    return false;
#else
    uint stack[kBvhStackSize];
    uint sp = 0u;
    uint node_index = 0u;
    float t_entry;
    if (!lc_hit_box(LC_BVH_NODE(0u), org, inv_dir, t_max, t_entry)) return false;
    while (true) {
        BvhNode node = LC_BVH_NODE(node_index);
        if (node.tri_count > 0u) {
            for (uint k = 0u; k < kBvhMaxLeafTriangles; ++k) {
                if (k >= node.tri_count) break;
                float u, v;
                if (lc_intersect_sheared(org, sheared, LC_TRIANGLE(node.first_or_left + k), t_max, u, v) > 0.0f)
                    return true;
            }
        } else {
            uint left = node.first_or_left;
            float t_left, t_right;
            bool hit_left = lc_hit_box(LC_BVH_NODE(left), org, inv_dir, t_max, t_left);
            bool hit_right = lc_hit_box(LC_BVH_NODE(left + 1u), org, inv_dir, t_max, t_right);
            if (hit_left) {
                if (hit_right) stack[sp++] = left + 1u;
                node_index = left;
                continue;
            }
            if (hit_right) {
                node_index = left + 1u;
                continue;
            }
        }
        if (sp == 0u) break;
        node_index = stack[--sp];
    }
    return false;
#endif
}

// Moves a hit point off its triangle along the geometric normal ng (turned
// to the side the ray came from) by 2^-20 of the triangle's largest
// coordinate (8 to 16 of its ulps). The barycentric point is off the plane by
// a few ulps of that coordinate, and a shadow ray's triangle test errs by as
// much, so this clears the surface at any scale and any distance from the
// origin, while staying far below any wall thickness a scene would model.
// (Offsets of a fixed number of ulps of p, as in Waechter and Binder, Ray
// Tracing Gems 2019, assume p = org + t * dir and unit-sized scenes: they
// moved points by 2 units at 1e5 and by 7% of a room scaled to 1e-4;
// tests/stress, Transformed.*.)
LC_KCONST float kHitOffsetRelative = 1.0f / 1048576.0f;

vec3 lc_offset_hit_point(vec3 p, vec3 ng, LC_IN(Triangle) tri) {
    vec3 m = max(max(abs(lc_tri_v0(tri)), abs(lc_tri_v1(tri))), abs(lc_tri_v2(tri)));
    return p + ng * (kHitOffsetRelative * max(max(m.x, m.y), m.z));
}
