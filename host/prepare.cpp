// Turns a loaded scene into what both renderers read: BVH, light tree and
// frame constants.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <type_traits>

#include <chrono>

#include "area_lights.h"
#include "environment_lights.h"
#include "vpls.h"
#include "scene/float_limits.h"
#include "scene/huge_pages.h"
#include "scene/scene_check.h"
#include "scene/textures.h"
#include "lightcuts/error.h"
#include "lightcuts/render.h"

namespace lc {
namespace {

// The inverse-square falloff 1/d^2 is evaluated as 1/max(d^2, min_d^2) in
// the exact term and in the bound alike, so bounds stay conservative and a
// light on a surface (d = 0) gives a bright but finite spot, never Inf/NaN.
// min_d is relative to the scene's size so it scales with the scene's units.
constexpr float kMinDistanceRelative = 1e-4f;

// True when no triangle can block a light that could reach a shaded
// point: every triangle lies in one plane, and every shading normal is
// that plane's (no normal or normal map bends it). Then a light behind the
// plane, which only the plane could block, meets the back of the point's
// hemisphere, and shadow rays are useless. A bent shading normal lets such
// a light through the cosine, and only its shadow ray blocks it.
bool nothing_can_shadow(const Scene& scene) {
    const std::vector<gpu::Triangle>& tris = scene.triangles;
    if (tris.empty()) return true;
    for (const gpu::Material& m : scene.materials)
        if ((m.flags & gpu::kMaterialTextured) != 0u && m.normal_texture != gpu::kInvalidIndex) return false;
    const auto& t0 = tris[0];
    glm::dvec3 a(t0.v0_x, t0.v0_y, t0.v0_z), b(t0.v1_x, t0.v1_y, t0.v1_z), c(t0.v2_x, t0.v2_y, t0.v2_z);
    glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    double scale = 0.0;
    for (const auto& t : tris)
        for (float v : {t.v0_x, t.v0_y, t.v0_z, t.v1_x, t.v1_y, t.v1_z, t.v2_x, t.v2_y, t.v2_z})
            scale = std::max(scale, double(std::abs(v)));
    double tolerance = 1e-6 * std::max(scale, 1.0);
    for (const auto& t : tris) {
        for (glm::dvec3 p : {glm::dvec3(t.v0_x, t.v0_y, t.v0_z), glm::dvec3(t.v1_x, t.v1_y, t.v1_z),
                             glm::dvec3(t.v2_x, t.v2_y, t.v2_z)}) {
            if (std::abs(glm::dot(p - a, n)) > tolerance) return false;
        }
    }
    for (const gpu::TriangleNormals& t : scene.normals)
        for (glm::dvec3 v : {glm::dvec3(t.n0_x, t.n0_y, t.n0_z), glm::dvec3(t.n1_x, t.n1_y, t.n1_z),
                             glm::dvec3(t.n2_x, t.n2_y, t.n2_z)})
            if (glm::length(glm::cross(v, n)) > 1e-6 * glm::length(v)) return false;
    return true;
}

// Adds `lights` to the running totals; an InputError naming the scene file
// and `field` where a per-type total leaves the float range, ending with
// `why`. Positions are not checked: these lights lie on the geometry or
// have none.
void check_generated_totals(const Scene& scene, loader::LightLimits& limits, std::span<const gpu::Light> lights,
                            const char* field, const char* why) {
    for (const gpu::Light& l : lights) {
        const loader::LightLimits::Problem problem = limits.add(l);
        if (problem.fault == loader::LightLimits::Fault::total)
            throw InputError(scene.file.string(), field, problem.text + why);
    }
}

// Moves a scene that lies far from the origin, compared with its size, to
// the origin (by its bounds' centre, in float): the renderer's precision
// then follows the scene's size, not its position. A hit point is shaded
// where it was moved off its surface, 2^-20 of its largest coordinate
// (lc_offset_hit_point), and every float step grows with the coordinates:
// the shipped room moved by 1e4 came out 30% off (relative RMSE), a light
// 0.25 above a floor moved by 16384 13.5% brighter under it. (pbrt-v4
// renders in camera-centred coordinates for the same reason.) A scene
// within 16 times its diagonal of the origin is left as it is, to the bit.
// The camera, the triangles and every light with a position move; nothing
// the renderer reports depends on where the scene is.
void centre_far_scene(Scene& scene) {
    const glm::dvec3 lo(scene.bounds_min), hi(scene.bounds_max);
    const double diagonal = glm::length(hi - lo);
    const double farthest = std::max({std::abs(lo.x), std::abs(lo.y), std::abs(lo.z), std::abs(hi.x), std::abs(hi.y),
                                      std::abs(hi.z)});
    if (!(farthest > 16.0 * diagonal) || scene.triangles.empty()) return;
    const glm::vec3 c(0.5 * (lo + hi));
    // The camera's forward vector is kept as it was: look_at moved on its
    // own rounds apart from the position where the camera is much farther
    // from c than the scene is wide (a camera 1e7 out with a 0.04 degree
    // view turned by half its tilt). Where even that rounds to nothing,
    // the scene stays where it is.
    const glm::vec3 position = scene.camera.position - c;
    const glm::dvec3 forward = glm::dvec3(scene.camera.look_at) - glm::dvec3(scene.camera.position);
    const glm::vec3 look_at(glm::dvec3(position) + forward);
    if (look_at == position) return;
    auto move = [&c](float& x, float& y, float& z) { x -= c.x, y -= c.y, z -= c.z; };
    for (gpu::Triangle& t : scene.triangles) {
        move(t.v0_x, t.v0_y, t.v0_z);
        move(t.v1_x, t.v1_y, t.v1_z);
        move(t.v2_x, t.v2_y, t.v2_z);
    }
    for (gpu::Light& l : scene.lights)
        if ((l.type & gpu::kLightTypeMask) != gpu::kLightDirectional) move(l.x, l.y, l.z);
    scene.camera.position = position;
    scene.camera.look_at = look_at;
    scene.bounds_min -= c;
    scene.bounds_max -= c;
}

// Moves each triangle's texture coordinates by a whole number of periods
// towards 0, where every texture its material samples repeats or mirrors
// without a transform along that axis (a move by an even number changes
// neither lookup). A float near 1e6 is a multiple of 0.0625, so the
// barycentric sums of coordinates that large lose the texture's detail
// (relative RMSE 0.36 at 64 texels with 999999 added to a quad's u and v,
// and the texture one colour at 1e7); moved, they keep their fraction. A
// triangle within 2 of the origin is left as it is, to the bit.
void wrap_texture_coordinates(Scene& scene) {
    if (scene.uvs.size() != scene.triangles.size() || scene.textures.empty()) return;
    for (std::size_t i = 0; i < scene.triangles.size(); ++i) {
        const gpu::Material& m = scene.materials[scene.triangles[i].material];
        if ((m.flags & gpu::kMaterialTextured) == 0u) continue;
        bool movable[2] = {true, true};
        for (const std::uint32_t t :
             {m.base_color_texture, m.metallic_roughness_texture, m.emissive_texture, m.normal_texture}) {
            if (t == gpu::kInvalidIndex) continue;
            const std::uint32_t sampling = scene.textures[t].sampling;
            for (std::uint32_t axis = 0; axis < 2; ++axis) {
                const std::uint32_t wrap = sampling >> (axis * gpu::kTextureWrapVShift) & 3u;
                movable[axis] = movable[axis] && (sampling & gpu::kTextureTransformed) == 0u &&
                                (wrap == gpu::kTextureWrapRepeat || wrap == gpu::kTextureWrapMirror);
            }
        }
        gpu::TriangleUvs& uv = scene.uvs[i];
        float* coordinates[2][3] = {{&uv.u0, &uv.u1, &uv.u2}, {&uv.v0, &uv.v1, &uv.v2}};
        for (std::uint32_t axis = 0; axis < 2; ++axis) {
            if (!movable[axis]) continue;
            const double lowest = std::min({*coordinates[axis][0], *coordinates[axis][1], *coordinates[axis][2]});
            if (std::abs(lowest) < 2.0) continue;
            // Even, and a float: a float at or above 2^24 is a whole number.
            const float periods = float(2.0 * std::floor(lowest / 2.0));
            for (float* c : coordinates[axis]) *c -= periods;
        }
    }
}

}  // namespace

PreparedScene prepare_scene(Scene scene, std::uint32_t seed, unsigned threads) {
    // A scene built or changed in code gets the loaders' checks, and its
    // bounds from its triangles (what load_scene left them, for one it read).
    const loader::Box geometry = loader::check_scene_geometry(scene);
    scene.bounds_min = glm::vec3(geometry.lo);
    scene.bounds_max = glm::vec3(geometry.hi);
    PreparedScene prepared;
    centre_far_scene(scene);
    wrap_texture_coordinates(scene);
    loader::add_mipmaps(scene);
    prepared.has_occluders = !nothing_can_shadow(scene);
    // A scene without texture coordinates gets zeros: every kernel reads them.
    if (scene.uvs.empty()) scene.uvs.assign(scene.triangles.size(), gpu::TriangleUvs{});
    prepared.bvh = build_bvh(scene.triangles, scene.normals, &scene.uvs);
    // Walter 2005 §5: area lights and the environment become many point and
    // directional lights, in the one tree with the scene's own.
    const auto start = std::chrono::steady_clock::now();
    UninitializedVector<gpu::Light> area = sample_area_lights(scene, scene.render.area_light_samples, seed, threads);
    const std::vector<gpu::Light> sky = environment_lights(scene.environment, scene.environment.directions);
    // The loader checked the scene's own lights' totals; the lights made
    // from emissive surfaces, the environment and light paths join the same
    // per-type sums, which must stay finite as floats too (a sky of radiance
    // 3e37, 3.8e38 over the sphere, made an infinite root intensity, and
    // lightcuts infinite pixels). The scene's totals are summed again only
    // where such lights exist (for 10^7 lights from a file, that pass and a
    // copy of the lights took 0.7 s).
    loader::LightLimits limits;
    bool limits_have_scene = false;
    auto check_generated = [&](std::span<const gpu::Light> generated, const char* field, const char* why) {
        if (generated.empty()) return;
        if (!limits_have_scene) {
            for (const gpu::Light& l : scene.lights) limits.add(l);
            limits_have_scene = true;
        }
        check_generated_totals(scene, limits, generated, field, why);
    };
    check_generated(area, "emissive surfaces", ", with the lights sampled on the emissive surfaces (emission times area)");
    check_generated(sky, "environment", ", with the environment's directional lights (radiance times solid angle)");
    prepared.area_lights = area.size();
    prepared.environment_lights = sky.size();
    // Every light of the tree: the scene's own, copied only where others
    // join them; the area lights moved, not copied, where they are all
    // (for 10^7 samples the copy took half of the 3 s the sampling did,
    // mostly the kernel zeroing its 480 MB of fresh pages).
    UninitializedVector<gpu::Light> joined;
    if (scene.lights.empty() && sky.empty()) {
        joined = std::move(area);
    } else if (!area.empty() || !sky.empty()) {
        joined.reserve(scene.lights.size() + area.size() + sky.size());
        joined.insert(joined.end(), scene.lights.begin(), scene.lights.end());
        joined.insert(joined.end(), area.begin(), area.end());
        joined.insert(joined.end(), sky.begin(), sky.end());
    }
    prepared.light_sampling_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Walter 2005 §5: indirect light as VPLs, one more type in the same tree.
    if (scene.render.indirect.vpls > 0) {
        const auto vpl_start = std::chrono::steady_clock::now();
        const std::span<const gpu::Light> emitters = joined.empty() ? std::span<const gpu::Light>(scene.lights)
                                                                    : std::span<const gpu::Light>(joined);
        VplSet vpls = trace_vpls(scene, prepared.bvh, emitters, scene.render.indirect, seed, threads);
        check_generated(vpls.lights, "indirect light",
                        ": together they carry the power of the lights they leave, whatever their number");
        prepared.vpls = vpls.lights.size();
        prepared.vpl_paths = vpls.paths;
        if (joined.empty() && !vpls.lights.empty()) joined.assign(scene.lights.begin(), scene.lights.end());
        joined.insert(joined.end(), vpls.lights.begin(), vpls.lights.end());
        prepared.vpl_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - vpl_start).count();
    }
    const std::span<const gpu::Light> lights =
        joined.empty() ? std::span<const gpu::Light>(scene.lights) : std::span<const gpu::Light>(joined);
    for (const gpu::Light& l : lights) {
        const std::uint32_t type = l.type & gpu::kLightTypeMask;
        prepared.has_oriented |= type == gpu::kLightSpot || type == gpu::kLightOriented || type == gpu::kLightVpl;
    }
    prepared.tree = build_light_tree(lights, seed, TreeBuilder::kFast, 1.0, threads);
    release(joined);
    for (const auto& m : scene.materials) {
        prepared.has_specular |= (m.flags & gpu::kMaterialHasSpecular) != 0u;
        prepared.has_textures |= (m.flags & gpu::kMaterialTextured) != 0u;
        const bool disney = (m.flags & gpu::kMaterialDisney) != 0u;
        prepared.has_disney |= disney;
        prepared.has_sheen |= disney && (m.flags & gpu::kMaterialHasSheen) != 0u;
        prepared.has_clearcoat |= disney && (m.flags & gpu::kMaterialHasClearcoat) != 0u;
    }
    // The geometry's size alone (Scene::bounds), in double: a far-away
    // light or the size of the light set must not change it.
    const glm::dvec3 extent = glm::dvec3(scene.bounds_max) - glm::dvec3(scene.bounds_min);
    const double min_d = kMinDistanceRelative * glm::length(extent);
    prepared.min_distance2 = float(std::clamp(min_d * min_d, double(std::numeric_limits<float>::min()),
                                              double(std::numeric_limits<float>::max())));
    const double clamp = scene.render.indirect.clamp;
    prepared.vpl_min_distance2 = std::max(prepared.min_distance2, float(std::min(clamp * clamp,
                                                                   double(std::numeric_limits<float>::max()))));
    prepared.scene = std::move(scene);
    return prepared;
}

