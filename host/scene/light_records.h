// Light records from what a scene file gives, with the checks the JSON
// lights and the CSV rows share, so both refuse the same values with the
// same words.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include <glm/glm.hpp>

#include "lc_shared/types.h"

namespace lc::loader {

// What is wrong with a light's values: the field (relative to the light:
// "direction", "inner_cone_degrees", ...) and the problem; both empty when
// the light is fine.
struct LightProblem {
    std::string field;
    std::string problem;
    explicit operator bool() const { return !problem.empty(); }
};

// What a light type's r, g, b sum to, in words: "intensity of the point
// lights", "irradiance of the directional lights", ...
const char* light_total_name(std::uint32_t type);

// A colour with its subnormal channels (below the smallest normal float,
// 1.2e-38) made zero: every light's intensity goes through it, the loaded
// ones' (point_light) and the generated ones' (area-light samples, the
// environment's directions, VPLs). Their bounds lost the last bit (one in
// 10^4 came out below its lights' contribution), and arithmetic on them
// took brute force twice as long.
inline glm::vec3 without_subnormals(glm::vec3 c) {
    const auto normal = [](float v) { return std::abs(v) < std::numeric_limits<float>::min() ? 0.0f : v; };
    return {normal(c.r), normal(c.g), normal(c.b)};
}

gpu::Light point_light(glm::vec3 position, glm::vec3 intensity);

// `travel` is the way the light travels (non-zero); stored towards the light.
gpu::Light directional_light(glm::vec3 travel, glm::vec3 irradiance, LightProblem& problem);

// glTF-style spot: `direction` (non-zero, normalised here) is the axis it
// shines along, intensity is on the axis, half-angles in degrees with
// 0 <= inner <= outer <= 90.
gpu::Light spot_light(glm::vec3 position, glm::vec3 direction, glm::vec3 intensity, float inner_degrees,
                      float outer_degrees, LightProblem& problem);

}  // namespace lc::loader
