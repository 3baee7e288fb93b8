// load_scene: the scene JSON (docs/scene-format.md) into a Scene: camera,
// meshes, lights, render settings.
//
// Every problem with the input becomes an lc::InputError naming the file and
// the field, so a user can fix a scene without reading this code. The scene is
// built in a local value and only returned when complete, so a throw can never
// leave a half-loaded scene behind.
#include "lightcuts/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "scene_check.h"
#include "csv_lights.h"
#include "float_limits.h"
#include "gltf_loader.h"
#include "input_file.h"
#include "json_reader.h"
#include "light_records.h"
#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "lightcuts/settings.h"
#include "materials.h"
#include "obj_loader.h"

namespace lc {
namespace loader {
namespace {

namespace fs = std::filesystem;

class SceneParser {
public:
    SceneParser(const fs::path& file, unsigned threads)
        : file_(file), dir_(file.parent_path()), in_(display(file)), threads_(threads) {}

    Scene parse() {
        const json root = parse_json_file(file_);
        in_.expect_object(root, "");
        in_.check_keys(root, "", {"description", "camera", "meshes", "lights", "render"});
        if (const json* d = JsonReader::find(root, "description")) in_.string(*d, "description");

        scene_.file = file_;
        parse_camera(in_.require(root, "", "camera"));
        // Meshes before lights: the lights' extent is checked against the geometry.
        parse_meshes(in_.require(root, "", "meshes"));
        // glTF meshes bring UVs; OBJ meshes after them have none.
        if (!scene_.uvs.empty()) scene_.uvs.resize(scene_.triangles.size());
        limits_ = LightLimits(meshes_.geometry);
        add_gltf_lights();
        if (const json* l = JsonReader::find(root, "lights")) parse_lights(*l);
        if (const json* r = JsonReader::find(root, "render")) parse_render(*r);
        require_some_light();
        update_bounds(scene_);
        return std::move(scene_);
    }

private:
    fs::path file_;
    fs::path dir_;
    JsonReader in_;
    unsigned threads_;  // SceneOptions::threads
    Scene scene_;
    MeshTarget meshes_{scene_, {}, {}, {}};
    LightLimits limits_;
    // The lights of the glTF meshes, with the file each came from; they
    // join the scene's lights before the "lights" list.
    std::vector<std::pair<std::string, GltfLight>> gltf_lights_;

    // "FIELD: file not found: FILE", or "FIELD: 'FILE' is a folder, not a
    // file" and so on, where `file` cannot be read (input_file_problem).
    void check_input_file(const fs::path& file, const std::string& field) const {
        const std::string problem = input_file_problem(file);
        if (problem == kFileNotFound) in_.fail(field, "file not found: " + display(file));
        if (!problem.empty()) in_.fail(field, "'" + display(file) + "' " + problem);
    }

    // A file the scene names, relative to the scene's folder. A NUL would
    // end the name where the system reads it, and another file be opened.
    fs::path resolve(const std::string& relative, const std::string& field) const {
        if (relative.empty()) in_.fail(field, "is empty: it must name a file");
        if (relative.find('\0') != std::string::npos) in_.fail(field, "the file name contains a NUL character");
        return dir_ / relative;
    }

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
        // Checked as --width and --height are, with the same message.
        if (const auto v = number_setting(j, path, kSettingWidth)) cam.width = static_cast<std::uint32_t>(*v);
        if (const auto v = number_setting(j, path, kSettingHeight)) cam.height = static_cast<std::uint32_t>(*v);

        // The camera basis is cross(forward, up): both must be usable.
        if (const CameraProblem p = camera_problem(cam); !p.field.empty()) in_.fail(p.field, p.problem);
        // Kept as a unit vector, so the camera's basis (prepare.cpp) is
        // computed from floats of ordinary size (up's length taken in
        // double: the square of a float as small as 1e-30 is out of range).
        const glm::dvec3 up(cam.up);
        cam.up = glm::vec3(up / glm::length(up));
    }

