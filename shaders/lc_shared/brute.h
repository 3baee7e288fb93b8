// Exact direct lighting: every light, one shadow ray each where it can
// contribute at all. The reference lightcuts is measured against. Shared by
// the CPU reference and the Vulkan kernel brute.comp; needs trace.h and
// shading.h first.
// No include guard: each kernel context includes it exactly once.

// Brute force's sum over the lights keeps what float rounding would drop:
// a million lights each below half a float step of the sum still count.
// (A plain float sum dropped them: a point light beside 4 * 10^6 samples
// of an emissive panel rendered 4% dark.) The CPU adds in
// double, whose add is as fast as float's; the kernels, which may lack
// doubles, add in float with Kahan's compensation, `carry` keeping what the
// sum's rounding dropped to take it off the next term, its operations
// `precise` so that no compiler folds (t - sum) - y to zero.
#ifdef __cplusplus
struct BruteSum {
    dvec3 sum = dvec3(0.0);
};
void lc_brute_add(BruteSum& acc, vec3 x) { acc.sum += dvec3(x); }
vec3 lc_brute_total(const BruteSum& acc) { return vec3(acc.sum); }
#else
struct BruteSum {
    vec3 sum;
    vec3 carry;
};
void lc_brute_add(inout BruteSum acc, vec3 x) {
    precise vec3 y = x - acc.carry;
    precise vec3 t = acc.sum + y;
    precise vec3 lost = (t - acc.sum) - y;
    acc.carry = lost;
    acc.sum = t;
}
vec3 lc_brute_total(BruteSum acc) { return acc.sum; }
#endif

// Every light's contribution, in light order, summed by lc_brute_add.
vec3 lc_shade_brute(LC_IN(SurfacePoint) sp, uint light_count, float min_distance2,
                    LC_INOUT(ShadeStats) stats) {
    BruteSum acc;
#ifndef __cplusplus
    acc.sum = vec3(0.0f);
    acc.carry = vec3(0.0f);
#endif
    for (uint i = 0u; i < light_count; ++i) {
        Light light = LC_LIGHT(i);
        lc_brute_add(acc, lc_light_unit_shadowed(sp, light, min_distance2, stats) * lc_light_intensity(light));
    }
    return lc_brute_total(acc);
}
