// Small scene builders and helpers shared by the tests.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "lightcuts/render.h"
#include "lightcuts/scene.h"
#include "scene/materials.h"

namespace lc::test {

// Overwrites the value of an OpenEXR file's header attribute `name` of
// type `type` with `size` bytes of `value`, leaving the rest as it is.
inline void patch_exr_attribute(const std::filesystem::path& file, const std::string& name, const std::string& type,
                                const void* value, std::size_t size) {
    std::string bytes;
    {
        std::ifstream in(file, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string attribute = name + '\0' + type + '\0';
    const std::size_t at = bytes.find(attribute);
    if (at == std::string::npos || at + attribute.size() + 4 + size > bytes.size())
        throw std::runtime_error(file.string() + ": no " + name + " attribute");
    std::memcpy(&bytes[at + attribute.size() + 4], value, size);  // after the attribute's 4-byte size
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// Rewrites an OpenEXR file's data window (its header's "dataWindow"
// attribute) to (0, 0) .. (max_x, max_y), leaving its pixels as they are:
// a small file whose header declares a large image.
inline void set_exr_data_window(const std::filesystem::path& file, std::int32_t max_x, std::int32_t max_y) {
    const std::int32_t window[4] = {0, 0, max_x, max_y};
    patch_exr_attribute(file, "dataWindow", "box2i", window, sizeof(window));
}

// A fresh directory under the system temp dir, removed with everything in it.
class TempDir {
public:
    TempDir() {
        static std::atomic<unsigned> counter{0};
        std::random_device entropy;
        path_ = std::filesystem::temp_directory_path() /
                ("lc_scene_test_" + std::to_string(entropy()) + "_" + std::to_string(counter++));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::filesystem::path write(const std::string& name, const std::string& text) const {
        const std::filesystem::path file = path_ / name;
        std::ofstream(file, std::ios::binary) << text;
        return file;
    }

    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

// Materials as the loader makes them (host/scene/materials.cpp), without
// its clamp of alpha: roughness = sqrt(alpha), no textures.
// The midpoint rule over the upper hemisphere (z > 0): `cells` x `cells`
// cells in (theta, phi), calling visit(wi, solid_angle_of_the_cell) once at
// each cell's centre.
template <typename Visit>
void for_hemisphere_cells(int cells, Visit&& visit) {
    constexpr double kPiD = 3.14159265358979323846;
    for (int i = 0; i < cells; ++i) {
        const double theta = (i + 0.5) * (0.5 * kPiD / cells);
        const double cell = (0.5 * kPiD / cells) * (2.0 * kPiD / cells) * std::sin(theta);
        for (int j = 0; j < cells; ++j) {
            const double phi = (j + 0.5) * (2.0 * kPiD / cells);
            visit(glm::vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                            float(std::cos(theta))),
                  cell);
        }
    }
}

// Corner k (0, 1, 2) of a triangle, and its shading normal there.
inline glm::vec3 vertex(const gpu::Triangle& t, int k) {
    if (k == 0) return {t.v0_x, t.v0_y, t.v0_z};
    if (k == 1) return {t.v1_x, t.v1_y, t.v1_z};
    return {t.v2_x, t.v2_y, t.v2_z};
}

// The side its corners' winding faces, (v1 - v0) x (v2 - v0), normalised:
// the side an emissive triangle emits from.
inline glm::vec3 winding_normal(const gpu::Triangle& t) {
    return glm::normalize(glm::cross(vertex(t, 1) - vertex(t, 0), vertex(t, 2) - vertex(t, 0)));
}

inline glm::vec3 normal(const gpu::TriangleNormals& n, int k) {
    if (k == 0) return {n.n0_x, n.n0_y, n.n0_z};
    if (k == 1) return {n.n1_x, n.n1_y, n.n1_z};
    return {n.n2_x, n.n2_y, n.n2_z};
}

inline gpu::Material lambert(glm::vec3 kd) {
    gpu::Material m{};
    m.kd_r = kd.x; m.kd_g = kd.y; m.kd_b = kd.z;
    m.alpha = 1.0f;
    m.roughness = 1.0f;
    m.specular = 0.5f;
    m.normal_scale = 1.0f;
    m.base_color_texture = m.metallic_roughness_texture = m.emissive_texture = m.normal_texture = gpu::kInvalidIndex;
    return m;
}

inline gpu::Material glossy(glm::vec3 kd, glm::vec3 ks, float alpha) {
    gpu::Material m = lambert(kd);
    m.ks_r = ks.x; m.ks_g = ks.y; m.ks_b = ks.z;
    m.alpha = alpha;
    m.roughness = std::sqrt(alpha);
    m.flags = gpu::kMaterialHasSpecular;
    return m;
}

inline gpu::Light point_light(glm::vec3 p, glm::vec3 intensity) {
    gpu::Light l{};
    l.x = p.x; l.y = p.y; l.z = p.z;
    l.r = intensity.x; l.g = intensity.y; l.b = intensity.z;
    l.type = gpu::kLightPoint;
    return l;
}

// `travel` is the way the light travels, as in the scene format.
inline gpu::Light directional_light(glm::vec3 travel, glm::vec3 irradiance) {
    gpu::Light l = point_light(-glm::normalize(travel), irradiance);
    l.type = gpu::kLightDirectional;
    return l;
}

// A spot at p shining along `axis`, half-angles in degrees.
inline gpu::Light spot_light(glm::vec3 p, glm::vec3 axis, glm::vec3 intensity, float inner_degrees,
                             float outer_degrees) {
    gpu::Light l = point_light(p, intensity);
    const glm::vec3 a = glm::normalize(axis);
    l.axis_x = a.x; l.axis_y = a.y; l.axis_z = a.z;
    l.cos_inner = std::cos(glm::radians(inner_degrees));
    l.cos_outer = std::cos(glm::radians(outer_degrees));
    l.type = gpu::kLightSpot;
    return l;
}

// A cosine emitter at p around `normal`, intensity along the normal.
inline gpu::Light oriented_light(glm::vec3 p, glm::vec3 normal, glm::vec3 intensity, bool two_sided = false) {
    gpu::Light l = point_light(p, intensity);
    const glm::vec3 n = glm::normalize(normal);
    l.axis_x = n.x; l.axis_y = n.y; l.axis_z = n.z;
    l.type = gpu::kLightOriented | (two_sided ? gpu::kLightTwoSided : 0u);
    return l;
}

// Random Disney parameters; each lobe is switched off entirely in about a
// quarter of the cases, so every combination of lobes occurs.
inline loader::DisneyParams random_disney_params(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const auto maybe = [&](float v) { return u(rng) < 0.25f ? 0.0f : v; };
    loader::DisneyParams p;
    p.base_color = glm::vec3(u(rng), u(rng), u(rng)) * (u(rng) < 0.1f ? 0.0f : 1.0f);
    p.metallic = u(rng) < 0.2f ? 1.0f : maybe(u(rng));
    p.roughness = u(rng) < 0.1f ? 0.0f : u(rng);
    p.specular = maybe(u(rng));
    p.specular_tint = u(rng);
    p.sheen = maybe(u(rng));
    p.sheen_tint = u(rng);
    p.clearcoat = maybe(u(rng));
    p.clearcoat_gloss = u(rng);
    return p;
}

// The sharpest Disney material: white polished metal (roughness 0, the
// GGX alpha floor) under a clearcoat of gloss 1, where the microfacet
// peaks are highest.
inline loader::DisneyParams polished_metal() {
    loader::DisneyParams p;
    p.base_color = glm::vec3(1.0f);
    p.metallic = 1.0f;
    p.roughness = 0.0f;
    p.clearcoat = 1.0f;
    p.clearcoat_gloss = 1.0f;
    return p;
}

// Eight bright point lights at the corners of a box below room_scene's
// ceiling and 65,536 dim ones inside it, each about 2^-27 of the bright
// ones' sum at a point of the floor, below half a float step of a running
// sum: a plain float sum rounds them away (5e-4 of the light).
inline std::vector<gpu::Light> many_dim_lights() {
    std::vector<gpu::Light> lights;
    for (int c = 0; c < 8; ++c)
        lights.push_back(point_light({c & 1 ? -0.3f : -0.7f, c & 2 ? 1.6f : 1.2f, c & 4 ? 0.9f : 0.5f}, glm::vec3(0.5f)));
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 65536; ++i)
        lights.push_back(
            point_light({-0.7f + 0.4f * u(rng), 1.2f + 0.4f * u(rng), 0.5f + 0.4f * u(rng)}, glm::vec3(1.6e-8f)));
    return lights;
}

// A uniformly distributed unit vector.
inline glm::vec3 random_unit(std::mt19937& rng) {
    std::normal_distribution<float> g;
    glm::vec3 v;
    do v = glm::vec3(g(rng), g(rng), g(rng));
    while (glm::dot(v, v) < 1e-6f);
    return glm::normalize(v);
}

// A light tree node with the given box and light type, for bound tests.
inline gpu::LightNode node_with_box(glm::vec3 lo, glm::vec3 hi, std::uint32_t type) {
    gpu::LightNode n{};
    n.min_x = lo.x; n.min_y = lo.y; n.min_z = lo.z;
    n.max_x = hi.x; n.max_y = hi.y; n.max_z = hi.z;
    n.flags = type << gpu::kNodeTypeShift;
    n.cos_theta_o = -1.0f;  // emits everywhere, as point and directional lights do
    return n;
}

// The type stored in a light tree node.
inline std::uint32_t node_type(const gpu::LightNode& n) {
    return (n.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
}

inline void add_triangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t material) {
    gpu::Triangle t{a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, material, 0u, 0u};
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    gpu::TriangleNormals tn{n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z, 0u, 0u, 0u};
    s.triangles.push_back(t);
    s.normals.push_back(tn);
}

inline void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material) {
    add_triangle(s, a, b, c, material);
    add_triangle(s, a, c, d, material);
}

// Axis-aligned box, six faces.
inline void add_box(Scene& s, glm::vec3 lo, glm::vec3 hi, std::uint32_t material) {
    glm::vec3 p[8];
    for (int i = 0; i < 8; ++i) p[i] = glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    add_quad(s, p[0], p[1], p[3], p[2], material);
    add_quad(s, p[4], p[6], p[7], p[5], material);
    add_quad(s, p[0], p[4], p[5], p[1], material);
    add_quad(s, p[2], p[3], p[7], p[6], material);
    add_quad(s, p[0], p[2], p[6], p[4], material);
    add_quad(s, p[1], p[5], p[7], p[3], material);
}

// Closed UV sphere with flat faces.
inline void add_sphere(Scene& s, glm::vec3 centre, float radius, int stacks, int slices, std::uint32_t material) {
    auto at = [&](int i, int j) {
        float theta = float(M_PI) * float(i) / float(stacks);
        float phi = 2.0f * float(M_PI) * float(j) / float(slices);
        return centre + radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                           std::sin(theta) * std::sin(phi));
    };
    for (int i = 0; i < stacks; ++i) {
        for (int j = 0; j < slices; ++j) {
            glm::vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            if (i > 0) add_triangle(s, a, b, d, material);
            if (i + 1 < stacks) add_triangle(s, b, c, d, material);
        }
    }
}

inline Camera camera(glm::vec3 pos, glm::vec3 at, float fov, std::uint32_t w, std::uint32_t h) {
    Camera c;
    c.position = pos;
    c.look_at = at;
    c.up = glm::vec3(0, 1, 0);
    if (std::abs(glm::dot(glm::normalize(at - pos), c.up)) > 0.99f) c.up = glm::vec3(0, 0, 1);
    c.fov_y_degrees = fov;
    c.width = w;
    c.height = h;
    return c;
}

// Lights uniformly in a box, intensities summing to `total` per channel.
inline std::vector<gpu::Light> random_point_lights(std::size_t n, glm::vec3 lo, glm::vec3 hi, float total,
                                                   std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<gpu::Light> lights;
    for (std::size_t i = 0; i < n; ++i) {
        glm::vec3 p = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 c = glm::vec3(0.5f + u(rng), 0.5f + u(rng), 0.5f + u(rng)) * (total / float(n));
        lights.push_back(point_light(p, c));
    }
    return lights;
}

// A closed room [-1,1]^2 x [0,2] in y with two boxes inside and one glossy
// sphere; camera at the front looking in.
inline Scene room_scene(std::vector<gpu::Light> lights, std::uint32_t size) {
    Scene s;
    s.materials = {lambert({0.7f, 0.7f, 0.7f}), lambert({0.7f, 0.2f, 0.2f}),
                   glossy({0.2f, 0.3f, 0.6f}, {0.5f, 0.5f, 0.5f}, 0.3f)};
    glm::vec3 lo(-1, 0, -1), hi(1, 2, 1);
    add_box(s, lo, hi, 0);
    add_box(s, {-0.6f, 0.0f, -0.5f}, {-0.1f, 0.7f, 0.0f}, 1);
    add_box(s, {0.2f, 0.0f, 0.1f}, {0.6f, 0.4f, 0.5f}, 0);
    add_sphere(s, {0.3f, 1.0f, -0.3f}, 0.25f, 12, 24, 2);
    s.lights = std::move(lights);
    s.camera = camera({0.0f, 1.0f, 0.95f}, {0.0f, 0.8f, 0.0f}, 70.0f, size, size);
    update_bounds(s);
    return s;
}

// A ground plane and a box under a constant sky of 2.7e37, the brightest
// the loader accepts (4 pi L = 3.39e38, just below FLT_MAX); 8 x 8, the
// top row of pixels sees the sky.
inline Scene brightest_sky_scene() {
    Scene s;
    s.materials = {lambert(glm::vec3(0.5f))};
    add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    add_box(s, {-0.3f, 0.0f, -0.3f}, {0.3f, 0.6f, 0.3f}, 0);
    s.camera = camera({0.0f, 1.0f, 3.0f}, {0.0f, 0.5f, 0.0f}, 60.0f, 8, 8);
    s.environment.width = 4;
    s.environment.height = 2;
    s.environment.rgb.assign(4 * 2 * 3, 2.7e37f);
    update_bounds(s);
    return s;
}

inline RenderOptions options(const std::string& method, std::uint32_t size) {
    RenderOptions o;
    o.method = method;
    o.width = o.height = size;
    return o;
}

}  // namespace lc::test
