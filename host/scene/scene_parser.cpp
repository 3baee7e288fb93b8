// load_scene: the scene JSON (docs/scene-format.md) into a Scene: camera,
// meshes, lights, render settings.
//
// Every problem with the input becomes an lc::InputError naming the file and
// the field, so a user can fix a scene without reading this code. The scene is
// built in a local value and only returned when complete, so a throw can never
// leave a half-loaded scene behind.
#include "lightcuts/scene.h"

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "csv_lights.h"
#include "float_limits.h"
#include "input_file.h"
#include "json_reader.h"
#include "lightcuts/settings.h"
#include "materials.h"
#include "obj_loader.h"

namespace lc {
namespace loader {
namespace {

namespace fs = std::filesystem;

class SceneParser {
public:
    explicit SceneParser(const fs::path& file) : file_(file), dir_(file.parent_path()), in_(display(file)) {}

    Scene parse() {
        const json root = parse_json_file(file_);
        in_.expect_object(root, "");
        in_.check_keys(root, "", {"description", "camera", "meshes", "lights", "render"});
        if (const json* d = JsonReader::find(root, "description")) in_.string(*d, "description");

        scene_.file = file_;
        parse_camera(in_.require(root, "", "camera"));
        // Meshes before lights: the lights' extent is checked against the geometry.
        parse_meshes(in_.require(root, "", "meshes"));
        parse_lights(in_.require(root, "", "lights"));
        if (const json* r = JsonReader::find(root, "render")) parse_render(*r);
        update_bounds(scene_);
        return std::move(scene_);
    }

private:
    fs::path file_;
    fs::path dir_;
    JsonReader in_;
    Scene scene_;
    MeshTarget meshes_{scene_, {}, {}};
    LightLimits limits_;

    fs::path resolve(const std::string& relative) const { return dir_ / relative; }

    void parse_camera(const json& j) {
        const std::string path = "camera";
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"position", "look_at", "up", "fov_y_degrees", "width", "height"});
        Camera& cam = scene_.camera;
        cam.position = in_.vec3(in_.require(j, path, "position"), "camera.position");
        cam.look_at = in_.vec3(in_.require(j, path, "look_at"), "camera.look_at");
        if (const json* v = JsonReader::find(j, "up")) cam.up = in_.vec3(*v, "camera.up");
        if (const json* v = JsonReader::find(j, "fov_y_degrees")) {
            cam.fov_y_degrees = in_.number_in(*v, "camera.fov_y_degrees", 0.0f, 180.0f, true, true);
        }
        if (const json* v = JsonReader::find(j, "width")) {
            cam.width = in_.unsigned_int(*v, "camera.width", 1, kMaxImageSide);
        }
        if (const json* v = JsonReader::find(j, "height")) {
            cam.height = in_.unsigned_int(*v, "camera.height", 1, kMaxImageSide);
        }

        // The camera basis is cross(forward, up): both must be usable.
        const glm::vec3 forward = cam.look_at - cam.position;
        const float forward_len = glm::length(forward);
        if (!(forward_len > 0.0f) || !std::isfinite(forward_len)) {
            in_.fail("camera.look_at", "must differ from camera.position");
        }
        const float up_len = glm::length(cam.up);
        if (!(up_len > 0.0f) || !std::isfinite(up_len)) in_.fail("camera.up", "must not be zero");
        const float sin_angle = glm::length(glm::cross(forward / forward_len, cam.up / up_len));
        if (!(sin_angle > 1e-6f)) in_.fail("camera.up", "must not be parallel to the view direction");
    }

