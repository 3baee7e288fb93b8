// Light records (host/scene/light_records.h).
#include "light_records.h"

#include <cmath>

namespace lc::loader {
namespace {

// A direction that can be normalised: finite, non-zero length.
bool usable_direction(glm::vec3 d) {
    const double length = std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
    return length > 0.0 && std::isfinite(length);
}

glm::vec3 normalised(glm::vec3 d) {
    const glm::dvec3 v(d);
    return glm::vec3(v / glm::length(v));
}

}  // namespace

const char* light_total_name(std::uint32_t type) {
    switch (type) {
        case gpu::kLightPoint: return "intensity of the point lights";
        case gpu::kLightDirectional: return "irradiance of the directional lights";
        case gpu::kLightSpot: return "intensity of the spot lights";
        case gpu::kLightOriented: return "intensity of the oriented lights";
        case gpu::kLightVpl: return "intensity of the virtual point lights";
        default: return "intensity of the lights";
    }
}

gpu::Light point_light(glm::vec3 position, glm::vec3 intensity) {
    gpu::Light l{};
    l.x = position.x; l.y = position.y; l.z = position.z;
    const glm::vec3 c = without_subnormals(intensity);
    l.r = c.r; l.g = c.g; l.b = c.b;
    l.type = gpu::kLightPoint;
    return l;
}

gpu::Light directional_light(glm::vec3 travel, glm::vec3 irradiance, LightProblem& problem) {
    if (!usable_direction(travel)) {
        problem = {"direction", "must not be zero-length"};
        return {};
    }
    gpu::Light l = point_light(-normalised(travel), irradiance);
    l.type = gpu::kLightDirectional;
    return l;
}

gpu::Light spot_light(glm::vec3 position, glm::vec3 direction, glm::vec3 intensity, float inner_degrees,
                      float outer_degrees, LightProblem& problem) {
    if (!usable_direction(direction)) {
        problem = {"direction", "must not be zero-length"};
        return {};
    }
    if (!(outer_degrees >= 0.0f && outer_degrees <= 90.0f)) {
        problem = {"outer_cone_degrees", "must be from 0 to 90"};
        return {};
    }
    if (!(inner_degrees >= 0.0f && inner_degrees <= outer_degrees)) {
        problem = {"inner_cone_degrees", "must be from 0 to outer_cone_degrees"};
        return {};
    }
    gpu::Light l = point_light(position, intensity);
    const glm::vec3 axis = normalised(direction);
    l.axis_x = axis.x; l.axis_y = axis.y; l.axis_z = axis.z;
    constexpr double kRadians = 3.14159265358979323846 / 180.0;
    l.cos_inner = float(std::cos(double(inner_degrees) * kRadians));
    l.cos_outer = float(std::cos(double(outer_degrees) * kRadians));
    l.type = gpu::kLightSpot;
    return l;
}

}  // namespace lc::loader
