// load_gltf: one glTF file's node hierarchy into the scene (gltf_loader.h).
#include "gltf_loader.h"

#include <algorithm>
#include <cstdio>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "gltf_accessors.h"
#include "gltf_file.h"
#include "gltf_materials.h"
#include "input_file.h"
#include "light_records.h"
#include "lightcuts/error.h"
#include "lightcuts/settings.h"

namespace lc::loader {
namespace {

namespace fs = std::filesystem;

glm::dvec3 finite_vec3(const std::vector<double>& v, std::size_t size, glm::dvec3 fallback, const std::string& name,
                       const std::string& field) {
    if (v.empty()) return fallback;
    if (v.size() != size) throw InputError(name, field, "must have " + std::to_string(size) + " numbers");
    for (std::size_t i = 0; i < size; ++i)
        if (!std::isfinite(v[i]) || std::abs(v[i]) > double(std::numeric_limits<float>::max()))
            throw InputError(name, field + "[" + std::to_string(i) + "]", "must be a finite float");
    return glm::dvec3(v[0], v[1], v[2]);
}

// glTF 3.5.3: the node's matrix, or T * R * S.
glm::dmat4 local_matrix(const tinygltf::Node& node, const std::string& name, const std::string& field) {
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) throw InputError(name, field + ".matrix", "must have 16 numbers");
        glm::dmat4 m;
        for (int i = 0; i < 16; ++i) {
            const double v = node.matrix[std::size_t(i)];
            if (!std::isfinite(v) || std::abs(v) > double(std::numeric_limits<float>::max()))
                throw InputError(name, field + ".matrix[" + std::to_string(i) + "]", "must be a finite float");
            m[i / 4][i % 4] = v;  // column-major, as glTF stores it
        }
        // glTF 3.5.3: a node's matrix is a transform of translation,
        // rotation and scale; its last row is 0, 0, 0, 1 (a projective one
        // would send points to w = 0).
        if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
            throw InputError(name, field + ".matrix", "its last row (elements 3, 7, 11, 15) must be 0, 0, 0, 1");
        return m;
    }
    const glm::dvec3 t = finite_vec3(node.translation, 3, glm::dvec3(0.0), name, field + ".translation");
    const glm::dvec3 s = finite_vec3(node.scale, 3, glm::dvec3(1.0), name, field + ".scale");
    glm::dquat q(1.0, 0.0, 0.0, 0.0);
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) throw InputError(name, field + ".rotation", "must have 4 numbers (x, y, z, w)");
        for (int i = 0; i < 4; ++i)
            if (!std::isfinite(node.rotation[std::size_t(i)]))
                throw InputError(name, field + ".rotation[" + std::to_string(i) + "]", "must be finite");
        q = glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        const double length = glm::length(q);
        if (!(length > 0.0) || !std::isfinite(length))
            throw InputError(name, field + ".rotation", "must be a non-zero quaternion");
        q /= length;
    }
    glm::dmat4 m = glm::mat4_cast(q);
    m[0] *= s.x;
    m[1] *= s.y;
    m[2] *= s.z;
    m[3] = glm::dvec4(t, 1.0);
    return m;
}

const char* mode_name(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS: return "POINTS";
        case TINYGLTF_MODE_LINE: return "LINES";
        case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
        default: return "LINE_STRIP";
    }
}

bool is_finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

class NodeWalker {
public:
    NodeWalker(const tinygltf::Model& model, const fs::path& file, const MeshTransform& transform, MeshTarget& target)
        : model_(model), name_(display(file)), transform_(transform), target_(target), notes_(target.scene, name_),
          accessors_(model, name_), materials_(model, target.scene, notes_) {}

    GltfNotes& notes() { return notes_; }

