#include "fuzz_input.h"
#include "lightcuts/error.h"
#include "lightcuts/settings.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <unistd.h>

#include <glm/glm.hpp>

namespace lc::fuzz {
namespace {

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool unit(glm::vec3 v) { return finite(v) && std::abs(glm::length(v) - 1.0f) < 1e-3f; }

bool in_unit_interval(float r, float g, float b) {
    return r >= 0.0f && r <= 1.0f && g >= 0.0f && g <= 1.0f && b >= 0.0f && b <= 1.0f;
}

}  // namespace

std::filesystem::path write_scene_files(std::string_view data, const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    const char* names[] = {kSceneFile, kLightsFile, kObjFile, kMtlFile};
    for (const char* name : names) {
        const std::size_t end = std::min(data.find('\0'), data.size());
        std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
        out.write(data.data(), std::streamsize(end));
        data.remove_prefix(std::min(end + 1, data.size()));
    }
    return dir / kSceneFile;
}

std::filesystem::path write_gltf_file(std::string_view data, const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / (data.substr(0, 4) == "glTF" ? "scene.glb" : "scene.gltf");
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(data.data(), std::streamsize(data.size()));
    return file;
}

std::string check_scene_contract(const Scene& s) {
    const Camera& c = s.camera;
    if (!finite(c.position) || !finite(c.look_at) || !finite(c.up)) return "camera not finite";
    if (c.position == c.look_at) return "camera looks at its own position";
    if (!(c.fov_y_degrees > 0.0f && c.fov_y_degrees < 180.0f)) return "fov out of (0, 180)";
    if (c.width < 1 || c.height < 1 || c.width > 16384 || c.height > 16384) return "image size out of range";
    if (s.triangles.empty()) return "no triangles";
    if (s.normals.size() != s.triangles.size()) return "normals not parallel to triangles";
    bool emissive = false;
    for (const auto& m : s.materials) emissive |= (m.flags & gpu::kMaterialEmissive) != 0u;
    if (s.lights.empty() && !emissive && !s.environment.present()) return "no light at all";
    for (float v : s.environment.rgb)
        if (!(std::isfinite(v) && v >= 0.0f)) return "environment radiance invalid";
    if (s.environment.present() && s.environment.rgb.size() != 3u * s.environment.width * s.environment.height)
        return "environment size disagrees with its texels";
    for (const auto& m : s.materials) {
        if (!in_unit_interval(m.kd_r, m.kd_g, m.kd_b) || !in_unit_interval(m.ks_r, m.ks_g, m.ks_b))
            return "material colour out of [0, 1]";
        if (!(m.alpha >= 1e-3f && m.alpha <= 1.0f)) return "GGX alpha out of [1e-3, 1]";
        const bool specular = m.ks_r > 0.0f || m.ks_g > 0.0f || m.ks_b > 0.0f;
        if (specular != ((m.flags & gpu::kMaterialHasSpecular) != 0u)) return "specular flag disagrees with ks";
        for (float v : {m.roughness, m.metallic, m.specular, m.specular_tint, m.sheen, m.sheen_tint, m.clearcoat,
                        m.clearcoat_gloss})
            if (!(v >= 0.0f && v <= 1.0f)) return "Disney parameter out of [0, 1]";
        const glm::vec3 e(m.emission_r, m.emission_g, m.emission_b);
        if (!finite(e) || e.r < 0.0f || e.g < 0.0f || e.b < 0.0f) return "emission invalid";
        const bool emits = e.r > 0.0f || e.g > 0.0f || e.b > 0.0f;
        if (emits != ((m.flags & gpu::kMaterialEmissive) != 0u)) return "emissive flag disagrees with emission";
    }
    for (std::size_t i = 0; i < s.triangles.size(); ++i) {
        const gpu::Triangle& t = s.triangles[i];
        const gpu::TriangleNormals& n = s.normals[i];
        if (t.material >= s.materials.size()) return "triangle material out of range";
        const glm::vec3 v0(t.v0_x, t.v0_y, t.v0_z), v1(t.v1_x, t.v1_y, t.v1_z), v2(t.v2_x, t.v2_y, t.v2_z);
        if (!finite(v0) || !finite(v1) || !finite(v2)) return "vertex not finite";
        if (!(glm::length(glm::cross(v1 - v0, v2 - v0)) > 0.0f)) return "degenerate triangle kept";
        if (!unit({n.n0_x, n.n0_y, n.n0_z}) || !unit({n.n1_x, n.n1_y, n.n1_z}) || !unit({n.n2_x, n.n2_y, n.n2_z}))
            return "normal not unit length";
    }
    if (!s.uvs.empty() && s.uvs.size() != s.triangles.size()) return "uvs not parallel to triangles";
    for (const auto& t : s.uvs)
        for (const float v : {t.u0, t.v0, t.u1, t.v1, t.u2, t.v2})
            if (!std::isfinite(v)) return "uv not finite";
    for (const auto& m : s.materials)
        for (const std::uint32_t t : {m.base_color_texture, m.metallic_roughness_texture, m.emissive_texture,
                                      m.normal_texture})
            if (t != gpu::kInvalidIndex && t >= s.textures.size()) return "material texture out of range";
    for (const auto& t : s.textures)
        if (t.width < 1 || t.height < 1 || std::uint64_t(t.offset) + std::uint64_t(t.width) * t.height > s.texels.size())
            return "texture texels out of range";
    for (const auto& l : s.lights) {
        if (l.type != gpu::kLightPoint && l.type != gpu::kLightDirectional && l.type != gpu::kLightSpot)
            return "unknown light type";
        if (!finite({l.x, l.y, l.z})) return "light position not finite";
        if (!finite({l.r, l.g, l.b}) || l.r < 0.0f || l.g < 0.0f || l.b < 0.0f) return "light intensity invalid";
        if (l.type == gpu::kLightDirectional && !unit({l.x, l.y, l.z})) return "light direction not unit";
        if (l.type == gpu::kLightSpot &&
            (!unit({l.axis_x, l.axis_y, l.axis_z}) || !(l.cos_outer >= -1e-6f && l.cos_outer <= l.cos_inner) ||
             !(l.cos_inner <= 1.0f)))
            return "spot axis or cone invalid";
    }
    if (!finite(s.bounds_min) || !finite(s.bounds_max)) return "bounds not finite";
    const RenderSettings& r = s.render;
    if (r.method != "brute" && r.method != "lightcuts" && r.method != "sampled" && r.method != "stochastic" &&
        r.method != "path")
        return "unknown method";
    if (r.light_pick != "tree" && r.light_pick != "uniform" && r.light_pick != "power") return "unknown light pick";
    if (r.spp < 1 || r.max_cut < 1 || r.light_samples < 1) return "spp, max_cut or light_samples below 1";
    if (!(r.relative_error >= 0.0f) || !std::isfinite(r.relative_error)) return "relative_error invalid";
    if (r.max_bounces > kMaxBounces || r.indirect.max_bounces > kMaxBounces) return "max_bounces out of range";
    if (r.indirect.vpls > kMaxVpls) return "vpls out of range";
    if (!(r.indirect.clamp >= 0.0f) || !std::isfinite(r.indirect.clamp)) return "clamp invalid";
    if (!(r.time_limit >= 0.0) || !std::isfinite(r.time_limit)) return "time_limit invalid";
    return {};
}

namespace {

struct WorkDir {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("lc_fuzz_" + std::to_string(::getpid()));
    ~WorkDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
};

}  // namespace

void load_or_abort(std::string_view data, InputWriter write) {
    static const WorkDir dir;
    const std::filesystem::path file = write(data, dir.path);
    try {
        const Scene scene = load_scene(file);
        const std::string broken = check_scene_contract(scene);
        if (!broken.empty()) {
            std::fprintf(stderr, "loaded scene breaks the loader's contract: %s\n", broken.c_str());
            std::abort();
        }
    } catch (const InputError&) {
        // Rejected with a message naming the file and field: correct.
    } catch (const std::exception& e) {
        std::fprintf(stderr, "load_scene threw something other than lc::InputError: %s\n", e.what());
        std::abort();
    }
}

}  // namespace lc::fuzz
