// Scene's own functions (lightcuts/scene.h): light counts and the geometry bounds.
#include "lightcuts/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>

#include "scene_check.h"
#include "float_limits.h"
#include "input_file.h"
#include "lightcuts/error.h"
#include "lightcuts/settings.h"
#include "light_records.h"

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
namespace {

// The box around the triangles; throws InputError naming the triangle
// whose vertex is not finite or that takes the extent past kMaxExtent.
loader::Box geometry_box(const Scene& scene) {
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
    return box;
}

}  // namespace

void update_bounds(Scene& scene) {
    const loader::Box box = geometry_box(scene);
    scene.bounds_min = glm::vec3(box.lo);
    scene.bounds_max = glm::vec3(box.hi);
}

namespace loader {

CameraProblem camera_problem(const Camera& cam) {
    const glm::dvec3 position(cam.position), look_at(cam.look_at), up(cam.up);
    if (!fits_float(position)) return {"camera.position", "must be finite"};
    if (!fits_float(look_at)) return {"camera.look_at", "must be finite"};
    if (!fits_float(up)) return {"camera.up", "must be finite"};
    // The kernels take the view direction in float.
    const glm::vec3 forward = cam.look_at - cam.position;
    const float forward_len = glm::length(forward);
    if (!std::isfinite(forward_len))
        return {"camera.look_at", "is too far from camera.position (the square of their distance overflows a float: "
                                  "at most about 1.8e19 apart)"};
    if (!(forward_len > 0.0f))
        return {"camera.look_at", forward == glm::vec3(0.0f)
                                      ? "must differ from camera.position"
                                      : "is too close to camera.position (the square of their distance underflows a "
                                        "float: at least about 3e-23 apart)"};
    // In double: the square of a float as small as 1e-30 (or as large as
    // 1e30) is out of float range, and up's length only sets its direction.
    const double up_len = glm::length(up);
    if (!(up_len > 0.0)) return {"camera.up", "must not be zero"};
    const double sin_angle = glm::length(glm::cross(glm::dvec3(forward) / double(forward_len), up / up_len));
    if (!(sin_angle > 1e-6)) return {"camera.up", "must not be parallel to the view direction"};
    return {};
}

}  // namespace loader

namespace {

bool finite3(float x, float y, float z) { return std::isfinite(x) && std::isfinite(y) && std::isfinite(z); }
bool in_unit(float v) { return v >= 0.0f && v <= 1.0f; }

// What is wrong with a light on its own: a field to add to "lights[i]" and
// the problem; a null problem where nothing is.
struct LightFault {
    const char* field = "";
    const char* problem = nullptr;
};

LightFault light_problem(const gpu::Light& l) {
    const std::uint32_t type = l.type & gpu::kLightTypeMask;
    if (type >= gpu::kLightTypeCount || (l.type & ~(gpu::kLightTypeMask | gpu::kLightTwoSided)) != 0u)
        return {".type", "is not a light type (kLightPoint ... kLightVpl, kLightTwoSided)"};
    if (!finite3(l.x, l.y, l.z)) return {"", "position or direction is not finite"};
    if (!(l.r >= 0.0f && l.g >= 0.0f && l.b >= 0.0f && finite3(l.r, l.g, l.b)))
        return {"", "intensity must be finite and not negative"};
    const auto unit = [](float x, float y, float z) {
        return std::abs(std::sqrt(double(x) * x + double(y) * y + double(z) * z) - 1.0) <= 1e-3;
    };
    if (type == gpu::kLightDirectional && !unit(l.x, l.y, l.z))
        return {"", "a directional light's x, y, z is the unit vector towards it"};
    if ((type == gpu::kLightSpot || type == gpu::kLightOriented || type == gpu::kLightVpl) &&
        !unit(l.axis_x, l.axis_y, l.axis_z))
        return {".axis", "must be a unit vector"};
    if (type == gpu::kLightSpot && !(l.cos_outer >= -1.0f && l.cos_outer <= l.cos_inner && l.cos_inner <= 1.0f))
        return {"", "a spot's cosines must satisfy -1 <= cos_outer <= cos_inner <= 1"};
    return {};
}

}  // namespace

void check_scene(const Scene& scene) { loader::check_scene_geometry(scene); }