    GltfContents walk() {
        std::vector<int> roots;
        // The file's `scene`; without one the first of its scenes, as
        // viewers take it (the spec leaves it to the reader).
        const int scene = model_.defaultScene >= 0 ? model_.defaultScene : model_.scenes.empty() ? -1 : 0;
        if (model_.defaultScene < 0 && model_.scenes.size() > 1)
            notes_.add("scenes", "the file names no default scene (`scene`); the first of its " +
                                     std::to_string(model_.scenes.size()) + " scenes is drawn");
        if (scene >= 0) {
            if (std::size_t(scene) >= model_.scenes.size())
                fail("scene", "scene " + std::to_string(scene) + " out of range (" +
                                  std::to_string(model_.scenes.size()) + " scenes)");
            roots = model_.scenes[std::size_t(scene)].nodes;
        } else {
            // No scene at all: every node that is nobody's child.
            std::vector<bool> child(model_.nodes.size(), false);
            for (const tinygltf::Node& n : model_.nodes)
                for (const int c : n.children)
                    if (c >= 0 && std::size_t(c) < child.size()) child[std::size_t(c)] = true;
            for (std::size_t i = 0; i < child.size(); ++i)
                if (!child[i]) roots.push_back(int(i));
        }
        visited_.assign(model_.nodes.size(), false);
        const glm::dmat4 base(transform_.position);
        for (std::size_t i = 0; i < roots.size(); ++i)
            visit(roots[i], base,
                  scene >= 0 ? "scenes[" + std::to_string(scene) + "].nodes[" + std::to_string(i) + "]"
                             : "nodes[" + std::to_string(roots[i]) + "]");
        if (kept_ == 0 && !flattened_.empty())
            fail(flattened_, "its transform makes every triangle of its mesh degenerate (a scale of 0, or one too "
                             "small for floats?), and no other triangle is left");
        if (kept_ == 0) fail("", "no usable triangles (after dropping degenerate ones)");
        return std::move(contents_);
    }

private:
    const tinygltf::Model& model_;
    std::string name_;
    const MeshTransform& transform_;
    MeshTarget& target_;
    GltfNotes notes_;
    GltfAccessors accessors_;
    GltfMaterials materials_;
    std::vector<bool> visited_;
    GltfContents contents_;
    std::size_t kept_ = 0;
    std::size_t degenerate_by_transform_ = 0;  // triangles that only the transform made degenerate
    std::string flattened_;  // the first node whose transform left nothing of its mesh

    [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
        throw InputError(name_, field, problem);
    }

    // Depth-first with an explicit stack of parents: a node reached twice
    // (a cycle, or two parents) is refused, so the walk always ends.
    void visit(int index, const glm::dmat4& parent, const std::string& field) {
        std::vector<std::pair<int, glm::dmat4>> stack{{index, parent}};
        std::vector<std::string> fields{field};
        while (!stack.empty()) {
            const auto [n, up] = stack.back();
            const std::string from = fields.back();
            stack.pop_back();
            fields.pop_back();
            if (n < 0 || std::size_t(n) >= model_.nodes.size())
                fail(from, "node " + std::to_string(n) + " out of range (" + std::to_string(model_.nodes.size()) +
                               " nodes)");
            const std::string name = "nodes[" + std::to_string(n) + "]";
            if (visited_[std::size_t(n)]) fail(from, name + " is reached twice (a cycle, or a node with two parents)");
            visited_[std::size_t(n)] = true;
            const tinygltf::Node& node = model_.nodes[std::size_t(n)];
            const glm::dmat4 world = up * local_matrix(node, name_, name);
            place(node, name, world);
            // Pushed last to first, so children are placed in file order.
            for (std::size_t c = node.children.size(); c-- > 0;) {
                stack.emplace_back(node.children[c], world);
                fields.push_back(name + ".children[" + std::to_string(c) + "]");
            }
        }
    }

    void place(const tinygltf::Node& node, const std::string& name, const glm::dmat4& world) {
        if (node.skin >= 0) notes_.add(name + ".skin", "skins are not supported; the mesh is drawn unskinned");
        if (node.mesh >= 0) add_mesh(node.mesh, name, world);
        if (node.camera >= 0) add_camera(node.camera, name, world);
        if (const auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end())
            add_light(it->second, name + ".extensions.KHR_lights_punctual", world);
    }

