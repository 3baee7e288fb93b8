// The stochastic methods: light sampling through the light tree
// (--method sampled) and the fresh representatives of Stochastic Lightcuts
// (--method stochastic). Shared by the CPU reference and the Vulkan
// kernels; needs trace.h and shading.h first. The includer defines
// LC_LIGHT_NODE(i) -> LightNode as for lc_shared/lightcuts.h.
//
// Every random number is a hash of (seed, pixel, camera sample, stream), so
// a render is deterministic for its seed and the same on both devices, and
// no two light samples or clusters of a pixel share their numbers.
// No include guard: each kernel context includes it exactly once.

// The random stream of camera sample `s` of pixel (x, y); a different
// stream from the pixel jitter of lc_pixel_sample.
uint lc_sample_stream(uint seed, uint x, uint y, uint s) {
    return lc_hash(lc_hash(seed ^ 0x5bd1e995u) ^ lc_pixel_key(x, y, s));
}

// Sub-stream `k` of a stream: light sample k, or the cluster with node k.
uint lc_substream(uint stream, uint k) { return lc_hash(stream ^ lc_hash(k + 0x9e3779b9u)); }

// How much a cluster is worth sampling at a shaded point (Conty Estevez and
// Kulla 2018; pbrt-v4's LightBounds::Importance): its intensity (luminance)
// times a bound of the cosine at the point and the emission bound of the
// error bound (lc_emission_bound), over the squared distance to the box
// centre, kept from falling below the squared radius of the box's bounding
// sphere (or d_min^2) so that a point inside a cluster does not make it
// infinitely important. The material is left out, as in pbrt-v4: for
// Lambert it is the same factor for every cluster, and the GGX lobe's bound
// (lc_ggx_bound) cost more than it saved (docs/lightcuts.md). Zero only
// where the cosine or the emission bound is zero, i.e. where no light of
// the cluster can contribute: tree sampling then never misses a light that
// can, which keeps it unbiased.
float lc_cluster_importance(LC_IN(SurfacePoint) sp, LC_IN(LightNode) node, float min_distance2) {
    vec3 lo = vec3(node.min_x, node.min_y, node.min_z);
    vec3 hi = vec3(node.max_x, node.max_y, node.max_z);
    bool positional = lc_node_type(node) != kLightDirectional;
    if (positional) {
        lo -= sp.p;
        hi -= sp.p;
    }
    vec3 c = 0.5f * (lo + hi);
    vec3 half_diagonal = 0.5f * (hi - lo);
    float d2 = dot(c, c);
    float r2 = dot(half_diagonal, half_diagonal);
    // Cosine bound over the box's bounding sphere (pbrt-v4's
    // LightBounds::Importance): cos(max(0, theta - theta_b)), theta the angle
    // between n and the way to the centre, theta_b the half-angle the sphere
    // subtends; 1 where the point is inside the sphere.
    float cos_bound = 1.0f;
    if (d2 > r2) {
        float inv_d = inversesqrt(d2);
        float cos_t = dot(sp.n, c) * inv_d;
        float sin_b2 = r2 / d2;
        float cos_b = sqrt(max(1.0f - sin_b2, 0.0f));
        if (cos_t < cos_b) {
            float sin_t = sqrt(max(1.0f - cos_t * cos_t, 0.0f));
            // Plus the cosine's rounding slack, so that a light whose
            // exact cosine rounds above zero is never given weight zero.
            cos_bound = cos_t * cos_b + sin_t * sqrt(sin_b2) + kCosineAbsSlack;
        }
    }
    if (!(cos_bound > 0.0f)) return 0.0f;
    float emission = (positional && kEnableOriented) ? lc_emission_bound(node, sp.p) : 1.0f;
    if (!(emission > 0.0f)) return 0.0f;
    float importance = lc_luminance(lc_node_intensity(node)) * min(cos_bound * kBoundSlack, 1.0f) * emission;
    if (positional) importance /= max(max(d2, r2), lc_falloff_clamp2(min_distance2, lc_node_type(node)));
    return importance;
}

// What tree descent weighs a node by: lc_cluster_importance for
// kLightPickTree, the luminance of the cluster's intensity for
// kLightPickPower (which makes the descent pick each light in proportion to
// its power, with no table beyond the tree).
float lc_pick_weight(LC_IN(SurfacePoint) sp, uint node_index, uint pick, float min_distance2) {
    LightNode node = LC_LIGHT_NODE(node_index);
    if (pick == kLightPickPower) return lc_luminance(lc_node_intensity(node));
    return lc_cluster_importance(sp, node, min_distance2);
}

// Every draw below takes the top 24 bits of a hash, an integer k in
// [0, 2^24), and chooses between two weights a and b by k < n, where n,
// lc_branch_steps, is a's share of the 2^24 values, rounded, but at least
// 1 where a > 0 and at most 2^24 - 1 where b > 0. The probability recorded
// for the choice is the share taken, n / 2^24 or (2^24 - n) / 2^24, exactly
// the frequency of the choice, and no side with weight is left without
// one. (A float probability against a 24-bit number was neither: a side
// with less than 2^-24 of the weight was drawn as often as one with 2^-24
// but weighed as if rarer, and one with less than about 3e-8 never, so a
// dim light beside a bright one it lit the shadow of was missed.)
LC_KCONST uint kBranchSteps = 16777216u;  // 2^24
LC_KCONST float kBranchStep = 1.0f / 16777216.0f;