gpu::FrameParams make_frame_params(const PreparedScene& prepared, const RenderOptions& options) {
    const Camera& cam = prepared.scene.camera;
    gpu::FrameParams f{};
    f.width = options.width ? options.width : cam.width;
    f.height = options.height ? options.height : cam.height;
    glm::vec3 fwd = glm::normalize(cam.look_at - cam.position);
    glm::vec3 right = glm::normalize(glm::cross(fwd, cam.up));
    glm::vec3 up = glm::cross(right, fwd);
    float tan_half = std::tan(glm::radians(cam.fov_y_degrees) * 0.5f);
    float aspect = float(f.width) / float(f.height);
    right *= tan_half * aspect;
    up *= tan_half;
    // The angle a sample's stratum spans at the image's centre: a pixel's
    // over the rows or columns of lc_pixel_sample's grid, whichever are
    // fewer (its strata are about sqrt(spp) a side, or spp columns of full
    // height), so that the samples' footprints cover the pixel's
    // (textures.h).
    const std::uint32_t spp = std::max(options.spp, 1u);
    std::uint32_t cols = std::uint32_t(std::ceil(std::sqrt(double(spp))));
    std::uint32_t rows = (spp + cols - 1) / cols;
    if (cols * rows != spp) cols = spp, rows = 1;
    f.pixel_spread = float(2.0 * double(tan_half) / double(f.height) / double(std::min(cols, rows)));
    f.cam_pos_x = cam.position.x; f.cam_pos_y = cam.position.y; f.cam_pos_z = cam.position.z;
    f.cam_right_x = right.x; f.cam_right_y = right.y; f.cam_right_z = right.z;
    f.cam_up_x = up.x; f.cam_up_y = up.y; f.cam_up_z = up.z;
    f.cam_fwd_x = fwd.x; f.cam_fwd_y = fwd.y; f.cam_fwd_z = fwd.z;
    f.min_distance2 = prepared.min_distance2;
    f.vpl_min_distance2 = prepared.vpl_min_distance2;
    f.relative_error = options.relative_error;
    f.max_cut = options.max_cut;
    f.spp = std::max(options.spp, 1u);
    f.seed = options.seed;
    f.light_count = static_cast<std::uint32_t>(prepared.tree.lights.size());
    for (std::uint32_t t = 0; t < gpu::kLightTypeCount; ++t) f.roots[t] = prepared.tree.roots[t];
    f.loop_probe_rounds = 2;
    f.env_width = prepared.scene.environment.width;
    f.env_height = prepared.scene.environment.height;
    f.light_samples = options.light_samples;
    f.light_pick = options.light_pick == "uniform" ? gpu::kLightPickUniform
                   : options.light_pick == "power" ? gpu::kLightPickPower
                                                   : gpu::kLightPickTree;
    return f;
}

