// glTF materials (pbrMetallicRoughness and the KHR_materials_* extensions we
// read) into Disney materials, and their images into the scene's textures
// (docs/scene-format.md, "glTF").
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "lightcuts/scene.h"

#include "materials.h"
#include "textures.h"

namespace tinygltf {
class Model;
class Value;
struct Material;
}

namespace lc::loader {

// What a glTF loader skipped, as "FILE: FIELD: TEXT" lines in
// Scene::load_notes, each line once.
class GltfNotes {
public:
    GltfNotes(Scene& scene, std::string file) : scene_(scene), file_(std::move(file)) {}
    void add(const std::string& field, const std::string& text);
    const std::string& file() const { return file_; }

private:
    Scene& scene_;
    std::string file_;
    std::set<std::string> seen_;
};

class GltfMaterials {
public:
    GltfMaterials(const tinygltf::Model& model, Scene& scene, GltfNotes& notes)
        : model_(model), scene_(scene), notes_(notes) {}

    // The scene.materials index of glTF material `index`, converted on first
    // use; -1 is glTF's default material (white, metallic 1, roughness 1).
    // `field` names the primitive that asked, for an index out of range.
    std::uint32_t material(int index, const std::string& field);

private:
    const tinygltf::Model& model_;
    Scene& scene_;
    GltfNotes& notes_;
    std::map<int, std::uint32_t> materials_;  // glTF material -> scene material
    std::map<int, std::uint32_t> images_;     // glTF image -> scene texture, so a shared image is added once

    gpu::Material convert(int index);
    DisneyParams params(const tinygltf::Material& g, const std::string& name);
    void add_textures(gpu::Material& m, const tinygltf::Material& g, const std::string& name);
    // The scene texture for a material's texture reference (its texture,
    // texCoord and extensions: the sampler and KHR_texture_transform
    // decide how it is sampled), or kInvalidIndex where it is left out
    // (with a note).
    std::uint32_t texture(int texture, int tex_coord, const std::map<std::string, tinygltf::Value>& extensions,
                          const std::string& field);
    // KHR_texture_transform `ext` (at `field`) into sampling's uv_transform;
    // its texCoord, where it has one, into tex_coord.
    void read_transform(const tinygltf::Value& ext, const std::string& field, int& tex_coord,
                        TextureSampling& sampling) const;
    // The scene texture of glTF image `index` (sampled as by default),
    // added on first use.
    std::uint32_t image(int index);
};

}  // namespace lc::loader
