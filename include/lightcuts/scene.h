// Scene description: camera, triangles, materials, lights, render settings.
// The vectors hold exactly the records the GPU reads (shaders/lc_shared/types.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "settings.h"
#include "lc_shared/types.h"

namespace lc {

struct Camera {
    glm::vec3 position{0.0f, 0.0f, 1.0f};
    glm::vec3 look_at{0.0f, 0.0f, 0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_degrees = 40.0f;
    std::uint32_t width = 256;
    std::uint32_t height = 256;
};

// Indirect light through virtual point lights (the render block's
// "indirect" object; host/vpls.h).
struct IndirectSettings {
    std::uint32_t vpls = 0;         // VPLs to leave; 0: direct light only
    std::uint32_t max_bounces = 3;  // VPLs per light path at most; 0: until Russian roulette ends it
    float clamp = 0.0f;             // VPLs' 1/d^2 stops growing below this distance (scene
                                    // units): biased, darker in corners; 0: none (consistent)
};

struct RenderSettings {
    std::string method = "brute";   // "brute", "lightcuts", "sampled", "stochastic" or "path"
    std::uint32_t spp = 1;          // camera rays per pixel (stratified, jittered)
    float relative_error = 0.02f;   // lightcuts: refine while bound > this * estimate
    std::uint32_t max_cut = 1000;   // lightcuts: largest cut per shaded point
    std::uint32_t cut_heap = kDefaultCutHeap;  // lightcuts: cut-heap capacity K per shaded point
    std::string cut_sharing = "auto";  // lightcuts: "pixel", "quad", "octet" or "auto" ("octet" on the CPU, "pixel" on Vulkan)
    std::uint32_t seed = 1;         // pixel jitter, light-tree representatives, light samples
    std::uint32_t light_samples = 1;  // sampled: lights per camera sample; stochastic: draws per cluster
    std::string light_pick = "tree";  // sampled: "tree", "uniform" or "power"
    // Point samples the emissive triangles become, in all (area_lights.h).
    std::uint32_t area_light_samples = 65536;
    IndirectSettings indirect;
    std::uint32_t max_bounces = 0;  // path: surface interactions per path; 0: unlimited (roulette)
    double time_limit = 0.0;        // path: seconds, the sample passes sized to end near it; 0: none
};

// An environment map holds at most 2^27 pixels (a 16384 x 8192 lat-long
// map: 1.5 GiB as RGB floats), the limit all textures share (kMaxTexels).
inline constexpr std::uint64_t kMaxEnvironmentPixels = std::uint64_t(1) << 27;

// An environment: lat-long RGB radiance, +Y up (docs/scene-format.md). A
// constant sky is a 1 x 1 map. Lights the scene as `directions` directional
// lights and is what camera rays that leave the scene see.
struct Environment {
    std::uint32_t width = 0, height = 0;  // 0: no environment; at most kMaxEnvironmentPixels
    std::vector<float> rgb;               // row 0 at the top, the scene's scale applied
    std::uint32_t directions = 3000;
    bool present() const { return width > 0 && height > 0; }
};

struct Scene {
    Camera camera;
    std::vector<gpu::Triangle> triangles;        // material index inside
    std::vector<gpu::TriangleNormals> normals;   // parallel to triangles
    std::vector<gpu::TriangleUvs> uvs;           // parallel to triangles (zeros without UVs), or empty
    std::vector<gpu::Material> materials;
    std::vector<gpu::TextureInfo> textures;      // Material.*_texture index these
    std::vector<std::uint32_t> texels;           // RGBA8 texels of all textures (TextureInfo.offset)
    std::vector<gpu::Light> lights;              // all types, in file order
    Environment environment;
    RenderSettings render;
    std::filesystem::path file;                  // the scene file it came from
    // Every file the loader read (the scene, meshes, material libraries,
    // light lists, textures, the environment, glTF buffers and images):
    // what a render's outputs may not replace.
    std::vector<std::filesystem::path> input_files;
    std::size_t degenerate_triangles_dropped = 0;
    // What the loader read but left out or approximated (glTF features it
    // does not support), one "FILE: FIELD: TEXT" line each; the CLI prints them.
    std::vector<std::string> load_notes;

    // Bounds of the triangles only, not of the lights (a zero box at the
    // origin if there are none). They scale the inverse-square clamp, so a
    // light far outside the geometry must not widen them (update_bounds).
    glm::vec3 bounds_min{0.0f};
    glm::vec3 bounds_max{0.0f};

    std::size_t count_lights(std::uint32_t type) const;
    // Triangles whose material emits: what area-light samples and the path
    // tracer's emitters come from.
    std::size_t count_emissive_triangles() const;
};

struct SceneOptions {
    // glTF scenes: the perspective camera of this name (empty: the first in
    // node order). A JSON scene has its own camera and refuses this.
    std::string camera;
    // Threads that read light lists (CSV files); 0: one per core.
    unsigned threads = 0;
};

// Loads a scene from JSON, or from a glTF 2.0 file (.gltf or .glb) on its
// own (docs/scene-format.md). Throws InputError naming the file and the
// field on any problem; never returns a half-loaded scene. Also refuses what
// would overflow the renderer's float sums: a per-type, per-channel light
// intensity total above FLT_MAX, or a box around the geometry and the point
// lights whose extent along an axis exceeds 1e19 (loader::kMaxExtent).
Scene load_scene(const std::filesystem::path& file, const SceneOptions& options = {});

// Parses "x,y,z,r,g,b" lines into point lights (optional header line, '#'
// comments). Throws InputError naming the file and line number, also for the
// first line where the lights' total intensity overflows a float or their
// extent passes 1e19.
std::vector<gpu::Light> load_points_csv(const std::filesystem::path& file);

// Recomputes scene.bounds_min/max from the triangles alone (lights are left
// out). Throws InputError naming scene.file and the triangle when a vertex is
// not finite as a float or the extent along an axis passes 1e19.
void update_bounds(Scene& scene);

// Checks a scene as the loaders check what they read, for one built or
// changed in code; prepare_scene calls it. Throws InputError naming
// scene.file ("scene" where it is empty) and the field: a camera that is not
// finite, has look_at at its position or up along the view, a field of view
// outside (0, 180) degrees or a width or height outside 1 to 16384;
// normals not one per triangle, uvs neither one per triangle nor none, a
// triangle whose material is not one of the scene's, a vertex, normal or uv
// that is not finite; a material value outside its range (colours and the
// Disney parameters 0 to 1, emission finite and not negative, alpha above 0
// to 1 where there is a GGX or Disney lobe) or, where it is textured
// (kMaterialTextured), naming a texture the scene does not have, a texture
// reaching past the texels; an environment whose rgb is not three values a
// pixel, finite and not negative, of more than kMaxEnvironmentPixels, or
// whose directions are out of range, and render counts prepare_scene uses
// (area_light_samples, indirect) out of range; a light of no known type, not
// finite, of negative intensity, without a unit direction or axis where its
// type has one, a spot whose cosines are out of order, or lights whose
// totals or extent the loaders refuse (load_scene above).
void check_scene(const Scene& scene);

}  // namespace lc