std::vector<SceneArray> scene_arrays(const PreparedScene& p) {
    auto array = [](const char* name, const auto& v) {
        using Vector = std::decay_t<decltype(v)>;
        using Allocator = typename Vector::allocator_type;
        SceneArray a{name, v.data(), sizeof(v[0]), v.size()};
        if constexpr (std::is_same_v<Allocator, DefaultInitAllocator<typename Vector::value_type>>) {
            if (v.capacity() * sizeof(v[0]) >= Allocator::kPagedFrom) a.page_bytes = Allocator::allocation_bytes(v.capacity());
        }
        return a;
    };
    return {
        array("bvh_nodes", p.bvh.nodes),
        array("triangles", p.scene.triangles),
        array("normals", p.scene.normals),
        array("uvs", p.scene.uvs),
        array("materials", p.scene.materials),
        array("textures", p.scene.textures),
        array("texels", p.scene.texels),
        array("lights", p.tree.lights),
        array("light_tree_nodes", p.tree.nodes),
        array("environment", p.scene.environment.rgb),
        // kBvh4NodeWords 16-byte words a node, as the kernels declare it.
        SceneArray{"wide_bvh_nodes", p.bvh.kernel_nodes.data(), sizeof(gpu::Bvh4Node) / gpu::kBvh4NodeWords,
                   gpu::kBvh4NodeWords * p.bvh.kernel_nodes.size()},
    };
}

}  // namespace lc