uint lc_branch_steps(float a, float b) {
    if (!(a > 0.0f)) return 0u;
    if (!(b > 0.0f)) return kBranchSteps;
    // Weights far from 1 are scaled by 2^-64 or 2^64 first (exactly, a
    // power of two): a + b must not overflow (two lights of 1.7e38: the
    // share came out 0, and sampled lightcuts 9% dark), and Vulkan's
    // division is accurate only for divisors from 2^-126 to 2^126. An
    // infinite weight takes all but the least share.
    float larger = max(a, b);
    if (larger > 1.26765060e30f) {  // 2^100
        a *= 5.42101086e-20f;       // 2^-64
        b *= 5.42101086e-20f;
    } else if (larger < 7.88860905e-31f) {  // 2^-100
        a *= 1.84467441e19f;                // 2^64
        b *= 1.84467441e19f;
    }
    bool a_inf = a > 3.40282347e38f, b_inf = b > 3.40282347e38f;
    float share = a_inf ? (b_inf ? 0.5f : 1.0f) : (b_inf ? 0.0f : a / (a + b));
    uint n = uint(share * float(kBranchSteps) + 0.5f);
    return min(max(n, 1u), kBranchSteps - 1u);
}

// Whether the 24-bit draw of hash `h` takes the side given `n` steps, and
// that side's probability multiplied into `pdf`.
bool lc_branch(uint h, uint n, LC_INOUT(float) pdf) {
    bool taken = (h >> 8u) < n;
    pdf *= float(taken ? n : kBranchSteps - n) * kBranchStep;
    return taken;
}

// The steps of the left of the two children `left` and `left + 1`, in
// proportion to their weights. Where neither child has any weight (the
// parent's bound was not zero, but both tighter ones are: no light below
// can contribute) it goes by power instead: whatever light it reaches
// contributes zero without a shadow ray, and the probabilities of all
// lights still sum to one.
uint lc_left_steps(LC_IN(SurfacePoint) sp, uint left, uint pick, float min_distance2) {
    float wl = lc_pick_weight(sp, left, pick, min_distance2);
    float wr = lc_pick_weight(sp, left + 1u, pick, min_distance2);
    if (!(wl + wr > 0.0f) && pick != kLightPickPower) {
        wl = lc_pick_weight(sp, left, kLightPickPower, min_distance2);
        wr = lc_pick_weight(sp, left + 1u, kLightPickPower, min_distance2);
    }
    return wl + wr > 0.0f ? lc_branch_steps(wl, wr) : kBranchSteps / 2u;
}

// Probability that descent goes to the left child (for tests).
float lc_left_probability(LC_IN(SurfacePoint) sp, uint left, uint pick, float min_distance2) {
    return float(lc_left_steps(sp, left, pick, min_distance2)) * kBranchStep;
}

// The light types are drawn one after another: type t, if it has weight,
// against the weight of the types after it (lc_branch_steps), each with a
// fresh hash. The roots' weights at a point, and the weight of the types
// after each.
struct RootWeights {
    float weight[kLightTypeCount];
    float after[kLightTypeCount];
};

// The weights are the roots' over 8 (exactly, a power of two), so that the
// sums of five stay finite (three of 2e38 made `after` infinite, and the
// first type was drawn with probability 6e-8 instead of 1/3).
RootWeights lc_root_weights(LC_IN(SurfacePoint) sp, LC_IN(FrameParams) f, uint pick) {
    RootWeights r;
    for (uint t = 0u; t < kLightTypeCount; ++t)
        r.weight[t] =
            f.roots[t] == kInvalidIndex ? 0.0f : 0.125f * lc_pick_weight(sp, f.roots[t], pick, f.min_distance2);
    float rest = 0.0f;
    for (uint i = 0u; i < kLightTypeCount; ++i) {
        uint t = kLightTypeCount - 1u - i;
        r.after[t] = rest;
        rest += r.weight[t];
    }
    return r;
}

// Probability of picking the tree of light type `type` (its root); 0 when
// no tree has any weight (for tests).
float lc_root_probability(LC_IN(SurfacePoint) sp, LC_IN(FrameParams) f, uint type, uint pick) {
    RootWeights r = lc_root_weights(sp, f, pick);
    float p = 1.0f;
    for (uint t = 0u; t < kLightTypeCount; ++t) {
        if (!(r.weight[t] > 0.0f)) {
            if (t == type) return 0.0f;
            continue;
        }
        uint n = lc_branch_steps(r.weight[t], r.after[t]);
        if (t == type) return p * float(n) * kBranchStep;
        p *= float(kBranchSteps - n) * kBranchStep;
    }
    return 0.0f;
}