    void add_mesh(int index, const std::string& node, const glm::dmat4& world) {
        if (std::size_t(index) >= model_.meshes.size())
            fail(node + ".mesh", "mesh " + std::to_string(index) + " out of range (" +
                                     std::to_string(model_.meshes.size()) + " meshes)");
        MeshTransform t;
        t.position = glm::mat4(world);
        t.normal = glm::mat3(glm::inverseTranspose(glm::dmat3(world)));
        t.mirrors = glm::determinant(glm::dmat3(world)) < 0.0;
        const tinygltf::Mesh& mesh = model_.meshes[std::size_t(index)];
        const std::size_t kept = kept_, flattened = degenerate_by_transform_;
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
            add_primitive(mesh.primitives[p], "meshes[" + std::to_string(index) + "].primitives[" + std::to_string(p) + "]",
                          t);
        // A node scaled to nothing (tools hide objects with a scale of 0) is
        // left out with a note; the walk fails on it only if nothing else
        // is left.
        if (kept_ == kept && degenerate_by_transform_ > flattened) {
            notes_.add(node, "its transform makes every triangle of meshes[" + std::to_string(index) +
                                 "] degenerate; the node is not drawn");
            if (flattened_.empty()) flattened_ = node;
        }
    }

    // The primitive's corners as index triples (glTF 3.7.2.1 for strips and fans).
    std::vector<std::array<std::uint32_t, 3>> triangles(const tinygltf::Primitive& prim, const std::string& field,
                                                        std::size_t vertices) const {
        std::vector<std::uint32_t> idx;
        if (prim.indices >= 0) {
            idx = accessors_.indices(prim.indices, field + ".indices", vertices);
        } else {
            idx.resize(vertices);
            for (std::size_t i = 0; i < vertices; ++i) idx[i] = std::uint32_t(i);
        }
        std::vector<std::array<std::uint32_t, 3>> out;
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (idx.size() % 3 != 0)
                fail(field + (prim.indices >= 0 ? ".indices" : ".attributes.POSITION"),
                     std::to_string(idx.size()) + " vertices do not make whole triangles");
            for (std::size_t i = 0; i + 2 < idx.size(); i += 3) out.push_back({idx[i], idx[i + 1], idx[i + 2]});
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (std::size_t i = 0; i + 2 < idx.size(); ++i)
                out.push_back(i % 2 == 0 ? std::array{idx[i], idx[i + 1], idx[i + 2]}
                                         : std::array{idx[i], idx[i + 2], idx[i + 1]});
        } else {
            for (std::size_t i = 1; i + 1 < idx.size(); ++i) out.push_back({idx[i], idx[i + 1], idx[0]});
        }
        return out;
    }

    void add_primitive(const tinygltf::Primitive& prim, const std::string& field, const MeshTransform& t) {
        if (prim.mode > TINYGLTF_MODE_TRIANGLE_FAN) fail(field + ".mode", "must be from 0 to 6");
        if (prim.mode >= 0 && prim.mode < TINYGLTF_MODE_TRIANGLES) {
            notes_.add(field + ".mode", std::string(mode_name(prim.mode)) + " is not drawn (only triangles are)");
            return;
        }
        if (!prim.targets.empty()) notes_.add(field + ".targets", "morph targets are not supported; the base shape is used");
        if (prim.extensions.count("KHR_draco_mesh_compression"))
            notes_.add(field + ".extensions.KHR_draco_mesh_compression", "not supported; the uncompressed accessors are used");
        for (const auto& [key, accessor] : prim.attributes)
            if (key.starts_with("COLOR_")) notes_.add(field + ".attributes." + key, "vertex colours are not read");
        const auto position = prim.attributes.find("POSITION");
        if (position == prim.attributes.end()) fail(field + ".attributes.POSITION", "missing");
        const auto positions = accessors_.vec3s(position->second, field + ".attributes.POSITION");
        const std::vector<glm::vec3>& p = *positions;
        static const std::vector<glm::vec3> no_normals;
        static const std::vector<glm::vec2> no_uvs;
        std::shared_ptr<const std::vector<glm::vec3>> normals;
        if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
            normals = accessors_.vec3s(it->second, field + ".attributes.NORMAL");
            if (normals->size() != p.size()) fail(field + ".attributes.NORMAL", "count differs from POSITION's");
        }
        const std::vector<glm::vec3>& n = normals ? *normals : no_normals;
        std::shared_ptr<const std::vector<glm::vec2>> uvs;
        if (const auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
            uvs = accessors_.vec2s(it->second, field + ".attributes.TEXCOORD_0");
            if (uvs->size() != p.size()) fail(field + ".attributes.TEXCOORD_0", "count differs from POSITION's");
        }
        const std::vector<glm::vec2>& uv = uvs ? *uvs : no_uvs;
        std::optional<std::uint32_t> material;
        for (const auto& c : triangles(prim, field, p.size())) {
            if (!add_triangle(p, n, uv, c, t, field)) continue;
            if (!material) material = materials_.material(prim.material, field + ".material");
            target_.scene.triangles.back().material = *material;
            ++kept_;
        }
        // glTF asks for the texture coordinates a material's textures use.
        if (material && uv.empty() && (target_.scene.materials[*material].flags & gpu::kMaterialTextured) != 0u)
            notes_.add(field + ".attributes.TEXCOORD_0",
                       "missing, but the material has textures: they are read at (0, 0) everywhere");
    }

    // False when the triangle is degenerate and dropped (as OBJ faces are).
    bool add_triangle(const std::vector<glm::vec3>& p, const std::vector<glm::vec3>& n,
                      const std::vector<glm::vec2>& uv, const std::array<std::uint32_t, 3>& corners,
                      const MeshTransform& t, const std::string& field) {
        // glTF 2.0, "Transformations": a negative determinant flips the
        // winding; the corners are stored in the order that keeps the side
        // the file's winding means.
        const std::array<std::uint32_t, 3> c = t.file_winding(corners);
        std::array<glm::vec3, 3> v;
        for (int k = 0; k < 3; ++k) v[std::size_t(k)] = glm::vec3(t.position * glm::vec4(p[c[std::size_t(k)]], 1.0f));
        glm::vec3 face;
        const TriangleShape shape = triangle_shape(v, face);
        if (shape == TriangleShape::too_large) fail(field, kTriangleTooLarge);
        if (shape == TriangleShape::degenerate) {
            ++target_.scene.degenerate_triangles_dropped;
            std::array<glm::vec3, 3> raw{p[c[0]], p[c[1]], p[c[2]]};
            glm::vec3 raw_face;
            if (triangle_shape(raw, raw_face) != TriangleShape::degenerate) ++degenerate_by_transform_;
            return false;
        }
        for (const glm::vec3& q : v) target_.geometry.grow(glm::dvec3(q));
        if (const std::string problem = extent_problem(target_.geometry); !problem.empty())
            fail(field, "too far from the rest of the geometry: " + problem);
        std::array<glm::vec3, 3> sn{face, face, face};
        if (!n.empty()) {
            for (std::size_t k = 0; k < 3; ++k) {
                if (!unit_vector(glm::dvec3(t.normal * n[c[k]]), sn[k])) {
                    sn = {face, face, face};  // a zero normal would poison shading
                    break;
                }
            }
        }
        Scene& s = target_.scene;
        s.uvs.resize(s.triangles.size());  // earlier OBJ meshes have none
        s.triangles.push_back(gpu::Triangle{v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z,
                                            0u, 0u, 0u});
        s.normals.push_back(gpu::TriangleNormals{sn[0].x, sn[0].y, sn[0].z, sn[1].x, sn[1].y, sn[1].z, sn[2].x,
                                                 sn[2].y, sn[2].z, 0u, 0u, 0u});
        gpu::TriangleUvs t_uv{};
        if (!uv.empty())
            t_uv = {uv[c[0]].x, uv[c[0]].y, uv[c[1]].x, uv[c[1]].y, uv[c[2]].x, uv[c[2]].y};
        s.uvs.push_back(t_uv);
        return true;
    }

    // A direction of the node's frame in world space, normalised; `what`
    // names it for the error when the transform collapses it.
    glm::dvec3 direction(const glm::dmat4& world, glm::dvec3 local, const std::string& field, const char* what) const {
        const glm::dvec3 d = glm::dmat3(world) * local;
        const double length = glm::length(d);
        if (!(length > 0.0) || !std::isfinite(length))
            fail(field, std::string("the node's transform leaves no usable ") + what + " direction");
        return d / length;
    }

    // kGltfImageHeight rows and aspect times as many columns (as many rows
    // as columns without an aspect ratio); where that is more than
    // kMaxImageSide columns, or less than one, the size is scaled to fit,
    // with a note.
    void image_size(double aspect, const std::string& name, Camera& c) {
        c.width = c.height = kGltfImageHeight;
        if (!(aspect > 0.0)) return;
        const double side = double(kMaxImageSide);
        double width = aspect * kGltfImageHeight, height = kGltfImageHeight;
        if (width > side) {
            height = std::max(1.0, std::round(side / aspect));
            width = side;
        } else if (width < 1.0) {
            height = std::min(side, std::round(1.0 / aspect));
            width = 1.0;
        }
        c.width = std::uint32_t(std::max(1.0, std::round(width)));
        c.height = std::uint32_t(height);
        if (height != kGltfImageHeight)
            notes_.add(name + ".perspective.aspectRatio",
                       "the camera's image is " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                           " to keep each side within " + std::to_string(kMaxImageSide) +
                           " pixels (--width and --height choose another)");
    }

    void add_camera(int index, const std::string& node, const glm::dmat4& world) {
        if (std::size_t(index) >= model_.cameras.size())
            fail(node + ".camera", "camera " + std::to_string(index) + " out of range (" +
                                       std::to_string(model_.cameras.size()) + " cameras)");
        const std::string name = "cameras[" + std::to_string(index) + "]";
        const tinygltf::Camera& cam = model_.cameras[std::size_t(index)];
        if (cam.type != "perspective") {
            notes_.add(name, "camera type \"" + cam.type + "\" is skipped (only perspective cameras are read)");
            contents_.skipped_cameras.emplace_back(cam.name, cam.type);
            return;
        }
        // In degrees and as the float the camera keeps: a yfov just inside
        // (0, pi) may round to 0 or 180 degrees. 0 where the file has none
        // (check_gltf_types refuses a 0 it has).
        const double radians = cam.perspective.yfov;
        const float yfov = float(radians * 180.0 / 3.14159265358979323846);
        if (!(radians > 0.0 && radians < 3.14159265358979323846))
            fail(name + ".perspective.yfov", "must be in (0, pi)");
        if (!(yfov > 0.0f && yfov < 180.0f))
            fail(name + ".perspective.yfov", "is so near " + std::string(yfov > 0.0f ? "pi" : "0") +
                                                 " that it is " + (yfov > 0.0f ? "180" : "0") +
                                                 " degrees as a float");
        Camera c;
        const glm::dvec3 position(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
        c.position = glm::vec3(position);
        if (!is_finite(c.position)) fail(node, "the camera's position is not finite");
        const glm::dvec3 view = direction(world, {0.0, 0.0, -1.0}, node, "view");
        const glm::dvec3 up = direction(world, {0.0, 1.0, 0.0}, node, "up");
        if (!(glm::length(glm::cross(view, up)) > 1e-6))
            fail(node, "the camera's up is parallel to its view direction");
        // As far along the view as the camera is from the origin (a point a
        // unit away from a far camera would round its direction away), but
        // not so far that the square of the distance leaves the float range
        // (the JSON loader's limit on camera.look_at).
        // Farther out the floats round the direction away (past 1e25 or
        // so), which is refused.
        c.look_at = glm::vec3(position + view * std::clamp(glm::length(position), 1.0, 1e18));
        const glm::dvec3 forward = glm::dvec3(c.look_at) - glm::dvec3(c.position);
        if (!(glm::dot(forward, view) > (1.0 - 1e-6) * glm::length(forward))) {
            char distance[32];
            std::snprintf(distance, sizeof distance, "%.3g", glm::length(position));
            fail(node, "the camera is too far from the origin (" + std::string(distance) +
                           ") for a float to keep its view direction");
        }
        c.up = glm::vec3(up);
        c.fov_y_degrees = yfov;
        image_size(cam.perspective.aspectRatio, name, c);
        contents_.cameras.push_back({cam.name, c});
    }

    void add_light(const tinygltf::Value& ext, const std::string& field, const glm::dmat4& world) {
        if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt())
            fail(field + ".light", "must be the index of a light");
        const int index = ext.Get("light").GetNumberAsInt();
        if (index < 0 || std::size_t(index) >= model_.lights.size())
            fail(field + ".light", "light " + std::to_string(index) + " out of range (" +
                                       std::to_string(model_.lights.size()) + " lights)");
        const std::string name = "extensions.KHR_lights_punctual.lights[" + std::to_string(index) + "]";
        const tinygltf::Light& l = model_.lights[std::size_t(index)];
        const glm::dvec3 colour = finite_vec3(l.color, 3, glm::dvec3(1.0), name_, name + ".color");
        if (colour.r < 0.0 || colour.g < 0.0 || colour.b < 0.0) fail(name + ".color", "must not be negative");
        if (!(l.intensity >= 0.0) || !std::isfinite(l.intensity)) fail(name + ".intensity", "must be finite and >= 0");
        // The intensity is read as the radiometric value: 1 cd as 1 W/sr, 1 lx as 1 W/m^2.
        const glm::dvec3 value = colour * l.intensity;
        for (int i = 0; i < 3; ++i)
            if (value[i] > double(std::numeric_limits<float>::max()))
                fail(name + ".intensity", "color x intensity overflows a float");
        if (l.range > 0.0) notes_.add(name + ".range", "ignored: lights fall off with the inverse square everywhere");
        const glm::vec3 position(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
        if (!is_finite(position)) fail(field, "the light's position is not finite");
        LightProblem problem;
        gpu::Light light;
        if (l.type == "point") {
            light = point_light(position, glm::vec3(value));
        } else if (l.type == "directional") {
            light = directional_light(glm::vec3(direction(world, {0.0, 0.0, -1.0}, field, "light")), glm::vec3(value), problem);
        } else if (l.type == "spot") {
            constexpr double kHalfPi = 1.57079632679489661923, kDegrees = 90.0 / kHalfPi;
            // Exporters that keep angles in floats write pi/2 as 1.5707964,
            // the shortest decimal of float(pi/2), a hair above pi/2: any
            // angle that rounds to that float is taken as pi/2.
            const auto angle = [&](double a) { return a > kHalfPi && float(a) <= float(kHalfPi) ? kHalfPi : a; };
            const double inner = angle(l.spot.innerConeAngle) * kDegrees, outer = angle(l.spot.outerConeAngle) * kDegrees;
            light = spot_light(position, glm::vec3(direction(world, {0.0, 0.0, -1.0}, field, "light")), glm::vec3(value),
                               float(inner), float(outer), problem);
            if (problem.field == "outer_cone_degrees") fail(name + ".spot.outerConeAngle", "must be from 0 to pi/2");
            if (problem.field == "inner_cone_degrees") fail(name + ".spot.innerConeAngle", "must be from 0 to outerConeAngle");
        } else {
            fail(name + ".type", "unknown light type \"" + l.type + "\" (expected point, directional or spot)");
        }
        if (problem) fail(field, problem.problem);
        contents_.lights.push_back({light, field});
    }
};

}  // namespace

bool is_gltf_path(const fs::path& file) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".gltf" || ext == ".glb";
}

GltfContents load_gltf(const fs::path& file, const MeshTransform& transform, MeshTarget& target) {
    GltfNotes file_notes(target.scene, display(file));
    const tinygltf::Model model = read_gltf_file(file, file_notes);
    NodeWalker walker(model, file, transform, target);
    return walker.walk();
}

}  // namespace lc::loader