    // Ranges and problem texts come from lightcuts/settings.h, so a value is
    // judged here exactly as on the command line.
    void parse_render(const json& j) {
        const std::string path = "render";
        in_.expect_object(j, path);
        in_.check_keys(j, path, {kSettingMethod, kSettingSpp, kSettingRelativeError, kSettingMaxCut, kSettingSeed});
        RenderSettings& r = scene_.render;
        if (const json* v = JsonReader::find(j, kSettingMethod)) {
            const std::string field = join_key(path, kSettingMethod);
            r.method = in_.string(*v, field);
            if (const std::string problem = method_problem(r.method); !problem.empty()) in_.fail(field, problem);
        }
        const auto setting = [&](std::string_view key) -> std::optional<double> {
            const json* v = JsonReader::find(j, key);
            if (!v) return std::nullopt;
            const std::string field = join_key(path, key);
            const double value = in_.number_value(*v, field);
            if (const std::string problem = setting_problem(key, value); !problem.empty()) in_.fail(field, problem);
            return value;
        };
        if (const auto v = setting(kSettingSpp)) r.spp = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingRelativeError)) r.relative_error = static_cast<float>(*v);
        if (const auto v = setting(kSettingMaxCut)) r.max_cut = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingSeed)) r.seed = static_cast<std::uint32_t>(*v);
    }

    // -- meshes -------------------------------------------------------------

    MeshTransform parse_transform(const json& j, const std::string& path) const {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"translate", "rotate_degrees", "scale"});
        glm::vec3 translate{0.0f}, rotate{0.0f}, scale{1.0f};
        if (const json* v = JsonReader::find(j, "translate")) translate = in_.vec3(*v, path + ".translate");
        if (const json* v = JsonReader::find(j, "rotate_degrees")) rotate = in_.vec3(*v, path + ".rotate_degrees");
        if (const json* v = JsonReader::find(j, "scale")) {
            const std::string field = path + ".scale";
            scale = v->is_array() ? in_.vec3(*v, field) : glm::vec3(in_.number(*v, field));
            for (int i = 0; i < 3; ++i) {
                if (scale[i] == 0.0f) {
                    in_.fail(v->is_array() ? join_index(field, static_cast<std::size_t>(i)) : field,
                             "must not be zero");
                }
            }
        }
        // M = T * Rz * Ry * Rx * S: scale first, then rotate about X, Y, Z, then translate.
        glm::mat4 m = glm::translate(glm::mat4(1.0f), translate);
        m = glm::rotate(m, glm::radians(rotate.z), glm::vec3(0, 0, 1));
        m = glm::rotate(m, glm::radians(rotate.y), glm::vec3(0, 1, 0));
        m = glm::rotate(m, glm::radians(rotate.x), glm::vec3(1, 0, 0));
        m = glm::scale(m, scale);
        MeshTransform t;
        t.position = m;
        t.normal = glm::inverseTranspose(glm::mat3(m));
        t.mirrors = scale.x * scale.y * scale.z < 0.0f;
        return t;
    }

    gpu::Material parse_material_override(const json& j, const std::string& path) const {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"kd", "ks", "roughness"});
        glm::vec3 kd{kDefaultAlbedo}, ks{0.0f};
        float roughness = kDefaultRoughness;
        if (const json* v = JsonReader::find(j, "kd")) kd = in_.colour(*v, path + ".kd", 1.0f);
        if (const json* v = JsonReader::find(j, "ks")) ks = in_.colour(*v, path + ".ks", 1.0f);
        if (const json* v = JsonReader::find(j, "roughness")) {
            roughness = in_.number_in(*v, path + ".roughness", 0.0f, 1.0f, true, false);
        }
        return make_material(kd, ks, roughness * roughness);
    }

    void parse_meshes(const json& j) {
        in_.expect_array(j, "meshes");
        if (j.empty()) in_.fail("meshes", "must contain at least one mesh");
        for (std::size_t i = 0; i < j.size(); ++i) parse_mesh(j[i], join_index("meshes", i));
    }

    void parse_mesh(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"obj", "transform", "material"});
        const std::string obj_field = path + ".obj";
        const fs::path obj_path = resolve(in_.string(in_.require(j, path, "obj"), obj_field));
        MeshTransform transform;
        if (const json* t = JsonReader::find(j, "transform")) transform = parse_transform(*t, path + ".transform");
        std::optional<gpu::Material> override_material;
        if (const json* m = JsonReader::find(j, "material")) {
            override_material = parse_material_override(*m, path + ".material");
        }

        std::error_code ec;
        if (!fs::is_regular_file(obj_path, ec)) in_.fail(obj_field, "file not found: " + display(obj_path));
        load_obj(obj_path, transform, override_material, meshes_);
    }

    // -- lights -------------------------------------------------------------

    void parse_lights(const json& j) {
        in_.expect_array(j, "lights");
        limits_ = LightLimits(meshes_.geometry);
        for (std::size_t i = 0; i < j.size(); ++i) parse_light(j[i], join_index("lights", i));
        if (scene_.lights.empty()) in_.fail("lights", "the scene has no lights (after loading CSV files)");
    }

    // A total that overflows is the list's fault, not one entry's; a position
    // too far out is the fault of the light that has it.
    void add_light(const gpu::Light& light, const std::string& path) {
        const LightLimits::Problem p = limits_.add(light);
        if (p.fault == LightLimits::Fault::total) in_.fail("lights", p.text);
        if (p.fault == LightLimits::Fault::position) in_.fail(path + ".position", p.text);
        scene_.lights.push_back(light);
    }

    void parse_light(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        const std::string type = in_.string(in_.require(j, path, "type"), path + ".type");
        constexpr float kMaxFloat = std::numeric_limits<float>::max();
        if (type == "point") {
            in_.check_keys(j, path, {"type", "position", "intensity"});
            const glm::vec3 p = in_.vec3(in_.require(j, path, "position"), path + ".position");
            const glm::vec3 c = in_.colour(in_.require(j, path, "intensity"), path + ".intensity", kMaxFloat);
            add_light({p.x, p.y, p.z, c.r, c.g, c.b, gpu::kLightPoint, 0u}, path);
        } else if (type == "directional") {
            in_.check_keys(j, path, {"type", "direction", "irradiance"});
            const glm::vec3 d = in_.vec3(in_.require(j, path, "direction"), path + ".direction");
            const float len = glm::length(d);
            if (!(len > 0.0f) || !std::isfinite(len)) in_.fail(path + ".direction", "must not be zero-length");
            const glm::vec3 c = in_.colour(in_.require(j, path, "irradiance"), path + ".irradiance", kMaxFloat);
            // The file gives the way light travels; shading wants the way to the light.
            const glm::vec3 to_light = -d / len;
            add_light({to_light.x, to_light.y, to_light.z, c.r, c.g, c.b, gpu::kLightDirectional, 0u}, path);
        } else if (type == "points_csv") {
            in_.check_keys(j, path, {"type", "file"});
            const std::string field = path + ".file";
            const fs::path csv = resolve(in_.string(in_.require(j, path, "file"), field));
            std::error_code ec;
            if (!fs::is_regular_file(csv, ec)) in_.fail(field, "file not found: " + display(csv));
            const std::vector<gpu::Light> loaded = read_points_csv(csv, limits_);
            scene_.lights.insert(scene_.lights.end(), loaded.begin(), loaded.end());
        } else {
            in_.fail(path + ".type", "unknown light type \"" + type + "\" (expected point, directional or points_csv)");
        }
    }
};

}  // namespace
}  // namespace loader

Scene load_scene(const std::filesystem::path& file) { return loader::SceneParser(file).parse(); }

}  // namespace lc
