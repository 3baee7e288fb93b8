// Wavefront OBJ/MTL meshes (through tinyobjloader) into the scene's triangles.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "float_limits.h"
#include "lightcuts/scene.h"

namespace lc::loader {

// A mesh's placement: p' = position * p; normals go through the inverse transpose.
struct MeshTransform {
    glm::mat4 position{1.0f};
    glm::mat3 normal{1.0f};
    bool mirrors = false;  // odd number of negative scales flips winding
    // A triangle's corners in the order that keeps the file's winding in
    // world space: corners 1 and 2 swapped where the transform mirrors, so
    // that (v1 - v0) x (v2 - v0), which decides the side an emissive
    // surface emits from (host/area_lights.cpp, lc_surface_emission),
    // faces the side the file meant.
    template <class Corners>
    Corners file_winding(Corners corners) const {
        if (mirrors) std::swap(corners[1], corners[2]);
        return corners;
    }
    // Where it was written (the scene file and its field, e.g.
    // "meshes[1].transform"), for an error it causes; empty for none.
    std::string scene_file, field;
};

// The scene under construction, as the meshes see it.
struct MeshTarget {
    Scene& scene;
    Box geometry;  // around every triangle kept so far, in double
    std::optional<std::uint32_t> default_material;  // index, added on first use
    // Texture files loaded so far (their normalised absolute paths) and
    // their scene.textures index: an image that several meshes' MTLs name,
    // or one OBJ listed several times, is decoded and stored once.
    std::map<std::filesystem::path, std::uint32_t> textures;
};

// Appends the OBJ's triangles (transformed; degenerate ones dropped and
// counted) and its MTL materials, or the one override material, to
// target.scene. Throws InputError naming the OBJ and the place in it; also
// when the geometry so far would be too large for floats (float_limits.h),
// and naming the transform's field when it alone makes every triangle
// degenerate (a scale too small for floats).
void load_obj(const std::filesystem::path& file, const MeshTransform& transform,
              const std::optional<gpu::Material>& override_material, MeshTarget& target);

}  // namespace lc::loader
