// The quad evaluations of host/pair_bound.h (a cluster's bound, a light's
// unit contribution), written once over a vector of float lanes:
// pair_bound.h includes this file in namespace quad4 (SSE: the four points
// of a quad in the lanes), built for AVX2 in namespace quad8 (two clusters
// or lights at the four points, the first in lanes 0-3, the second in lanes
// 4-7) and built for AVX-512 in namespace quad16 (four clusters, each in a
// quarter; only cluster_errors is used there). The including namespace provides
// the vector type V and its operations v_set1, v_zero, v_add, v_sub, v_mul,
// v_div, v_sqrt, v_and, v_andnot, v_or, v_cmpgt, v_cmpge, v_cmpnle,
// v_abs, v_min and v_max (GLSL's min and max, see glsl_min), v_movemask,
// and v_set2(a, b): the first cluster's value a and the second's b.
// Every value is computed with the same operations in the same order as
// the scalar lc_cluster_bound, lc_ggx_bound, lc_disney_bound,
// lc_emission_bound, lc_light_unit, lc_brdf_cos and lc_disney_brdf_cos
// (shaders/lc_shared), so the results are theirs bit for bit
// (tests/test_quad_cut.cpp). Those bounds form no angles (no acos, asin or
// cos) for this: sqrt, like the rest, is rounded the same way in every lane.
// No include guard: included once per vector width.

// The shaded points lane by lane: positions, frames, the diffuse and
// specular colours (zero at points without a GGX lobe) and what the GGX
// bound needs of each point alone.
struct QuadLanes {
    V px, py, pz;
    V nx, ny, nz, anx, any, anz;
    V tx, ty, tz, atx, aty, atz;
    V bx, by, bz, abx, aby, abz;
    V kd_r, kd_g, kd_b, ks_r, ks_g, ks_b;
    V wox, woy, woz;
    // lc_ggx_bound's terms that depend on the point alone: cos_o, the
    // mirror direction wr, alpha^2, lc_smith_g1(cos_o, alpha) and 4 cos_o.
    V cos_o, wr_x, wr_y, wr_z, a2, g1, four_cos_o;
    V active;             // all ones in the lanes of active points
    V specular_lanes;     // all ones in the lanes of active points with a GGX lobe
    unsigned specular;    // lanes whose material has a GGX lobe
    // The quad functions cover these points (a Disney material at some
    // point under the seed report's lobe bound, a benchmark's switch, they
    // do not).
    bool covered = false;
    // Points with the Disney BRDF: what lc_disney_bound needs of each point
    // alone (set where `disney` has the lane's bit, anything elsewhere):
    // 1 - metallic, 2 roughness, lc_schlick_weight(cos_o), lc_disney_spec0,
    // lc_disney_sheen_color where the material has sheen, and of the
    // clearcoat lobe 0.25 clearcoat, lc_gtr1_d's a2, a2 - 1 and kPi log(a2)
    // for lc_clearcoat_alpha, and lc_smith_g1(cos_o, kClearcoatSmithAlpha).
    unsigned disney = 0u;
    V disney_lanes, sheen_lanes, coat_lanes;  // all ones where the point has the BRDF, the lobe
    V one_minus_metallic, two_roughness, schlick_o;
    V spec0_r, spec0_g, spec0_b, sheen_r, sheen_g, sheen_b;
    V coat_weight, coat_a2, coat_a2_minus_1, coat_pi_log, coat_g1;
};

// The clusters lane by lane: their boxes, radii, intensities and falloff
// clamps, and their emission cones (lc_emission_bound) where some cluster
// has one.
struct QuadNodes {
    V min_x, min_y, min_z, max_x, max_y, max_z;
    V radius;  // half the box's diagonal (lc_box_cone)
    V intensity_r, intensity_g, intensity_b;
    V clamp;   // lc_falloff_clamp2 of the cluster's type
    bool any_cone = false;  // the fields below are set
    V cone;                 // all ones where the cluster's lights do not emit everywhere
    V axis_x, axis_y, axis_z;
    V cos_o, sin_o;         // min(cos_theta_o, 1) and its sine
    V cos_e, edge;          // cos_theta_e and lc_spot_edge of it
    V falloff_width;
    V two_sided, cosine, spot;  // all ones where the node is two-sided, oriented or VPL, a spot
};

