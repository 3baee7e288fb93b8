// Scene's own functions (lightcuts/scene.h): light counts and the bounds.
#include "lightcuts/scene.h"

#include <algorithm>
#include <limits>

namespace lc {

std::size_t Scene::count_lights(std::uint32_t type) const {
    return static_cast<std::size_t>(
        std::count_if(lights.begin(), lights.end(), [type](const gpu::Light& l) { return l.type == type; }));
}

void update_bounds(Scene& scene) {
    glm::vec3 lo(std::numeric_limits<float>::infinity());
    glm::vec3 hi(-std::numeric_limits<float>::infinity());
    const auto grow = [&](float x, float y, float z) {
        lo = glm::min(lo, glm::vec3(x, y, z));
        hi = glm::max(hi, glm::vec3(x, y, z));
    };
    for (const gpu::Triangle& t : scene.triangles) {
        grow(t.v0_x, t.v0_y, t.v0_z);
        grow(t.v1_x, t.v1_y, t.v1_z);
        grow(t.v2_x, t.v2_y, t.v2_z);
    }
    // Directional lights have no position; they do not widen the box.
    for (const gpu::Light& l : scene.lights) {
        if (l.type == gpu::kLightPoint) grow(l.x, l.y, l.z);
    }
    if (lo.x > hi.x) lo = hi = glm::vec3(0.0f);
    scene.bounds_min = lo;
    scene.bounds_max = hi;
}

}  // namespace lc
