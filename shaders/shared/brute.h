// Exact direct lighting: every light, one shadow ray each where it can
// contribute at all. The reference lightcuts is measured against. Shared by
// the CPU reference and the Vulkan kernel brute.comp; needs trace.h and
// shading.h first.
// No include guard: each kernel context includes it exactly once.

vec3 lc_shade_brute(LC_IN(SurfacePoint) sp, uint light_count, float min_distance2,
                    LC_INOUT(ShadeStats) stats) {
    vec3 sum = vec3(0.0f);
    for (uint i = 0u; i < light_count; ++i) {
        Light light = LC_LIGHT(i);
        sum += lc_light_unit_shadowed(sp, light, min_distance2, stats) * lc_light_intensity(light);
    }
    return sum;
}
