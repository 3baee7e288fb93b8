// load_gltf_scene: a glTF file as a whole scene (gltf_loader.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "scene_check.h"
#include "float_limits.h"
#include "gltf_loader.h"
#include "input_file.h"
#include "lightcuts/error.h"

namespace lc::loader {
namespace {

// With no camera in the file: look along -Z at the bounding sphere of the
// triangles, which fills the default 40-degree view. In double: geometry
// near the float range puts that camera beyond it, which is an error
// naming the file.
Camera default_framing(const Scene& scene, const std::string& name) {
    const glm::dvec3 lo(scene.bounds_min), hi(scene.bounds_max);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    double radius = 0.5 * glm::length(hi - lo);
    if (!(radius > 0.0)) radius = 1.0;
    Camera c;
    c.fov_y_degrees = kDefaultFramingFovDegrees;
    const double distance = radius / std::sin(glm::radians(0.5 * double(c.fov_y_degrees)));
    const glm::dvec3 position = centre + glm::dvec3(0.0, 0.0, distance);
    if (!(std::abs(position.z) <= double(std::numeric_limits<float>::max())))
        throw InputError(name, "cameras",
                         "no perspective camera, and a default one framing geometry this large would stand "
                         "beyond the float range: add a camera");
    c.position = glm::vec3(position);
    c.look_at = glm::vec3(centre);
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    // Geometry far out along z, or about 1e19 across, leaves no float
    // camera that frames it (the position rounds onto the centre, or their
    // distance's square overflows): it rendered with a NaN view.
    if (const CameraProblem p = camera_problem(c); !p.field.empty())
        throw InputError(name, "cameras",
                         "no perspective camera, and a default one cannot frame this geometry in float (" + p.field +
                             " " + p.problem + "): add a camera");
    return c;
}

}  // namespace

Scene load_gltf_scene(const std::filesystem::path& file, const std::string& camera) {
    const std::string name = display(file);
    Scene scene;
    scene.file = file;
    // A glTF file has no render settings. Lightcuts, not the JSON default
    // brute force, which sums every light, the 65536 area-light samples of
    // any emissive surface included, at every pixel.
    scene.render.method = "lightcuts";
    MeshTarget target{scene, {}, {}, {}};
    const GltfContents contents = load_gltf(file, MeshTransform{}, target);

    LightLimits limits(target.geometry);
    for (const GltfLight& l : contents.lights) {
        const LightLimits::Problem p = limits.add(l.light);
        if (p.fault == LightLimits::Fault::total) throw InputError(name, "extensions.KHR_lights_punctual", p.text);
        if (p.fault == LightLimits::Fault::position) throw InputError(name, l.field, p.text);
        scene.lights.push_back(l.light);
    }
    bool emissive = false;
    for (const gpu::Material& m : scene.materials) emissive = emissive || (m.flags & gpu::kMaterialEmissive) != 0u;
    if (scene.lights.empty() && !emissive)
        throw InputError(name, "", "the scene has no light: no KHR_lights_punctual light and no emissive material");
    update_bounds(scene);

    if (!camera.empty()) {
        // The first in node order; a camera on several nodes, or several
        // cameras of one name, are each a match.
        const auto named = [&](const GltfCamera& c) { return c.name == camera; };
        const auto first = std::find_if(contents.cameras.begin(), contents.cameras.end(), named);
        if (first != contents.cameras.end()) {
            scene.camera = first->camera;
            if (const auto count = std::count_if(contents.cameras.begin(), contents.cameras.end(), named); count > 1)
                scene.load_notes.push_back(name + ": --camera: " + std::to_string(count) + " camera nodes are named '" +
                                           camera + "'; the first in node order is used");
            return scene;
        }
        for (const auto& [skipped, type] : contents.skipped_cameras)
            if (skipped == camera)
                throw InputError(name, "--camera", "'" + camera + "' is an " + type +
                                                       " camera; only perspective cameras are read");
        std::string names;
        for (const GltfCamera& c : contents.cameras) names += (names.empty() ? "" : ", ") + ("'" + c.name + "'");
        throw InputError(name, "--camera", "no perspective camera named '" + camera + "' (the file has " +
                                               (names.empty() ? std::string("none") : names) + ")");
    }
    scene.camera = contents.cameras.empty() ? default_framing(scene, name) : contents.cameras.front().camera;
    if (contents.cameras.empty())
        scene.load_notes.push_back(name + ": no perspective camera; looking along -Z at the bounding sphere (40 degrees)");
    return scene;
}

}  // namespace lc::loader
