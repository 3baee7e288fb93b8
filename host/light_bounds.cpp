// What the light tree needs to know of a light (host/light_bounds.h).
#include "light_bounds.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "lc_shared/octahedral.h"

namespace lc {
namespace {

constexpr float kPi = 3.14159265358979f;

float angle_between(glm::vec3 a, glm::vec3 b) {
    // Equal axes first, as the lights of one emissive surface and VPLs on
    // one wall have them: the answer is 0 either way, without the atan2.
    if (a == b) return 0.0f;
    // atan2 of |a x b| and a . b is accurate at all angles, unlike acos.
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

std::int32_t snorm16(float v) { return std::int32_t(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f)); }

std::uint32_t encode_octahedral(glm::vec3 v) {
    v /= std::abs(v.x) + std::abs(v.y) + std::abs(v.z);
    glm::vec2 e(v.x, v.y);
    if (v.z < 0.0f)
        e = glm::vec2((1.0f - std::abs(v.y)) * (v.x >= 0.0f ? 1.0f : -1.0f),
                      (1.0f - std::abs(v.x)) * (v.y >= 0.0f ? 1.0f : -1.0f));
    return (std::uint32_t(snorm16(e.x)) & 0xFFFFu) | (std::uint32_t(snorm16(e.y)) << 16);
}

}  // namespace

glm::vec3 tree_point(const gpu::Light& l) {
    switch (l.type & gpu::kLightTypeMask) {
        case gpu::kLightPoint:
        case gpu::kLightDirectional:
        case gpu::kLightSpot:
        case gpu::kLightOriented:
        case gpu::kLightVpl:
            return {l.x, l.y, l.z};
        default:
            throw std::invalid_argument("light tree: unknown light type " + std::to_string(l.type));
    }
}

EmissionCone EmissionCone::everywhere() {
    return EmissionCone{glm::vec3(0.0f, 0.0f, 1.0f), 3.14159265f, 1.57079633f, false, 1.0f};
}

EmissionCone EmissionCone::of_light(const gpu::Light& light) {
    EmissionCone cone = everywhere();
    switch (light.type & gpu::kLightTypeMask) {
        case gpu::kLightSpot:
            cone.axis = glm::vec3(light.axis_x, light.axis_y, light.axis_z);
            cone.theta_o = 0.0f;
            cone.theta_e = std::acos(std::clamp(light.cos_outer, -1.0f, 1.0f));
            cone.falloff_width = std::max(1e-3f, light.cos_inner - light.cos_outer);
            break;
        case gpu::kLightOriented:
        case gpu::kLightVpl:
            cone.axis = glm::vec3(light.axis_x, light.axis_y, light.axis_z);
            cone.theta_o = 0.0f;
            cone.theta_e = 0.5f * kPi;
            cone.two_sided = (light.type & gpu::kLightTwoSided) != 0u;
            break;
        default:
            break;
    }
    return cone;
}

EmissionCone cone_union(const EmissionCone& a, const EmissionCone& b) {
    EmissionCone u = EmissionCone::everywhere();
    u.theta_e = std::max(a.theta_e, b.theta_e);
    u.falloff_width = std::min(a.falloff_width, b.falloff_width);
    u.two_sided = a.two_sided || b.two_sided;
    if (a.emits_everywhere() || b.emits_everywhere()) return u;
    const float theta_d = angle_between(a.axis, b.axis);
    if (std::min(theta_d + b.theta_o, kPi) <= a.theta_o) {
        u.axis = a.axis;
        u.theta_o = a.theta_o;
        return u;
    }
    if (std::min(theta_d + a.theta_o, kPi) <= b.theta_o) {
        u.axis = b.axis;
        u.theta_o = b.theta_o;
        return u;
    }
    const float theta_o = 0.5f * (a.theta_o + theta_d + b.theta_o);
    const glm::vec3 w = glm::cross(a.axis, b.axis);
    if (theta_o >= kPi || glm::dot(w, w) == 0.0f) return u;  // everywhere
    // Turn a's axis towards b's by theta_o - theta_a.
    const glm::quat turn = glm::angleAxis(theta_o - a.theta_o, glm::normalize(w));
    u.axis = glm::normalize(turn * a.axis);
    // Rounding of the rotation: the union must still hold both cones.
    u.theta_o = std::max({theta_o, angle_between(u.axis, a.axis) + a.theta_o,
                          angle_between(u.axis, b.axis) + b.theta_o});
    return u;
}

ConeSpread ConeSpread::of(const EmissionCone& cone) {
    if (cone.emits_everywhere()) return ConeSpread{-2.0f, 0.0f, -1.0f};
    const float half = 0.5f * cone.theta_o;
    const float sin_half = std::sin(half);
    // 1 - 2 sin^2: accurate for the narrow cones, where 1 - cos beta is small.
    return ConeSpread{std::cos(half), sin_half, 1.0f - 2.0f * sin_half * sin_half};
}

EmissionCone quantized(const EmissionCone& cone, std::uint32_t& packed) {
    EmissionCone q = cone;
    packed = encode_octahedral(cone.axis);
    if (cone.emits_everywhere()) return q;
    q.axis = gpu::lc_decode_axis(packed);
    q.theta_o = std::min(kPi, cone.theta_o + angle_between(q.axis, cone.axis) + 1e-6f);
    return q;
}

}  // namespace lc
