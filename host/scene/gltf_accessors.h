// Reading glTF accessors (positions, normals, texture coordinates, indices)
// out of tinygltf's buffers, with every offset, stride, count and value
// checked first: a malformed file gets an InputError, never a read past a
// buffer.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace tinygltf {
class Model;
}

namespace lc::loader {

class GltfAccessors {
public:
    // `file` names the glTF in error messages; the model must outlive this.
    GltfAccessors(const tinygltf::Model& model, std::string file) : model_(model), file_(std::move(file)) {}

    // The accessor `index` as VEC3 floats (FLOAT components only), every
    // value finite. `field` is the glTF path that named the accessor
    // ("meshes[0].primitives[1].attributes.POSITION") for error messages.
    // The last few decoded are kept for the primitives that name them next:
    // exporters split one vertex array into many primitives (10,000 over
    // one POSITION accessor of 10^6 triangles took 25 s to load, decoding
    // it again for each; an audit of large meshes).
    std::shared_ptr<const std::vector<glm::vec3>> vec3s(int index, const std::string& field) const;

    // VEC2 texture coordinates: FLOAT, or normalized UNSIGNED_BYTE/SHORT;
    // kept as vec3s are.
    std::shared_ptr<const std::vector<glm::vec2>> vec2s(int index, const std::string& field) const;

    // SCALAR vertex indices (UNSIGNED_BYTE/SHORT/INT), each below
    // vertex_count.
    std::vector<std::uint32_t> indices(int index, const std::string& field, std::size_t vertex_count) const;

private:
    const tinygltf::Model& model_;
    std::string file_;
    // The accessors last decoded, newest last: a primitive's positions and
    // normals, and its texture coordinates.
    static constexpr std::size_t kRecent = 2;
    mutable std::vector<std::pair<int, std::shared_ptr<const std::vector<glm::vec3>>>> recent_vec3s_;
    mutable std::vector<std::pair<int, std::shared_ptr<const std::vector<glm::vec2>>>> recent_vec2s_;

    // The accessor's components as doubles (count * components values),
    // sparse substitutions applied; integers normalized when the accessor
    // says so.
    std::vector<double> components(int index, const std::string& field, int type,
                                   std::initializer_list<int> component_types) const;
};

}  // namespace lc::loader