// The clusters `a` and `b` as v_set2 lays them out; their radii only where
// a point has a GGX lobe or the Disney BRDF (`ggx`), the bounds that read
// them.
template <class Kernel>
LC_ALWAYS_INLINE inline QuadNodes quad_nodes(Kernel& kernel, const gpu::LightNode& a, const gpu::LightNode& b,
                                             float min_distance2, bool ggx) {
    const auto radius = [ggx](const gpu::LightNode& n) {
        if (!ggx) return 0.0f;
        const glm::vec3 extent(n.max_x - n.min_x, n.max_y - n.min_y, n.max_z - n.min_z);
        return 0.5f * std::sqrt((extent.x * extent.x + extent.y * extent.y) + extent.z * extent.z);
    };
    const auto clamp = [&](const gpu::LightNode& n) {
        return kernel.lc_falloff_clamp2(min_distance2, (n.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask);
    };
    QuadNodes n;
    n.min_x = v_set2(a.min_x, b.min_x);
    n.min_y = v_set2(a.min_y, b.min_y);
    n.min_z = v_set2(a.min_z, b.min_z);
    n.max_x = v_set2(a.max_x, b.max_x);
    n.max_y = v_set2(a.max_y, b.max_y);
    n.max_z = v_set2(a.max_z, b.max_z);
    n.radius = v_set2(radius(a), radius(b));
    n.intensity_r = v_set2(a.intensity_r, b.intensity_r);
    n.intensity_g = v_set2(a.intensity_g, b.intensity_g);
    n.intensity_b = v_set2(a.intensity_b, b.intensity_b);
    n.clamp = v_set2(clamp(a), clamp(b));
    const auto has_cone = [](const gpu::LightNode& x) { return !(x.cos_theta_o <= -1.0f); };
    n.any_cone = Kernel::kEnableOriented && (has_cone(a) || has_cone(b));
    if (!n.any_cone) return n;
    // Each node's own values, computed once here by the scalar functions
    // lc_emission_bound calls, so that the lanes hold their very bits.
    const auto all = [](bool on) { return on ? std::bit_cast<float>(~0u) : 0.0f; };
    const auto type = [](const gpu::LightNode& x) { return (x.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask; };
    glm::vec3 axis_a, axis_b;
    decode_axis_pair(a.axis_oct, b.axis_oct, axis_a, axis_b);
    const float cos_o_a = std::min(a.cos_theta_o, 1.0f), cos_o_b = std::min(b.cos_theta_o, 1.0f);
    n.cone = v_set2(all(has_cone(a)), all(has_cone(b)));
    n.axis_x = v_set2(axis_a.x, axis_b.x);
    n.axis_y = v_set2(axis_a.y, axis_b.y);
    n.axis_z = v_set2(axis_a.z, axis_b.z);
    n.cos_o = v_set2(cos_o_a, cos_o_b);
    n.sin_o = v_set2(kernel.lc_sin_of(cos_o_a), kernel.lc_sin_of(cos_o_b));
    n.cos_e = v_set2(a.cos_theta_e, b.cos_theta_e);
    n.edge = v_set2(kernel.lc_spot_edge(a.cos_theta_e), kernel.lc_spot_edge(b.cos_theta_e));
    n.falloff_width = v_set2(a.falloff_width, b.falloff_width);
    n.two_sided = v_set2(all((a.flags & gpu::kNodeTwoSided) != 0u), all((b.flags & gpu::kNodeTwoSided) != 0u));
    const auto cosine = [&](const gpu::LightNode& x) {
        return type(x) == gpu::kLightOriented || type(x) == gpu::kLightVpl;
    };
    n.cosine = v_set2(all(cosine(a)), all(cosine(b)));
    n.spot = v_set2(all(type(a) == gpu::kLightSpot), all(type(b) == gpu::kLightSpot));
    return n;
}

// Where m is all ones, a; elsewhere b.
LC_ALWAYS_INLINE inline V v_select(V m, V a, V b) { return v_or(v_and(m, a), v_andnot(m, b)); }

// ((a_x * v_x + a_y * v_y) + a_z * v_z) lane by lane: glm's dot.
LC_ALWAYS_INLINE inline V dot4(V ax, V ay, V az, V vx, V vy, V vz) {
    return v_add(v_add(v_mul(ax, vx), v_mul(ay, vy)), v_mul(az, vz));
}

// lc_smith_g1(cos_v, alpha) lane by lane, with a2 = alpha * alpha.
LC_ALWAYS_INLINE inline V smith_g1(V cos_v, V a2) {
    return v_div(v_mul(v_set1(2.0f), cos_v),
                 v_add(cos_v, v_sqrt(v_add(a2, v_mul(v_mul(v_sub(v_set1(1.0f), a2), cos_v), cos_v)))));
}

// The point-only terms of QuadLanes from its positions, frames, view
// directions and the roughness `alpha`.
LC_ALWAYS_INLINE inline void set_ggx_terms(QuadLanes& q, V alpha) {
    const V two = v_set1(2.0f);
    q.cos_o = dot4(q.nx, q.ny, q.nz, q.wox, q.woy, q.woz);
    const V two_cos_o = v_mul(two, q.cos_o);
    q.wr_x = v_sub(v_mul(two_cos_o, q.nx), q.wox);
    q.wr_y = v_sub(v_mul(two_cos_o, q.ny), q.woy);
    q.wr_z = v_sub(v_mul(two_cos_o, q.nz), q.woz);
    q.a2 = v_mul(alpha, alpha);
    q.g1 = smith_g1(q.cos_o, q.a2);
    q.four_cos_o = v_mul(v_set1(4.0f), q.cos_o);
}

// lc_box_cone of each lane's box at its point: whether the point is outside
// the bounding sphere (else any direction), the unit axis a and sin_c, cos_c
// of the half-angle.
struct BoxCones {
    V outside, a_x, a_y, a_z, sin_c, cos_c;
};

template <class Kernel>
LC_ALWAYS_INLINE inline BoxCones box_cones(const QuadLanes& q, const QuadNodes& n) {
    const V zero = v_zero(), one = v_set1(1.0f), half = v_set1(0.5f);
    const V c_x = v_mul(half, v_add(v_sub(n.min_x, q.px), v_sub(n.max_x, q.px)));
    const V c_y = v_mul(half, v_add(v_sub(n.min_y, q.py), v_sub(n.max_y, q.py)));
    const V c_z = v_mul(half, v_add(v_sub(n.min_z, q.pz), v_sub(n.max_z, q.pz)));
    const V dist = v_sqrt(dot4(c_x, c_y, c_z, c_x, c_y, c_z));
    BoxCones cone;
    cone.outside = v_cmpgt(dist, v_mul(n.radius, v_set1(Kernel::kOutsideSphere)));
    cone.a_x = v_div(c_x, dist), cone.a_y = v_div(c_y, dist), cone.a_z = v_div(c_z, dist);
    cone.sin_c = v_min(v_div(n.radius, dist), one);
    cone.cos_c = v_sqrt(v_max(v_sub(one, v_mul(cone.sin_c, cone.sin_c)), zero));
    return cone;
}

// lc_cos_h_max at each lane's point for its box's cone.
template <class Kernel>
LC_ALWAYS_INLINE inline V cos_h_max(const QuadLanes& q, const BoxCones& cone) {
    const V one = v_set1(1.0f), half = v_set1(0.5f), zero = v_zero();
    const V cos_r = dot4(q.wr_x, q.wr_y, q.wr_z, cone.a_x, cone.a_y, cone.a_z);
    // theta_c + kAngleSlack.
    const V slack_cos = v_set1(Kernel::kAngleSlackCos), slack_sin = v_set1(Kernel::kAngleSlackSin);
    const V cos_c = v_sub(v_mul(cone.cos_c, slack_cos), v_mul(cone.sin_c, slack_sin));
    const V sin_c = v_add(v_mul(cone.sin_c, slack_cos), v_mul(cone.cos_c, slack_sin));
    const V in_cone = v_cmpge(cos_r, cos_c);  // the mirror direction in the cone: 1
    const V x_x = v_sub(v_mul(q.wr_y, cone.a_z), v_mul(cone.a_y, q.wr_z));
    const V x_y = v_sub(v_mul(q.wr_z, cone.a_x), v_mul(cone.a_z, q.wr_x));
    const V x_z = v_sub(v_mul(q.wr_x, cone.a_y), v_mul(cone.a_x, q.wr_y));
    const V sin_r = v_sqrt(dot4(x_x, x_y, x_z, x_x, x_y, x_z));
    const V cos_delta = v_min(
        v_add(v_add(v_mul(cos_r, cos_c), v_mul(sin_r, sin_c)), v_set1(Kernel::kCosineAbsSlack)), one);
    const V narrowed =
        v_min(v_mul(v_sqrt(v_max(v_add(half, v_mul(half, cos_delta)), zero)), v_set1(Kernel::kBoundSlack)), one);
    const V wide = v_andnot(cone.outside, one);
    const V narrow = v_and(cone.outside, v_or(v_and(in_cone, one), v_andnot(in_cone, narrowed)));
    return v_or(wide, narrow);
}

// lc_ggx_d(cos_h, sin2_h, alpha) lane by lane.
template <class Kernel>
LC_ALWAYS_INLINE inline V ggx_d(const QuadLanes& q, V cos_h, V sin2_h) {
    const V denom = v_add(sin2_h, v_mul(q.a2, v_mul(cos_h, cos_h)));
    return v_div(q.a2, v_mul(v_mul(v_set1(Kernel::kPi), denom), denom));
}

// 1 - cos_h^2, as the bounds give lc_ggx_d and lc_gtr1_d for cos_h_max.
LC_ALWAYS_INLINE inline V one_minus_square(V cos_h) { return v_sub(v_set1(1.0f), v_mul(cos_h, cos_h)); }

// lc_half_angle(n, h) at each lane's point for the unit half vector h:
// clamp(dot(n, h), 0, 1) into cos_h, and into sin2_h 1 - cos_h^2, or where
// that is below kHalfAngleCross the square of glm's cross(n, h).
template <class Kernel>
LC_ALWAYS_INLINE inline void half_angle(const QuadLanes& q, V h_x, V h_y, V h_z, V& cos_h, V& sin2_h) {
    cos_h = v_min(v_max(dot4(q.nx, q.ny, q.nz, h_x, h_y, h_z), v_zero()), v_set1(1.0f));
    sin2_h = one_minus_square(cos_h);
    const V near_peak = v_cmpgt(v_set1(Kernel::kHalfAngleCross), sin2_h);
    if (v_movemask(near_peak) == 0) return;
    const V s_x = v_sub(v_mul(q.ny, h_z), v_mul(h_y, q.nz));
    const V s_y = v_sub(v_mul(q.nz, h_x), v_mul(h_z, q.nx));
    const V s_z = v_sub(v_mul(q.nx, h_y), v_mul(h_x, q.ny));
    sin2_h = v_select(near_peak, dot4(s_x, s_y, s_z, s_x, s_y, s_z), sin2_h);
}

// lc_ggx_bound of each lane's box at its point: lc_box_cone, lc_cos_h_max,
// lc_ggx_d and lc_smith_g1; 0 where cos_o <= 0, anything in lanes the
// caller masks.
template <class Kernel>
LC_ALWAYS_INLINE inline V ggx_bounds(const QuadLanes& q, V cos_h) {
    const V bound = v_mul(v_div(v_mul(ggx_d<Kernel>(q, cos_h, one_minus_square(cos_h)), q.g1), q.four_cos_o),
                          v_set1(Kernel::kBoundSlack));
    return v_and(bound, v_cmpnle(q.cos_o, v_zero()));  // lc_ggx_bound: 0 where cos_o <= 0
}

// lc_schlick_weight lane by lane.
LC_ALWAYS_INLINE inline V schlick_weight(V cos_x) {
    const V m = v_min(v_max(v_sub(v_set1(1.0f), cos_x), v_zero()), v_set1(1.0f));
    const V m2 = v_mul(m, m);
    return v_mul(v_mul(m2, m2), m);
}

// lc_gtr1_d(cos_h, sin2_h, lc_clearcoat_alpha) lane by lane, from the
// point's terms.
LC_ALWAYS_INLINE inline V gtr1_d(const QuadLanes& q, V cos_h, V sin2_h) {
    return v_div(q.coat_a2_minus_1, v_mul(q.coat_pi_log, v_add(sin2_h, v_mul(q.coat_a2, v_mul(cos_h, cos_h)))));
}

// The Disney BRDF's lobes after the diffuse one, added to r, g, b in the
// order of lc_disney_bound and lc_disney_brdf_cos: the specular lobe's
// microfacet term `specular` times glm's mix(spec0, 1, w), which is
// spec0 (1 - w) + 1 w, and 1 w is w, bit for bit; sheen times w * cos; the
// clearcoat lobe from its microfacet term coat() (called only where the
// kernel has the lobe).
template <class Kernel, class Coat>
LC_ALWAYS_INLINE inline void add_disney_lobes(const QuadLanes& q, V w, V specular, V cos, Coat coat, V& r, V& g,
                                              V& b) {
    const V one_minus_w = v_sub(v_set1(1.0f), w);
    r = v_add(r, v_mul(v_add(v_mul(q.spec0_r, one_minus_w), w), specular));
    g = v_add(g, v_mul(v_add(v_mul(q.spec0_g, one_minus_w), w), specular));
    b = v_add(b, v_mul(v_add(v_mul(q.spec0_b, one_minus_w), w), specular));
    if (Kernel::kEnableSheen) {
        const V weight = v_mul(w, cos);
        r = v_select(q.sheen_lanes, v_add(r, v_mul(q.sheen_r, weight)), r);
        g = v_select(q.sheen_lanes, v_add(g, v_mul(q.sheen_g, weight)), g);
        b = v_select(q.sheen_lanes, v_add(b, v_mul(q.sheen_b, weight)), b);
    }
    if (Kernel::kEnableClearcoat) {
        const V fresnel = v_add(v_mul(v_set1(0.04f), one_minus_w), w);
        const V lobe = v_mul(v_mul(q.coat_weight, fresnel), coat());
        r = v_select(q.coat_lanes, v_add(r, lobe), r);
        g = v_select(q.coat_lanes, v_add(g, lobe), g);
        b = v_select(q.coat_lanes, v_add(b, lobe), b);
    }
}

// lc_disney_bound at each lane's point (cosine bound cos_bound) into r, g,
// b: lc_cos_d_range, then the lobes; anything in lanes without the BRDF.
template <class Kernel>
LC_ALWAYS_INLINE inline void disney_bounds(const QuadLanes& q, const BoxCones& cone, V cos_h, V cos_bound, V& r, V& g,
                                           V& b) {
    const V zero = v_zero(), one = v_set1(1.0f), half = v_set1(0.5f), minus_one = v_set1(-1.0f);
    const V slack = v_set1(Kernel::kBoundSlack);
    // lc_cos_d_range: cos(angle_o -+ (theta_c + kAngleSlack)), their half
    // angles' cosines; (0, 1) inside the sphere.
    const V cos_o = v_min(v_max(dot4(q.wox, q.woy, q.woz, cone.a_x, cone.a_y, cone.a_z), minus_one), one);
    const V x_x = v_sub(v_mul(q.woy, cone.a_z), v_mul(cone.a_y, q.woz));
    const V x_y = v_sub(v_mul(q.woz, cone.a_x), v_mul(cone.a_z, q.wox));
    const V x_z = v_sub(v_mul(q.wox, cone.a_y), v_mul(cone.a_x, q.woy));
    const V sin_o = v_min(v_sqrt(dot4(x_x, x_y, x_z, x_x, x_y, x_z)), one);
    // lc_cos_d_range's min(cone.w, 1) and its cosine are box_cones' sin_c
    // and cos_c, float for float.
    const V sin_c = cone.sin_c, cos_c = cone.cos_c;
    const V slack_cos = v_set1(Kernel::kAngleSlackCos), slack_sin = v_set1(Kernel::kAngleSlackSin);
    const V cos_cs = v_sub(v_mul(cos_c, slack_cos), v_mul(sin_c, slack_sin));
    const V sin_cs = v_add(v_mul(sin_c, slack_cos), v_mul(cos_c, slack_sin));
    const V cos_near =
        v_select(v_cmpge(cos_o, cos_cs), one, v_min(v_add(v_mul(cos_o, cos_cs), v_mul(sin_o, sin_cs)), one));
    const V cos_far = v_select(v_cmpge(v_mul(cos_cs, minus_one), cos_o), minus_one,
                               v_max(v_sub(v_mul(cos_o, cos_cs), v_mul(sin_o, sin_cs)), minus_one));
    const V d_min = v_select(
        cone.outside,
        v_max(v_sub(v_div(v_sqrt(v_add(half, v_mul(half, cos_far))), slack), v_set1(Kernel::kCosineAbsSlack)), zero),
        zero);
    const V d_max = v_select(cone.outside, v_min(v_mul(v_sqrt(v_add(half, v_mul(half, cos_near))), slack), one), one);
    // The diffuse lobe: F_D90 at the largest cos_d.
    const V fd90 = v_add(half, v_mul(v_mul(q.two_roughness, d_max), d_max));
    const V retro = v_mul(v_max(fd90, one), v_add(one, v_mul(v_sub(fd90, one), q.schlick_o)));
    const V diffuse = v_div(v_mul(v_mul(q.one_minus_metallic, retro), cos_bound), v_set1(Kernel::kPi));
    r = v_mul(q.kd_r, diffuse);
    g = v_mul(q.kd_g, diffuse);
    b = v_mul(q.kd_b, diffuse);
    // The specular lobe at the largest cos_h, Schlick's weight at the
    // smallest cos_d.
    const V w = schlick_weight(d_min);
    const V sin2_h = one_minus_square(cos_h);
    const V ggx = v_div(v_mul(ggx_d<Kernel>(q, cos_h, sin2_h), q.g1), q.four_cos_o);
    add_disney_lobes<Kernel>(
        q, w, ggx, cos_bound, [&] { return v_div(v_mul(gtr1_d(q, cos_h, sin2_h), q.coat_g1), q.four_cos_o); }, r,
        g, b);
    const V lit = v_cmpgt(q.cos_o, zero);  // lc_disney_bound: 0 where !(cos_o > 0)
    r = v_and(v_mul(r, slack), lit);
    g = v_and(v_mul(g, slack), lit);
    b = v_and(v_mul(b, slack), lit);
}

// lc_disney_brdf_cos at each lane's point for the unit direction wi, whose
// cosine with the normal is cos_i > 0, into r, g, b (the BRDF times cos_i):
// 0 where cos_o <= 0, anything in lanes without the BRDF.
template <class Kernel>
LC_ALWAYS_INLINE inline void disney_values(const QuadLanes& q, V wi_x, V wi_y, V wi_z, V cos_i, V& r, V& g, V& b) {
    const V zero = v_zero(), one = v_set1(1.0f), half = v_set1(0.5f);
    // The half vector, glm's normalize: v * (1 / sqrt(dot(v, v))).
    const V s_x = v_add(wi_x, q.wox), s_y = v_add(wi_y, q.woy), s_z = v_add(wi_z, q.woz);
    const V inverse = v_div(one, v_sqrt(dot4(s_x, s_y, s_z, s_x, s_y, s_z)));
    const V h_x = v_mul(s_x, inverse), h_y = v_mul(s_y, inverse), h_z = v_mul(s_z, inverse);
    V cos_h, sin2_h;
    half_angle<Kernel>(q, h_x, h_y, h_z, cos_h, sin2_h);
    const V cos_d = v_min(v_max(dot4(wi_x, wi_y, wi_z, h_x, h_y, h_z), zero), one);
    const V w = schlick_weight(cos_d);
    // The diffuse lobe (lc_disney_diffuse).
    const V fd90 = v_add(half, v_mul(v_mul(q.two_roughness, cos_d), cos_d));
    const V fl = v_add(one, v_mul(v_sub(fd90, one), schlick_weight(cos_i)));
    const V fv = v_add(one, v_mul(v_sub(fd90, one), q.schlick_o));
    const V diffuse = v_div(v_mul(v_mul(v_mul(q.one_minus_metallic, fl), fv), cos_i), v_set1(Kernel::kPi));
    r = v_mul(q.kd_r, diffuse);
    g = v_mul(q.kd_g, diffuse);
    b = v_mul(q.kd_b, diffuse);
    // The specular and clearcoat lobes (lc_microfacet_cos; lc_smith_g1 at
    // cos_i), where the facets reflect towards the viewer
    // (lc_facets_reflect: wo . h > 0); 0, which adds nothing, elsewhere.
    const V facets = v_cmpgt(dot4(q.wox, q.woy, q.woz, h_x, h_y, h_z), zero);
    const V specular = v_and(
        v_div(v_mul(v_mul(ggx_d<Kernel>(q, cos_h, sin2_h), smith_g1(cos_i, q.a2)), q.g1), q.four_cos_o), facets);
    add_disney_lobes<Kernel>(
        q, w, specular, cos_i,
        [&] {
            const V g1_coat_i =
                smith_g1(cos_i, v_set1(Kernel::kClearcoatSmithAlpha * Kernel::kClearcoatSmithAlpha));
            return v_and(v_div(v_mul(v_mul(gtr1_d(q, cos_h, sin2_h), g1_coat_i), q.coat_g1), q.four_cos_o), facets);
        },
        r, g, b);
    const V seen = v_cmpgt(q.cos_o, zero);  // lc_disney_brdf_cos: 0 where !(cos_o > 0)
    r = v_and(r, seen);
    g = v_and(g, seen);
    b = v_and(b, seen);
}

// lc_emission_bound of each lane's cluster at its point, from the box
// relative to the point (lo, hi: box - p) and its centre c; 1 where the
// cluster emits everywhere.
template <class Kernel>
LC_ALWAYS_INLINE inline V emission_bounds(const QuadNodes& n, V lo_x, V lo_y, V lo_z, V hi_x, V hi_y, V hi_z, V c_x,
                                          V c_y, V c_z) {
    const V zero = v_zero(), one = v_set1(1.0f), half = v_set1(0.5f);
    const V h_x = v_sub(hi_x, lo_x), h_y = v_sub(hi_y, lo_y), h_z = v_sub(hi_z, lo_z);
    const V radius = v_mul(half, v_sqrt(dot4(h_x, h_y, h_z, h_x, h_y, h_z)));
    const V d = v_sqrt(dot4(c_x, c_y, c_z, c_x, c_y, c_z));
    const V outside = v_cmpgt(d, v_mul(radius, v_set1(Kernel::kOutsideSphere)));  // else any direction: 1
    V cos_w = v_div(v_mul(dot4(n.axis_x, n.axis_y, n.axis_z, c_x, c_y, c_z), v_set1(-1.0f)), d);
    cos_w = v_min(v_max(cos_w, v_set1(-1.0f)), one);  // clamp
    cos_w = v_select(n.two_sided, v_abs(cos_w), cos_w);
    const V sin_b = v_min(v_div(radius, d), one);
    const V cos_b = v_sqrt(v_max(v_sub(one, v_mul(sin_b, sin_b)), zero));
    const V cos_ob = v_sub(v_mul(n.cos_o, cos_b), v_mul(n.sin_o, sin_b));
    const V sin_ob = v_add(v_mul(n.sin_o, cos_b), v_mul(n.cos_o, sin_b));
    const V slack_cos = v_set1(Kernel::kAngleSlackCos), slack_sin = v_set1(Kernel::kAngleSlackSin);
    const V cos_s = v_sub(v_mul(cos_ob, slack_cos), v_mul(sin_ob, slack_sin));
    const V sin_s = v_add(v_mul(sin_ob, slack_cos), v_mul(cos_ob, slack_sin));
    const V sin_w = v_sqrt(v_max(v_sub(one, v_mul(cos_w, cos_w)), zero));
    const V apart = v_and(v_cmpgt(v_add(n.cos_o, cos_b), zero), v_and(v_cmpgt(sin_s, zero), v_cmpgt(cos_s, cos_w)));
    const V cos_t = v_select(apart, v_min(v_add(v_mul(cos_w, cos_s), v_mul(sin_w, sin_s)), one), one);
    const V cosine = v_min(v_mul(cos_t, v_set1(Kernel::kBoundSlack)), one);
    const V s = v_min(v_mul(v_div(v_sub(cos_t, n.edge), n.falloff_width), v_set1(Kernel::kBoundSlack)), one);
    V e = v_select(n.cosine, cosine, v_select(n.spot, v_mul(s, s), one));
    e = v_andnot(v_cmpge(n.cos_e, cos_t), e);  // theta' >= theta_e: 0
    return v_select(v_and(n.cone, outside), e, one);
}

// lc_cluster_error of each lane's cluster at its point, 0 in inactive
// lanes; false (and zeros) when it is 0 in every lane.
template <class Kernel>
LC_ALWAYS_INLINE inline bool cluster_errors(const QuadLanes& q, const QuadNodes& n, V& errors) {
    const V half = v_set1(0.5f), zero = v_zero();
    const V lo_x = v_sub(n.min_x, q.px), lo_y = v_sub(n.min_y, q.py), lo_z = v_sub(n.min_z, q.pz);
    const V hi_x = v_sub(n.max_x, q.px), hi_y = v_sub(n.max_y, q.py), hi_z = v_sub(n.max_z, q.pz);
    const V c_x = v_mul(half, v_add(lo_x, hi_x)), c_y = v_mul(half, v_add(lo_y, hi_y)),
            c_z = v_mul(half, v_add(lo_z, hi_z));
    const V e_x = v_mul(half, v_sub(hi_x, lo_x)), e_y = v_mul(half, v_sub(hi_y, lo_y)),
            e_z = v_mul(half, v_sub(hi_z, lo_z));
    const V ne = dot4(q.anx, q.any, q.anz, e_x, e_y, e_z);
    const V z_max = v_add(v_add(dot4(q.nx, q.ny, q.nz, c_x, c_y, c_z), ne),
                          v_mul(v_set1(Kernel::kCosineAbsSlack),
                                v_add(dot4(q.anx, q.any, q.anz, v_abs(c_x), v_abs(c_y), v_abs(c_z)), ne)));
    const V near_x =
        v_max(v_sub(v_abs(dot4(q.tx, q.ty, q.tz, c_x, c_y, c_z)), dot4(q.atx, q.aty, q.atz, e_x, e_y, e_z)), zero);
    const V near_y =
        v_max(v_sub(v_abs(dot4(q.bx, q.by, q.bz, c_x, c_y, c_z)), dot4(q.abx, q.aby, q.abz, e_x, e_y, e_z)), zero);
    const V qq = v_add(v_add(v_mul(near_x, near_x), v_mul(near_y, near_y)), v_mul(z_max, z_max));
    const V bound = v_mul(z_max, v_div(v_set1(1.0f), v_sqrt(qq)));
    const V cos_bound = v_min(v_mul(bound, v_set1(Kernel::kBoundSlack)), v_set1(1.0f));
    // lc_cosine_bound and lc_cluster_bound return 0 where z_max <= 0 or the
    // cosine bound <= 0 (a NaN goes on, as there).
    const V cosines = v_and(cos_bound, v_and(v_cmpnle(z_max, zero), q.active));
    const V positive = v_and(v_cmpnle(cosines, zero), q.active);
    if (v_movemask(positive) == 0) {
        errors = zero;
        return false;
    }
    const V d_x = v_max(v_max(lo_x, v_sub(q.px, n.max_x)), zero);
    const V d_y = v_max(v_max(lo_y, v_sub(q.py, n.max_y)), zero);
    const V d_z = v_max(v_max(lo_z, v_sub(q.pz, n.max_z)), zero);
    const V d2 = v_add(v_add(v_mul(d_x, d_x), v_mul(d_y, d_y)), v_mul(d_z, d_z));
    V factor = v_div(v_set1(Kernel::kBoundSlack), v_max(d2, n.clamp));
    V counted = positive;
    if (n.any_cone) {
        // lc_cluster_bound: the emission bound times kBoundSlack over the
        // distance (1 times it where the lights emit everywhere, the same
        // float), and 0 where the emission bound is <= 0.
        const V emission = emission_bounds<Kernel>(n, lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, c_x, c_y, c_z);
        factor = v_mul(emission, factor);
        counted = v_and(counted, v_cmpnle(emission, zero));
    }
    const V cos_over_pi = v_div(cosines, v_set1(Kernel::kPi));
    V r = v_mul(q.kd_r, cos_over_pi);
    V g = v_mul(q.kd_g, cos_over_pi);
    V b = v_mul(q.kd_b, cos_over_pi);
    if (q.specular != 0u || q.disney != 0u) {
        const BoxCones cone = box_cones<Kernel>(q, n);
        const V cos_h = cos_h_max<Kernel>(q, cone);
        if (q.specular != 0u) {
            // The lobe counts at points that have one, where the cosine bound
            // is above 0 (or NaN), as in lc_cluster_bound.
            const V ggx = v_and(ggx_bounds<Kernel>(q, cos_h), v_and(positive, q.specular_lanes));
            r = v_add(r, v_mul(q.ks_r, ggx));
            g = v_add(g, v_mul(q.ks_g, ggx));
            b = v_add(b, v_mul(q.ks_b, ggx));
        }
        if (q.disney != 0u) {
            V dr, dg, db;
            disney_bounds<Kernel>(q, cone, cos_h, cosines, dr, dg, db);
            r = v_select(q.disney_lanes, dr, r);
            g = v_select(q.disney_lanes, dg, g);
            b = v_select(q.disney_lanes, db, b);
        }
    }
    r = v_mul(v_mul(r, factor), n.intensity_r);
    g = v_mul(v_mul(g, factor), n.intensity_g);
    b = v_mul(v_mul(b, factor), n.intensity_b);
    const V error = v_add(v_add(v_mul(v_set1(0.2126f), r), v_mul(v_set1(0.7152f), g)), v_mul(v_set1(0.0722f), b));
    errors = v_and(error, counted);
    return true;
}

// Lights lane by lane for light_values, as v_set2 lays them out: their
// positions, falloff clamps and, where some light is not a point light,
// their emission (lc_light_unit's spot falloff or cosine).
struct LightLanes {
    V x, y, z, clamp;
    bool any_emission = false;  // the fields below are set
    V point;                    // all ones where the light emits the same everywhere
    V axis_x, axis_y, axis_z;
    V spot, two_sided;  // all ones where the light is a spot, a two-sided cosine emitter
    V cos_outer, width;  // a spot's: cos_outer and max(1e-3, cos_inner - cos_outer)
};

// The lights `a` and `b`, each a point light, spot, cosine emitter or VPL.
template <class Kernel>
LC_ALWAYS_INLINE inline LightLanes light_lanes(Kernel& kernel, const gpu::Light& a, const gpu::Light& b,
                                               float min_distance2) {
    const std::uint32_t type_a = a.type & gpu::kLightTypeMask, type_b = b.type & gpu::kLightTypeMask;
    LightLanes l;
    l.x = v_set2(a.x, b.x);
    l.y = v_set2(a.y, b.y);
    l.z = v_set2(a.z, b.z);
    l.clamp = v_set2(kernel.lc_falloff_clamp2(min_distance2, type_a), kernel.lc_falloff_clamp2(min_distance2, type_b));
    l.any_emission = type_a != gpu::kLightPoint || type_b != gpu::kLightPoint;
    if (!l.any_emission) return l;
    const auto all = [](bool on) { return on ? std::bit_cast<float>(~0u) : 0.0f; };
    l.point = v_set2(all(type_a == gpu::kLightPoint), all(type_b == gpu::kLightPoint));
    l.axis_x = v_set2(a.axis_x, b.axis_x);
    l.axis_y = v_set2(a.axis_y, b.axis_y);
    l.axis_z = v_set2(a.axis_z, b.axis_z);
    l.spot = v_set2(all(type_a == gpu::kLightSpot), all(type_b == gpu::kLightSpot));
    l.two_sided = v_set2(all((a.type & gpu::kLightTwoSided) != 0u), all((b.type & gpu::kLightTwoSided) != 0u));
    l.cos_outer = v_set2(a.cos_outer, b.cos_outer);
    l.width = v_set2(std::max(1e-3f, a.cos_inner - a.cos_outer), std::max(1e-3f, b.cos_inner - b.cos_outer));
    return l;
}

// lc_light_unit of each lane's light at its point, with the operations of
// lc_light_unit, lc_spot_falloff, lc_brdf_cos and lc_disney_brdf_cos in
// their order: the unit (the BRDF times the cosine and the falloff) into
// r, g, b, the direction to the light into wi and the shadow ray's length
// into length; the lanes where the light reaches the point (lc_light_unit's
// early returns not taken) are all ones in the result.
template <class Kernel>
LC_ALWAYS_INLINE inline V light_values(const QuadLanes& q, const LightLanes& l, V& r, V& g, V& b, V& wi_x, V& wi_y,
                                       V& wi_z, V& length) {
    const V zero = v_zero(), one = v_set1(1.0f);
    const V tx = v_sub(l.x, q.px), ty = v_sub(l.y, q.py), tz = v_sub(l.z, q.pz);
    const V d2 = dot4(tx, ty, tz, tx, ty, tz);
    const V d = v_sqrt(d2);
    wi_x = v_div(tx, d), wi_y = v_div(ty, d), wi_z = v_div(tz, d);
    length = v_mul(d, v_set1(1.0f - Kernel::kShadowEndRelative));
    V factor = v_div(one, v_max(d2, l.clamp));
    if (l.any_emission) {
        // The emission towards each point: -(axis . wi), then the spot's
        // falloff (lc_spot_falloff) or the cosine emitter's cosine.
        const V cos_axis = v_mul(dot4(l.axis_x, l.axis_y, l.axis_z, wi_x, wi_y, wi_z), v_set1(-1.0f));
        const V s = v_min(v_max(v_div(v_sub(v_min(cos_axis, one), l.cos_outer), l.width), zero), one);
        const V emission =
            v_select(l.spot, v_mul(s, s), v_select(l.two_sided, v_abs(cos_axis), v_max(cos_axis, zero)));
        factor = v_select(l.point, factor, v_mul(factor, emission));
    }
    const V cos_i = dot4(q.nx, q.ny, q.nz, wi_x, wi_y, wi_z);
    // lc_light_unit's early returns: no direction (d = 0), the light behind
    // the surface, no emission towards it.
    const V lit = v_and(v_and(v_cmpgt(d, zero), v_cmpnle(cos_i, zero)), v_and(v_cmpgt(factor, zero), q.active));
    const V c = v_div(cos_i, v_set1(Kernel::kPi));
    r = v_mul(q.kd_r, c), g = v_mul(q.kd_g, c), b = v_mul(q.kd_b, c);
    if (Kernel::kEnableGgx && q.specular != 0u) {
        // lc_brdf_cos's GGX lobe where cos_o > 0: h = normalize(wi + wo)
        // (glm's: v * (1 / sqrt(dot(v, v)))), then D G1(cos_i) G1(cos_o) /
        // (4 cos_o), the point's terms from set_ggx_terms.
        const V sx = v_add(wi_x, q.wox), sy = v_add(wi_y, q.woy), sz = v_add(wi_z, q.woz);
        const V inverse = v_div(one, v_sqrt(dot4(sx, sy, sz, sx, sy, sz)));
        const V hx = v_mul(sx, inverse), hy = v_mul(sy, inverse), hz = v_mul(sz, inverse);
        V cos_h, sin2_h;
        half_angle<Kernel>(q, hx, hy, hz, cos_h, sin2_h);
        const V spec =
            v_div(v_mul(v_mul(ggx_d<Kernel>(q, cos_h, sin2_h), smith_g1(cos_i, q.a2)), q.g1), q.four_cos_o);
        // Where cos_o > 0 and the facets reflect towards the viewer
        // (lc_facets_reflect).
        const V facets = v_cmpgt(dot4(q.wox, q.woy, q.woz, hx, hy, hz), zero);
        const V lobe = v_and(v_and(q.specular_lanes, v_cmpgt(q.cos_o, zero)), facets);
        r = v_select(lobe, v_add(r, v_mul(q.ks_r, spec)), r);
        g = v_select(lobe, v_add(g, v_mul(q.ks_g, spec)), g);
        b = v_select(lobe, v_add(b, v_mul(q.ks_b, spec)), b);
    }
    if (q.disney != 0u) {
        V dr, dg, db;
        disney_values<Kernel>(q, wi_x, wi_y, wi_z, cos_i, dr, dg, db);
        r = v_select(q.disney_lanes, dr, r);
        g = v_select(q.disney_lanes, dg, g);
        b = v_select(q.disney_lanes, db, b);
    }
    r = v_mul(r, factor), g = v_mul(g, factor), b = v_mul(b, factor);
    return lit;
}
