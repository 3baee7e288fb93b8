// glTF 2.0 (.gltf and .glb, through Debian's tinygltf) into the scene:
// meshes under their node hierarchy, materials and textures, the
// KHR_lights_punctual lights and the perspective cameras
// (docs/scene-format.md, "glTF").
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "lightcuts/scene.h"
#include "obj_loader.h"

namespace lc::loader {

// A light of the glTF, placed by its node; `field` names that node for
// error messages ("nodes[4].extensions.KHR_lights_punctual").
struct GltfLight {
    gpu::Light light;
    std::string field;
};

// A perspective camera, placed by its node, with the glTF camera's name.
struct GltfCamera {
    std::string name;
    Camera camera;
};

struct GltfContents {
    std::vector<GltfLight> lights;    // in node order, not yet checked against the scene's totals
    std::vector<GltfCamera> cameras;  // in node order
    // The cameras skipped for their type ("orthographic"), by name, so that
    // --camera naming one says why it is not there.
    std::vector<std::pair<std::string, std::string>> skipped_cameras;
};

// True for a path ending in .gltf or .glb (any case).
bool is_gltf_path(const std::filesystem::path& file);

// Appends the triangles of the file's scene (every node's world transform,
// then `transform`), their materials and textures to target.scene, notes
// about what was skipped to Scene::load_notes, and returns the lights and
// cameras (placed by the same transforms). Throws InputError naming the
// file and the glTF path ("meshes[2].primitives[0].attributes.POSITION").
GltfContents load_gltf(const std::filesystem::path& file, const MeshTransform& transform, MeshTarget& target);

// A whole scene from one glTF file: its lights, the perspective camera named
// `camera` (empty: the first in node order; none: a default framing of the
// bounds) and the default render settings, but method lightcuts.
Scene load_gltf_scene(const std::filesystem::path& file, const std::string& camera);

// Image size of a glTF camera: 256 rows, aspectRatio x 256 columns.
inline constexpr std::uint32_t kGltfImageHeight = 256;
// Vertical field of view of the default framing, in degrees.
inline constexpr float kDefaultFramingFovDegrees = 40.0f;

}  // namespace lc::loader
