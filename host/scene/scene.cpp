// Scene's own functions (lightcuts/scene.h): light counts and the geometry bounds.
#include "lightcuts/scene.h"

#include <algorithm>
#include <string>

#include "float_limits.h"
#include "input_file.h"
#include "lightcuts/error.h"

namespace lc {

std::size_t Scene::count_lights(std::uint32_t type) const {
    return static_cast<std::size_t>(
        std::count_if(lights.begin(), lights.end(), [type](const gpu::Light& l) { return l.type == type; }));
}

std::size_t Scene::count_emissive_triangles() const {
    return static_cast<std::size_t>(std::count_if(triangles.begin(), triangles.end(), [this](const gpu::Triangle& t) {
        return (materials[t.material].flags & gpu::kMaterialEmissive) != 0u;
    }));
}

// Lights stay out of the box: it scales the inverse-square clamp, and one
// far light must not change the clamp of the whole image.
void update_bounds(Scene& scene) {
    const auto fail = [&](std::size_t triangle, const std::string& problem) {
        const std::string file = scene.file.empty() ? "scene" : loader::display(scene.file);
        throw InputError(file, "triangles[" + std::to_string(triangle) + "]", problem);
    };
    loader::Box box;
    for (std::size_t i = 0; i < scene.triangles.size(); ++i) {
        const gpu::Triangle& t = scene.triangles[i];
        for (const glm::dvec3 p : {glm::dvec3(t.v0_x, t.v0_y, t.v0_z), glm::dvec3(t.v1_x, t.v1_y, t.v1_z),
                                   glm::dvec3(t.v2_x, t.v2_y, t.v2_z)}) {
            if (!loader::fits_float(p)) fail(i, "a vertex is not finite");
            box.grow(p);
        }
        // Every vertex can be a finite float while max - min is not.
        if (std::string problem = loader::extent_problem(box); !problem.empty()) fail(i, problem);
    }
    if (box.empty()) box.lo = box.hi = glm::dvec3(0.0);
    scene.bounds_min = glm::vec3(box.lo);
    scene.bounds_max = glm::vec3(box.hi);
}

}  // namespace lc