    // Ranges and problem texts come from lightcuts/settings.h, so a value is
    // judged here exactly as on the command line.
    void parse_render(const json& j) {
        const std::string path = "render";
        in_.expect_object(j, path);
        in_.check_keys(j, path, {kSettingMethod, kSettingSpp, kSettingRelativeError, kSettingMaxCut, kSettingCutHeap,
                                 kSettingSeed, kSettingAreaLightSamples, kSettingLightSamples, kSettingLightPick,
                                 kSettingCutSharing, kSettingMaxBounces, kSettingTimeLimit, kSettingIndirect});
        RenderSettings& r = scene_.render;
        if (const json* v = JsonReader::find(j, kSettingMethod)) {
            const std::string field = join_key(path, kSettingMethod);
            r.method = in_.string(*v, field);
            if (const std::string problem = method_problem(r.method); !problem.empty()) in_.fail(field, problem);
        }
        if (const json* v = JsonReader::find(j, kSettingLightPick)) {
            const std::string field = join_key(path, kSettingLightPick);
            r.light_pick = in_.string(*v, field);
            if (const std::string problem = light_pick_problem(r.light_pick); !problem.empty()) in_.fail(field, problem);
        }
        if (const json* v = JsonReader::find(j, kSettingCutSharing)) {
            const std::string field = join_key(path, kSettingCutSharing);
            r.cut_sharing = in_.string(*v, field);
            if (const std::string problem = cut_sharing_problem(r.cut_sharing); !problem.empty())
                in_.fail(field, problem);
        }
        const auto setting = [&](std::string_view key) { return number_setting(j, path, key); };
        if (const auto v = setting(kSettingSpp)) r.spp = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingRelativeError)) r.relative_error = static_cast<float>(*v);
        if (const auto v = setting(kSettingMaxCut)) r.max_cut = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingCutHeap)) r.cut_heap = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingSeed)) r.seed = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingAreaLightSamples)) r.area_light_samples = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingLightSamples)) r.light_samples = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingMaxBounces)) r.max_bounces = static_cast<std::uint32_t>(*v);
        if (const auto v = setting(kSettingTimeLimit)) r.time_limit = *v;
        if (const json* v = JsonReader::find(j, kSettingIndirect)) parse_indirect(*v, join_key(path, kSettingIndirect));
    }

    // render.indirect: {"vpls": N, "max_bounces": B, "clamp": D}.
    void parse_indirect(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {kSettingVpls, kSettingMaxBounces, kSettingClamp});
        IndirectSettings& ind = scene_.render.indirect;
        if (const auto v = number_setting(j, path, kSettingVpls)) ind.vpls = static_cast<std::uint32_t>(*v);
        if (const auto v = number_setting(j, path, kSettingMaxBounces)) ind.max_bounces = static_cast<std::uint32_t>(*v);
        if (const auto v = number_setting(j, path, kSettingClamp)) ind.clamp = static_cast<float>(*v);
    }

    // The number at j[key], checked by setting_problem; nullopt when absent.
    std::optional<double> number_setting(const json& j, const std::string& path, std::string_view key) const {
        const json* v = JsonReader::find(j, key);
        if (!v) return std::nullopt;
        const std::string field = join_key(path, key);
        const double value = in_.number_value(*v, field);
        if (const std::string problem = setting_problem(key, value); !problem.empty()) in_.fail(field, problem);
        return value;
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
        t.scene_file = in_.file();
        t.field = path;
        return t;
    }

    // A material naming any Disney key is a Disney material (roughness is
    // shared by both kinds); kd and ks belong to Lambert + GGX only.
    gpu::Material parse_material_override(const json& j, const std::string& path) const {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"kd", "ks", "roughness", "emission", "emission_two_sided", "base_color", "metallic",
                                 "specular", "specular_tint", "sheen", "sheen_tint", "clearcoat",
                                 "clearcoat_gloss"});
        const char* disney_key = nullptr;
        for (const char* key : {"base_color", "metallic", "specular", "specular_tint", "sheen", "sheen_tint",
                                "clearcoat", "clearcoat_gloss"}) {
            if (JsonReader::find(j, key) != nullptr) {
                disney_key = key;
                break;
            }
        }
        float roughness = kDefaultRoughness;
        if (const json* v = JsonReader::find(j, "roughness")) {
            roughness = in_.number_in(*v, path + ".roughness", 0.0f, 1.0f, true, false);
        }
        gpu::Material m;
        if (disney_key != nullptr) {
            for (const char* key : {"kd", "ks"}) {
                if (JsonReader::find(j, key) != nullptr) {
                    in_.fail(path + "." + key, std::string("belongs to Lambert + GGX materials; this one is a Disney "
                                                           "material (it has \"") + disney_key + "\"): use base_color");
                }
            }
            m = make_disney_material(parse_disney(j, path, roughness));
        } else {
            glm::vec3 kd{kDefaultAlbedo}, ks{0.0f};
            if (const json* v = JsonReader::find(j, "kd")) kd = in_.colour(*v, path + ".kd", 1.0f);
            if (const json* v = JsonReader::find(j, "ks")) ks = in_.colour(*v, path + ".ks", 1.0f);
            m = make_material(kd, ks, roughness * roughness);
        }
        glm::vec3 emission{0.0f};
        if (const json* v = JsonReader::find(j, "emission"))
            emission = in_.colour(*v, path + ".emission", std::numeric_limits<float>::max());
        bool two_sided = false;
        if (const json* v = JsonReader::find(j, "emission_two_sided")) two_sided = in_.boolean(*v, path + ".emission_two_sided");
        set_emission(m, emission, two_sided);
        return m;
    }

    DisneyParams parse_disney(const json& j, const std::string& path, float roughness) const {
        DisneyParams p;
        p.roughness = roughness;
        if (const json* v = JsonReader::find(j, "base_color")) p.base_color = in_.colour(*v, path + ".base_color", 1.0f);
        const auto unit = [&](const char* key, float& out) {
            if (const json* v = JsonReader::find(j, key)) out = in_.number_in(*v, path + "." + key, 0.0f, 1.0f, false, false);
        };
        unit("metallic", p.metallic);
        unit("specular", p.specular);
        unit("specular_tint", p.specular_tint);
        unit("sheen", p.sheen);
        unit("sheen_tint", p.sheen_tint);
        unit("clearcoat", p.clearcoat);
        unit("clearcoat_gloss", p.clearcoat_gloss);
        return p;
    }

    void parse_meshes(const json& j) {
        in_.expect_array(j, "meshes");
        if (j.empty()) in_.fail("meshes", "must contain at least one mesh");
        for (std::size_t i = 0; i < j.size(); ++i) parse_mesh(j[i], join_index("meshes", i));
    }

    void parse_mesh(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        if (JsonReader::find(j, "gltf")) {
            parse_gltf_mesh(j, path);
            return;
        }
        in_.check_keys(j, path, {"obj", "transform", "material"});
        const std::string obj_field = path + ".obj";
        const fs::path obj_path = resolve(in_.string(in_.require(j, path, "obj"), obj_field), obj_field);
        MeshTransform transform;
        if (const json* t = JsonReader::find(j, "transform")) transform = parse_transform(*t, path + ".transform");
        std::optional<gpu::Material> override_material;
        if (const json* m = JsonReader::find(j, "material")) {
            override_material = parse_material_override(*m, path + ".material");
        }

        check_input_file(obj_path, obj_field);
        load_obj(obj_path, transform, override_material, meshes_);
    }

    // {"gltf": "file.glb", "transform": {...}}: the glTF's meshes, materials
    // and lights (its cameras are not used; the scene has its own).
    void parse_gltf_mesh(const json& j, const std::string& path) {
        in_.check_keys(j, path, {"gltf", "transform"});
        const fs::path file = existing_file(j, path, "gltf");
        MeshTransform transform;
        if (const json* t = JsonReader::find(j, "transform")) transform = parse_transform(*t, path + ".transform");
        GltfContents contents = load_gltf(file, transform, meshes_);
        for (GltfLight& l : contents.lights) gltf_lights_.emplace_back(display(file), std::move(l));
    }

    void add_gltf_lights() {
        for (const auto& [file, l] : gltf_lights_) {
            const LightLimits::Problem p = limits_.add(l.light);
            if (p.fault == LightLimits::Fault::total) in_.fail("lights", p.text);
            if (p.fault == LightLimits::Fault::position) throw InputError(file, l.field, p.text);
            scene_.lights.push_back(l.light);
        }
    }

    // -- lights -------------------------------------------------------------

    void parse_lights(const json& j) {
        in_.expect_array(j, "lights");
        for (std::size_t i = 0; i < j.size(); ++i) parse_light(j[i], join_index("lights", i));
    }

    // Lights may come from the lights array, emissive surfaces or an
    // environment; a scene with none of them renders black, which is a
    // mistake, not a picture.
    void require_some_light() const {
        if (!scene_.lights.empty() || scene_.environment.present()) return;
        for (const gpu::Material& m : scene_.materials)
            if ((m.flags & gpu::kMaterialEmissive) != 0u) return;
        in_.fail("lights", "the scene has no light: no lights (after loading CSV files), no emissive "
                           "material and no environment");
    }

    // A total that overflows is the list's fault, not one entry's; a position
    // too far out is the fault of the light that has it.
    void add_light(const gpu::Light& light, const std::string& path) {
        const LightLimits::Problem p = limits_.add(light);
        if (p.fault == LightLimits::Fault::total) in_.fail("lights", p.text);
        if (p.fault == LightLimits::Fault::position) in_.fail(path + ".position", p.text);
        scene_.lights.push_back(light);
    }

    void add_checked(const gpu::Light& light, const LightProblem& problem, const std::string& path) {
        if (problem) in_.fail(path + "." + problem.field, problem.problem);
        add_light(light, path);
    }

    glm::vec3 intensity(const json& j, const std::string& path, const char* key) const {
        return in_.colour(in_.require(j, path, key), path + "." + key, std::numeric_limits<float>::max());
    }

    void parse_light(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        const std::string type = in_.string(in_.require(j, path, "type"), path + ".type");
        LightProblem problem;
        if (type == "point") {
            in_.check_keys(j, path, {"type", "position", "intensity"});
            const glm::vec3 p = in_.vec3(in_.require(j, path, "position"), path + ".position");
            add_light(point_light(p, intensity(j, path, "intensity")), path);
        } else if (type == "directional") {
            in_.check_keys(j, path, {"type", "direction", "irradiance"});
            const glm::vec3 d = in_.vec3(in_.require(j, path, "direction"), path + ".direction");
            add_checked(directional_light(d, intensity(j, path, "irradiance"), problem), problem, path);
        } else if (type == "spot") {
            parse_spot(j, path);
        } else if (type == "points_csv" || type == "spots_csv") {
            in_.check_keys(j, path, {"type", "file"});
            const fs::path csv = existing_file(j, path, "file");
            std::vector<gpu::Light> loaded =
                type == "points_csv" ? read_points_csv(csv, limits_, threads_) : read_spots_csv(csv, limits_, threads_);
            if (loaded.empty())
                scene_.load_notes.push_back(in_.file() + ": " + path + ".file: " + display(csv) +
                                            " holds no lights (no line but comments, blanks or a header)");
            if (scene_.lights.empty())
                scene_.lights = std::move(loaded);  // no copy of a file of 10^7 lights
            else
                scene_.lights.insert(scene_.lights.end(), loaded.begin(), loaded.end());
        } else if (type == "environment") {
            parse_environment(j, path);
        } else {
            in_.fail(path + ".type", "unknown light type \"" + type +
                                         "\" (expected point, directional, spot, points_csv, spots_csv or environment)");
        }
    }

    fs::path existing_file(const json& j, const std::string& path, const char* key) const {
        const std::string field = path + "." + key;
        const fs::path file = resolve(in_.string(in_.require(j, path, key), field), field);
        check_input_file(file, field);
        return file;
    }

    void parse_spot(const json& j, const std::string& path) {
        in_.check_keys(j, path, {"type", "position", "direction", "intensity", "inner_cone_degrees",
                                 "outer_cone_degrees"});
        const glm::vec3 p = in_.vec3(in_.require(j, path, "position"), path + ".position");
        const glm::vec3 d = in_.vec3(in_.require(j, path, "direction"), path + ".direction");
        const float inner = in_.number(in_.require(j, path, "inner_cone_degrees"), path + ".inner_cone_degrees");
        const float outer = in_.number(in_.require(j, path, "outer_cone_degrees"), path + ".outer_cone_degrees");
        LightProblem problem;
        const gpu::Light l = spot_light(p, d, intensity(j, path, "intensity"), inner, outer, problem);
        add_checked(l, problem, path);
    }

    // {"type": "environment", "file": "sky.exr" | "color": [r, g, b],
    //  "scale": 1, "directions": 3000}; at most one per scene.
    void parse_environment(const json& j, const std::string& path) {
        in_.check_keys(j, path, {"type", "file", "color", "scale", "directions"});
        if (scene_.environment.present()) in_.fail(path, "a scene has at most one environment");
        const bool has_file = JsonReader::find(j, "file") != nullptr;
        if (has_file == (JsonReader::find(j, "color") != nullptr))
            in_.fail(path, "needs exactly one of \"file\" (a lat-long OpenEXR) and \"color\"");
        Environment env;
        if (has_file) {
            const fs::path exr = existing_file(j, path, "file");
            const Image map = read_exr_display_window(exr, kMaxEnvironmentPixels);  // notes the file as an input
            env.width = map.width;
            env.height = map.height;
            env.rgb = map.rgb;
            check_radiance(env.rgb, display(exr), env.width);
        } else {
            const glm::vec3 c = intensity(j, path, "color");
            env.width = env.height = 1;
            env.rgb = {c.r, c.g, c.b};
        }
        float scale = 1.0f;
        if (const json* v = JsonReader::find(j, "scale"))
            scale = in_.number_in(*v, path + ".scale", 0.0f, std::numeric_limits<float>::max(), true, false);
        for (float& value : env.rgb) {
            value *= scale;
            if (!std::isfinite(value)) in_.fail(path + ".scale", "makes the map's radiance overflow a float");
        }
        if (const json* v = JsonReader::find(j, kSettingDirections)) {
            const std::string field = path + "." + std::string(kSettingDirections);
            const double n = in_.number_value(*v, field);
            if (const std::string p = setting_problem(kSettingDirections, n); !p.empty()) in_.fail(field, p);
            env.directions = static_cast<std::uint32_t>(n);
        }
        // A black sky gets a note, as black lights get a word in the report
        // (it was accepted in silence, the only light of a scene that
        // rendered black).
        if (std::all_of(env.rgb.begin(), env.rgb.end(), [](float v) { return v == 0.0f; }))
            scene_.load_notes.push_back(in_.file() + ": " + path + ": the environment is black; it adds no light");
        scene_.environment = std::move(env);
    }

    // Every texel finite and not negative, or the map's file and pixel named.
    static void check_radiance(const std::vector<float>& rgb, const std::string& file, std::uint32_t width) {
        for (std::size_t i = 0; i < rgb.size(); ++i) {
            if (std::isfinite(rgb[i]) && rgb[i] >= 0.0f) continue;
            const std::size_t texel = i / 3;
            throw InputError(file, "pixel (" + std::to_string(texel % width) + ", " + std::to_string(texel / width) + ")",
                             std::string("radiance must be finite and not negative, got ") + std::to_string(rgb[i]));
        }
    }
};

}  // namespace
}  // namespace loader

Scene load_scene(const std::filesystem::path& file, const SceneOptions& options) {
    std::vector<std::filesystem::path> inputs;
    Scene scene;
    {
        const loader::InputFileLog log(inputs);
        if (loader::is_gltf_path(file)) {
            scene = loader::load_gltf_scene(file, options.camera);
        } else {
            if (!options.camera.empty())
                throw InputError(loader::display(file), "",
                                 "--camera picks a camera of a glTF scene; a JSON scene has its own");
            scene = loader::SceneParser(file, options.threads).parse();
        }
    }
    scene.input_files = std::move(inputs);
    return scene;
}

}  // namespace lc