loader::Box loader::check_scene_geometry(const Scene& scene) {
    const std::string file = scene.file.empty() ? "scene" : loader::display(scene.file);
    const auto fail = [&](const std::string& field, const std::string& problem) {
        throw InputError(file, field, problem);
    };
    if (const loader::CameraProblem p = loader::camera_problem(scene.camera); !p.field.empty()) fail(p.field, p.problem);
    const Camera& cam = scene.camera;
    if (!(cam.fov_y_degrees > 0.0f && cam.fov_y_degrees < 180.0f))
        fail("camera.fov_y_degrees", "must be above 0 and below 180");
    for (const auto& [side, field] : {std::pair{cam.width, "camera.width"}, {cam.height, "camera.height"}})
        if (side < 1 || side > kMaxImageSide)
            fail(field, "must be from 1 to " + std::to_string(kMaxImageSide) + ", got " + std::to_string(side));

    const std::size_t triangles = scene.triangles.size();
    if (scene.normals.size() != triangles)
        fail("normals", "holds " + std::to_string(scene.normals.size()) + " entries for " + std::to_string(triangles) +
                            " triangles (one per triangle)");
    if (!scene.uvs.empty() && scene.uvs.size() != triangles)
        fail("uvs", "holds " + std::to_string(scene.uvs.size()) + " entries for " + std::to_string(triangles) +
                        " triangles (one per triangle, or none)");
    for (std::size_t i = 0; i < triangles; ++i) {
        const std::uint32_t m = scene.triangles[i].material;
        if (m >= scene.materials.size())
            fail("triangles[" + std::to_string(i) + "].material",
                 "is " + std::to_string(m) + "; the scene has " + std::to_string(scene.materials.size()) +
                     " materials");
        const gpu::TriangleNormals& n = scene.normals[i];
        if (!finite3(n.n0_x, n.n0_y, n.n0_z) || !finite3(n.n1_x, n.n1_y, n.n1_z) || !finite3(n.n2_x, n.n2_y, n.n2_z))
            fail("normals[" + std::to_string(i) + "]", "must be finite");
    }
    for (std::size_t i = 0; i < scene.uvs.size(); ++i) {
        const gpu::TriangleUvs& uv = scene.uvs[i];
        if (!finite3(uv.u0, uv.v0, uv.u1) || !finite3(uv.v1, uv.u2, uv.v2))
            fail("uvs[" + std::to_string(i) + "]", "must be finite");
    }

    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
        const gpu::Material& m = scene.materials[i];
        const std::string name = "materials[" + std::to_string(i) + "].";
        for (const auto& [v, field] : {std::pair{m.kd_r, "kd_r"}, {m.kd_g, "kd_g"}, {m.kd_b, "kd_b"}, {m.ks_r, "ks_r"},
                                       {m.ks_g, "ks_g"}, {m.ks_b, "ks_b"}, {m.roughness, "roughness"},
                                       {m.metallic, "metallic"}, {m.specular, "specular"},
                                       {m.specular_tint, "specular_tint"}, {m.sheen, "sheen"},
                                       {m.sheen_tint, "sheen_tint"}, {m.clearcoat, "clearcoat"},
                                       {m.clearcoat_gloss, "clearcoat_gloss"}})
            if (!in_unit(v)) fail(name + field, "must be from 0 to 1");
        // The GGX and Disney lobes' width; a Lambert material has none.
        const bool glossy = (m.flags & (gpu::kMaterialHasSpecular | gpu::kMaterialDisney)) != 0u;
        if (glossy && !(m.alpha > 0.0f && m.alpha <= 1.0f)) fail(name + "alpha", "must be above 0 and at most 1");
        for (const auto& [v, field] :
             {std::pair{m.emission_r, "emission_r"}, {m.emission_g, "emission_g"}, {m.emission_b, "emission_b"}})
            if (!(v >= 0.0f && std::isfinite(v))) fail(name + field, "must be finite and not negative");
        if (!std::isfinite(m.normal_scale)) fail(name + "normal_scale", "must be finite");
        // The kernels read a material's textures only where it is textured.
        const bool textured = (m.flags & gpu::kMaterialTextured) != 0u;
        for (const auto& [t, field] : {std::pair{m.base_color_texture, "base_color_texture"},
                                       {m.metallic_roughness_texture, "metallic_roughness_texture"},
                                       {m.emissive_texture, "emissive_texture"}, {m.normal_texture, "normal_texture"}})
            if (textured && t != gpu::kInvalidIndex && t >= scene.textures.size())
                fail(name + field, "is " + std::to_string(t) + "; the scene has " +
                                       std::to_string(scene.textures.size()) + " textures");
    }
    for (std::size_t i = 0; i < scene.textures.size(); ++i) {
        const gpu::TextureInfo& t = scene.textures[i];
        const std::string name = "textures[" + std::to_string(i) + "]";
        if (t.width < 1 || t.height < 1) fail(name, "must be at least 1 x 1 texels");
        if (std::uint64_t(t.offset) + std::uint64_t(t.width) * t.height > scene.texels.size())
            fail(name, "reaches past the " + std::to_string(scene.texels.size()) + " texels");
        for (const float v : t.uv_transform)
            if (!std::isfinite(v)) fail(name + ".uv_transform", "must be finite");
    }

    // What prepare_scene makes lights of: the environment, and the counts
    // of the render block it reads (the rest are checked at each render).
    const Environment& env = scene.environment;
    if (env.present()) {
        const std::uint64_t pixels = std::uint64_t(env.width) * env.height;
        if (pixels > kMaxEnvironmentPixels)
            fail("environment", "is " + std::to_string(env.width) + " x " + std::to_string(env.height) +
                                    " pixels, more than the " + std::to_string(kMaxEnvironmentPixels) + " it may hold");
        if (env.rgb.size() != pixels * 3)
            fail("environment.rgb", "holds " + std::to_string(env.rgb.size()) + " values for " +
                                        std::to_string(env.width) + " x " + std::to_string(env.height) +
                                        " pixels (three each)");
        for (std::size_t i = 0; i < env.rgb.size(); ++i)
            if (!(env.rgb[i] >= 0.0f && std::isfinite(env.rgb[i])))
                fail("environment.rgb[" + std::to_string(i) + "]", "radiance must be finite and not negative");
        // 0: no lights made of it (what the command line asks for the path
        // tracer, which samples the map itself).
        if (const std::string p = setting_problem(kSettingDirections, env.directions);
            env.directions != 0 && !p.empty())
            fail("environment.directions", p);
    }
    // (area_light_samples 0: none made, as for the path tracer.)
    const IndirectSettings& indirect = scene.render.indirect;
    for (const auto& [key, value, field] :
         {std::tuple{kSettingAreaLightSamples, double(scene.render.area_light_samples), "render.area_light_samples"},
          {kSettingVpls, double(indirect.vpls), "render.indirect.vpls"},
          {kSettingMaxBounces, double(indirect.max_bounces), "render.indirect.max_bounces"},
          {kSettingClamp, double(indirect.clamp), "render.indirect.clamp"}})
        if (const std::string p = setting_problem(key, value);
            !p.empty() && !(key == kSettingAreaLightSamples && value == 0.0))
            fail(field, p);

    // The lights as the loaders make them, and the totals they check: in
    // one pass that names nothing (10^7 lights from a file, which the loader
    // has checked already, take about 0.12 s of the 8 to 10 s their render
    // takes; 0.38 s when each light's name was made as it was checked), and
    // where it finds a fault, again light by light to name the first.
    const loader::Box geometry = geometry_box(scene);
    std::array<glm::dvec3, gpu::kLightTypeCount> totals{};
    loader::Box box = geometry;
    bool fine = true;
    for (const gpu::Light& l : scene.lights) {
        if (light_problem(l).problem != nullptr) {
            fine = false;
            break;
        }
        const std::uint32_t type = l.type & gpu::kLightTypeMask;
        totals[type] += glm::dvec3(l.r, l.g, l.b);
        if (type != gpu::kLightDirectional) box.grow(glm::dvec3(l.x, l.y, l.z));
    }
    for (const glm::dvec3& t : totals) fine = fine && loader::fits_float(t);
    if (fine && loader::extent_problem(box).empty()) return geometry;
    loader::LightLimits limits(geometry);
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const gpu::Light& l = scene.lights[i];
        const std::string name = "lights[" + std::to_string(i) + "]";
        if (const LightFault f = light_problem(l); f.problem != nullptr) fail(name + f.field, f.problem);
        if (const loader::LightLimits::Problem p = limits.add(l); p.fault != loader::LightLimits::Fault::none)
            fail(p.fault == loader::LightLimits::Fault::total ? "lights" : name, p.text);
    }
    return geometry;
}

}  // namespace lc
