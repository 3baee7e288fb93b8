// Area-light sampling (host/area_lights.h).
#include "area_lights.h"

#include <cmath>

#include <glm/glm.hpp>

#include "shared/color.h"

namespace lc {
namespace {

glm::vec3 vertex(const gpu::Triangle& t, int i) {
    return i == 0 ? glm::vec3(t.v0_x, t.v0_y, t.v0_z)
                  : i == 1 ? glm::vec3(t.v1_x, t.v1_y, t.v1_z) : glm::vec3(t.v2_x, t.v2_y, t.v2_z);
}

glm::vec3 emission(const gpu::Material& m) { return {m.emission_r, m.emission_g, m.emission_b}; }

bool emits(const gpu::Material& m) { return (m.flags & gpu::kMaterialEmissive) != 0u; }

// Radical inverse in base 2 (van der Corput): with (k + jitter) / m in the
// other coordinate, m points stratified over the unit square.
float radical_inverse(std::uint32_t k) {
    std::uint32_t bits = k;
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return float(bits) * 2.3283064e-10f;
}

// m stratified samples on one triangle, appended to `out`.
void sample_triangle(const gpu::Triangle& t, const gpu::Material& m, std::uint32_t samples,
                     std::uint32_t hash, std::vector<gpu::Light>& out) {
    const glm::vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
    const glm::vec3 cross = glm::cross(b - a, c - a);
    const float area = 0.5f * glm::length(cross);
    const glm::vec3 normal = glm::normalize(cross);
    const glm::vec3 intensity = emission(m) * (area / float(samples));
    // A random shift of the whole pattern (Cranley-Patterson rotation).
    const float shift_u = gpu::lc_unit_float(hash), shift_v = gpu::lc_unit_float(gpu::lc_hash(hash));
    for (std::uint32_t k = 0; k < samples; ++k) {
        const float u = std::fmod((float(k) + 0.5f) / float(samples) + shift_u, 1.0f);
        const float v = std::fmod(radical_inverse(k) + shift_v, 1.0f);
        // Area-preserving square-to-triangle map (Shirley and Chiu).
        const float su = std::sqrt(u);
        const glm::vec3 p = (1.0f - su) * a + su * (1.0f - v) * b + su * v * c;
        gpu::Light l{};
        l.x = p.x; l.y = p.y; l.z = p.z;
        l.r = intensity.x; l.g = intensity.y; l.b = intensity.z;
        l.axis_x = normal.x; l.axis_y = normal.y; l.axis_z = normal.z;
        l.type = gpu::kLightOriented | ((m.flags & gpu::kMaterialEmitsBothSides) ? gpu::kLightTwoSided : 0u);
        out.push_back(l);
    }
}

}  // namespace

std::vector<gpu::Light> sample_area_lights(std::span<const gpu::Triangle> triangles,
                                           std::span<const gpu::Material> materials, std::uint32_t count,
                                           std::uint32_t seed) {
    // Power of each emitting triangle, in double: many small triangles add up.
    std::vector<double> power(triangles.size(), 0.0);
    double total = 0.0;
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        const gpu::Triangle& t = triangles[i];
        const gpu::Material& m = materials[t.material];
        if (!emits(m)) continue;
        const double area = 0.5 * double(glm::length(glm::cross(vertex(t, 1) - vertex(t, 0), vertex(t, 2) - vertex(t, 0))));
        const double sides = (m.flags & gpu::kMaterialEmitsBothSides) ? 2.0 : 1.0;
        power[i] = double(gpu::lc_luminance(emission(m))) * area * sides;
        total += power[i];
    }
    std::vector<gpu::Light> lights;
    if (!(total > 0.0) || count == 0) return lights;
    lights.reserve(count);
    // Systematic sampling: sample k stands at (k + offset) / count of the
    // cumulative power; a triangle gets the samples that fall on its share.
    const double offset = gpu::lc_unit_float(gpu::lc_hash(seed ^ 0x9E3779B9u));
    std::size_t last_emitter = 0;
    for (std::size_t i = 0; i < triangles.size(); ++i)
        if (power[i] > 0.0) last_emitter = i;
    double before = 0.0;
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        if (power[i] <= 0.0) continue;
        // The last share ends at the total exactly, so no sample is lost to rounding.
        const double after = i == last_emitter ? total : before + power[i];
        const double first = std::floor(before / total * count - offset + 1.0);
        const double last = std::floor(after / total * count - offset + 1.0);
        before = after;
        const auto samples = std::uint32_t(std::max(0.0, last - first));
        if (samples == 0) continue;
        sample_triangle(triangles[i], materials[triangles[i].material], samples,
                        gpu::lc_hash(seed ^ gpu::lc_hash(std::uint32_t(i))), lights);
    }
    return lights;
}

}  // namespace lc