// Descends from `node_index` to a leaf, choosing each child with
// lc_left_steps and one fresh random number per level of `stream`.
// Returns the leaf's light and multiplies `pdf` by the branch probabilities
// taken. (Written as a loop with its test in the head: with a `return`
// inside `while (true)` instead, lavapipe returned light 0 from the copy of
// this function inlined into lightcuts.comp, though the pdf was right.)
uint lc_descend(LC_IN(SurfacePoint) sp, uint node_index, uint pick, float min_distance2, uint stream,
                LC_INOUT(float) pdf) {
    uint h = stream;
    LightNode node = LC_LIGHT_NODE(node_index);
    while ((node.flags & kNodeLeaf) == 0u) {
        uint n = lc_left_steps(sp, node.left, pick, min_distance2);
        h = lc_hash(h);
        node_index = lc_branch(h, n, pdf) ? node.left : node.left + 1u;
        node = LC_LIGHT_NODE(node_index);
    }
    return node.rep_light;
}

// Light `h mod n` for a hash h, every light with probability exactly 1/n:
// h is hashed again while it falls in the last 2^32 mod n values, which
// would give the first lights one chance more (at most 8 times; the chance
// of a ninth is below (n / 2^32)^8). (The light of a 24-bit float u, u * n,
// drew some of 10^7 lights half as often as others, and at 2 * 10^7 some
// never.)
uint lc_uniform_light(uint h, uint n) {
    uint extra = (0u - n) % n;  // 2^32 mod n
    for (uint tries = 0u; tries < 8u && h > 0xFFFFFFFFu - extra; ++tries) h = lc_hash(h);
    return h % n;
}

// One light drawn for a shaded point with the scene's light pick: a root
// (lc_root_weights), then down its tree (tree and power), or any light
// with the same probability (uniform). Its probability in `pdf`;
// kInvalidIndex when no light can be drawn.
uint lc_pick_light(LC_IN(SurfacePoint) sp, LC_IN(FrameParams) f, uint stream, LC_OUT(float) pdf) {
    pdf = 0.0f;
    if (f.light_count == 0u) return kInvalidIndex;
    if (f.light_pick == kLightPickUniform) {
        pdf = 1.0f / float(f.light_count);
        return lc_uniform_light(stream, f.light_count);
    }
    RootWeights r = lc_root_weights(sp, f, f.light_pick);
    uint h = stream;
    pdf = 1.0f;
    for (uint t = 0u; t < kLightTypeCount; ++t) {
        if (!(r.weight[t] > 0.0f)) continue;
        h = lc_hash(h);
        // The last type with weight has after[t] == 0: always taken.
        if (lc_branch(h, lc_branch_steps(r.weight[t], r.after[t]), pdf))
            return lc_descend(sp, f.roots[t], f.light_pick, f.min_distance2, h, pdf);
    }
    pdf = 0.0f;
    return kInvalidIndex;
}

// --method sampled: light samples [first, first + count) of the point's
// f.light_samples, each one light picked by lc_pick_light and one shadow
// ray; returns their sum of contribution / probability / f.light_samples
// (each divided before it is added: a sum of estimates near FLT_MAX each
// would overflow before a division at the end).
vec3 lc_shade_sampled(LC_IN(SurfacePoint) sp, LC_IN(FrameParams) f, uint stream, uint first, uint count,
                      LC_INOUT(ShadeStats) stats) {
    float per_sample = 1.0f / float(f.light_samples);
    vec3 sum = vec3(0.0f);
    for (uint k = first; k < first + count; ++k) {
        float pdf;
        uint light = lc_pick_light(sp, f, lc_substream(stream, k), pdf);
        if (light == kInvalidIndex || !(pdf > 0.0f)) continue;
        Light l = LC_LIGHT(light);
        // Divided by pdf last: pdf <= 1, so no step overflows where the
        // result does not (intensity / pdf did, for a light of 1e38 picked
        // with probability 0.5, or a dim one at the tree pick's 2^-24).
        sum += ((lc_light_unit_shadowed(sp, l, f.min_distance2, stats) * lc_light_intensity(l)) / pdf) * per_sample;
    }
    return sum;
}

// Stochastic Lightcuts (Yuksel 2019): the contribution of the cluster
// `node_index` estimated with a representative drawn afresh, in proportion
// to the luminance of the lights' intensities (the distribution the fixed
// representatives are drawn from when the tree is built), one shadow ray.
// Unbiased for the cluster's exact contribution: the light drawn, j, has
// probability P_j and the estimate is I_j * unit_j / P_j. `draw` numbers
// the independent draws of one cluster at one camera sample
// (f.light_samples of them; the caller averages).
vec3 lc_shade_cluster_stochastic(LC_IN(SurfacePoint) sp, uint node_index, float min_distance2, uint stream,
                                 uint draw, LC_INOUT(ShadeStats) stats) {
    float pdf = 1.0f;
    uint light = lc_descend(sp, node_index, kLightPickPower, min_distance2,
                            lc_substream(lc_substream(stream, node_index), draw), pdf);
    if (!(pdf > 0.0f)) return vec3(0.0f);
    Light l = LC_LIGHT(light);
    return (lc_light_unit_shadowed(sp, l, min_distance2, stats) * lc_light_intensity(l)) / pdf;  // as lc_shade_sampled
}
