// load_obj: one OBJ file's faces and materials into the scene (obj_loader.h).
#include "obj_loader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <istream>
#include <limits>
#include <map>
#include <set>
#include <streambuf>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include <tiny_obj_loader.h>

#include "input_file.h"
#include "lightcuts/error.h"
#include "materials.h"
#include "obj_numbers.h"
#include "polygon.h"
#include "textures.h"

namespace lc::loader {
namespace {

using Corners = std::array<tinyobj::index_t, 3>;


// What tinyobjloader makes of an OBJ and its material libraries.
struct ObjData {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    // The folder of the MTL file each material came from, which its
    // texture paths are relative to.
    std::vector<std::filesystem::path> material_folders;
    std::size_t short_faces = 0;  // of one or two corners, which tinyobj skips with a warning
};

// A std::istream over text that stays where it is (an OBJ may be hundreds
// of MB: no copy).
class TextBuffer : public std::streambuf {
public:
    explicit TextBuffer(std::string_view text) {
        char* begin = const_cast<char*>(text.data());  // only read
        setg(begin, begin, begin + text.size());
    }
};

// tinyobjloader's material reader for the `mtllib` lines, so that
// tinyobjloader opens no file itself: each library is found beside the OBJ
// (or at its absolute path), read by read_input_file (it is one of the
// scene's inputs, with or without a material override), its numbers checked
// when its materials are used, a byte order mark skipped, and its text
// handed to tinyobjloader's MTL parser. A library must be a regular file:
// tinyobjloader would read /dev/zero until memory runs out and take a folder
// for an empty library. Problems are kept, not thrown through
// tinyobjloader, and raised by rethrow() after it returns.
//
// A `mtllib` line may name several libraries, all of which the OBJ format
// reads. tinyobjloader asks for the line's names in turn and stops at the
// first it gets, so on that one the rest of the line is read too (`obj`,
// the OBJ's text, gives the lines); a name that is not found is skipped,
// as tinyobjloader skips it, and a line none of whose files is found is an
// error where the materials are used.
class MtlLibraries : public tinyobj::MaterialReader {
public:
    MtlLibraries(std::filesystem::path folder, const std::string& obj_name, bool uses_mtl, std::string_view obj,
                 std::vector<std::filesystem::path>& material_folders)
        : folder_(std::move(folder)), obj_name_(obj_name), uses_mtl_(uses_mtl), material_folders_(material_folders) {
        for_each_line(obj, [&](const Line& line) {
            if (line.words[0] == "mtllib") lines_.emplace_back(line.words.begin() + 1, line.words.end());
        });
    }

    bool operator()(const std::string& given, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* material_map, std::string* warn, std::string* err) override {
        if (problem_) return false;
        try {
            // tinyobjloader splits a mtllib line at spaces only: a line that
            // ends in a space gives an empty last name, a tab stays in the
            // name. The first of its words is the name (the line's words,
            // lines_, give the rest).
            std::string library;
            for_each_line(given, [&](const Line& line) {
                if (library.empty()) library = line.words[0];
            });
            if (library.empty()) return false;
            if (!read(library, materials, material_map, warn, err)) {
                if (missing_.empty()) missing_ = library;
                return false;  // tinyobjloader tries the line's next file name
            }
            missing_.clear();  // (see missing_)
            // The names after this one on its line: the first line from the
            // last one read on that names it (tinyobjloader reads the
            // lines in order, one call for each until a name is found).
            for (; next_line_ < lines_.size(); ++next_line_) {
                const std::vector<std::string>& names = lines_[next_line_];
                const auto self = std::find(names.begin(), names.end(), library);
                if (self == names.end()) continue;
                for (auto next = self + 1; next != names.end(); ++next) read(*next, materials, material_map, warn, err);
                ++next_line_;
                break;
            }
            return true;
        } catch (...) {
            problem_ = std::current_exception();
            return false;
        }
    }

    // Whether the OBJ has a mtllib line.
    bool any() const { return !lines_.empty(); }

    // Throws the first problem met, if any; else, when the materials are
    // used and a `mtllib` line found none of its files, InputError naming it.
    void rethrow(const std::string& warning) const {
        if (problem_) std::rethrow_exception(problem_);
        if (uses_mtl_ && warning.find("Failed to load material file") != std::string::npos)
            throw InputError(obj_name_, "mtllib",
                             (missing_.empty() ? std::string("material library") : "'" + missing_ + "'") +
                                 " not found next to the OBJ");
    }

private:
    // Reads the library `name` into the materials; false where it is not
    // found. Throws InputError where it is not a regular file.
    bool read(const std::string& name, std::vector<tinyobj::material_t>* materials,
              std::map<std::string, int>* material_map, std::string* warn, std::string* err) {
        const std::filesystem::path file = folder_ / name;
        const std::string problem = input_file_problem(file);
        if (problem == kFileNotFound) return false;
        if (!problem.empty()) throw InputError(obj_name_, "mtllib", "'" + name + "' " + problem);
        // A library named again (on two mtllib lines) is read once.
        if (!read_.insert(file.lexically_normal()).second) return true;
        const std::string text = read_input_file(file);
        if (uses_mtl_) refuse_utf16(text, display(file));
        const std::string_view mtl = without_bom(text);
        if (uses_mtl_) check_mtl_numbers(mtl, display(file));
        // Each named material's block: whether it has a Kd, and which of
        // the maps the renderer reads it has.
        struct Block {
            bool kd = false, map_kd = false, map_ke = false, norm = false;
        };
        std::vector<Block> blocks;
        bool named = false;
        for_each_line(mtl, [&](const Line& line) {
            const std::string_view key = line.words[0];
            if (key == "newmtl") {
                named = line.words.size() > 1;
                if (named) blocks.emplace_back();
            } else if (named) {
                Block& b = blocks.back();
                b.kd = b.kd || key == "Kd";
                b.map_kd = b.map_kd || key == "map_Kd";
                b.map_ke = b.map_ke || key == "map_Ke";
                b.norm = b.norm || key == "norm";
            }
        });
        const std::size_t first = materials->size();
        TextBuffer buffer(mtl);
        std::istream in(&buffer);
        tinyobj::LoadMtl(material_map, materials, &in, warn, err);
        material_folders_.resize(materials->size(), file.parent_path());
        if (materials->size() - first != blocks.size()) return true;
        for (std::size_t k = 0; k < blocks.size(); ++k) {
            tinyobj::material_t& m = (*materials)[first + k];
            // tinyobjloader reads -s and -o as three numbers: given two,
            // it takes the file name for the third and the map names none.
            for (const auto& [given, name, key] :
                 {std::tuple{blocks[k].map_kd, &m.diffuse_texname, "map_Kd"},
                  std::tuple{blocks[k].map_ke, &m.emissive_texname, "map_Ke"},
                  std::tuple{blocks[k].norm, &m.normal_texname, "norm"}})
                if (given && name->empty())
                    throw InputError(display(file), "material '" + m.name + "'." + key,
                                     "names no texture file (its -s and -o options take three numbers, u v w)");
            // A map_Kd without a Kd is the base colour itself (Kd 1), as a
            // map_Ke without a Ke emits the texture itself; tinyobjloader
            // gives such a material Kd 0.6 (where no Kd came before it in
            // the file).
            if (!blocks[k].kd && blocks[k].map_kd)
                for (tinyobj::real_t& c : m.diffuse) c = 1;
        }
        return true;
    }

    std::filesystem::path folder_;
    const std::string& obj_name_;
    bool uses_mtl_;
    std::vector<std::vector<std::string>> lines_;  // the names of each mtllib line
    std::size_t next_line_ = 0;                    // of lines_, the first not yet read
    std::set<std::filesystem::path> read_;         // the libraries read so far
    // The first of the names not found since the last one found: where the
    // OBJ's last `mtllib` line found none of its files, that line's first.
    // (Where an earlier line found none, a later line's found name clears
    // it, and the message names no file rather than a wrong one.)
    std::string missing_;
    std::exception_ptr problem_;
    std::vector<std::filesystem::path>& material_folders_;
};

// tinyobj treats an unknown usemtl name as a warning and falls back to "no
// material"; silently grey walls are worse than an error. `libraries`:
// whether the OBJ has a mtllib line at all; `obj`, its text, says whether
// a usemtl line comes before the first of them (tinyobjloader reads a
// library where its line is, so a material named earlier is not found).
void check_usemtl_warnings(const std::string& warning, const std::string& obj_name, bool libraries,
                           std::string_view obj) {
    if (const auto at = warning.find("not found in .mtl"); at != std::string::npos) {
        const auto begin = warning.rfind('\n', at);
        const auto from = begin == std::string::npos ? 0 : begin + 1;
        std::size_t first_usemtl = 0, first_mtllib = 0;
        for_each_line(obj, [&](const Line& line) {
            if (line.words[0] == "usemtl" && first_usemtl == 0) first_usemtl = line.number;
            if (line.words[0] == "mtllib" && first_mtllib == 0) first_mtllib = line.number;
        });
        const std::string order = first_usemtl != 0 && first_usemtl < first_mtllib
                                      ? " (line " + std::to_string(first_usemtl) + "'s usemtl comes before line " +
                                            std::to_string(first_mtllib) + "'s mtllib, which reads the library)"
                                      : "";
        throw InputError(obj_name, "usemtl",
                         "tinyobjloader: " + warning.substr(from, at - from) +
                             (libraries ? "not found in .mtl" + order : "not found: the OBJ has no mtllib line"));
    }
}

void read_obj(const std::filesystem::path& file, const std::string& obj_name, bool uses_mtl, ObjData& obj) {
    // tinyobjloader reads a number it cannot parse as 0: checked first. It
    // reads a byte order mark as part of the first line's keyword, losing
    // that line (and shifting every later vertex index): skipped here.
    const std::string bytes = read_input_file(file);
    refuse_utf16(bytes, obj_name);
    const std::string_view text = without_bom(bytes);
    const std::vector<std::size_t> non_finite_normals = check_obj_numbers(text, obj_name);
    TextBuffer buffer(text);
    std::istream in(&buffer);
    MtlLibraries libraries(file.parent_path(), obj_name, uses_mtl, text, obj.material_folders);
    std::string warning, err;
    const bool ok = tinyobj::LoadObj(&obj.attrib, &obj.shapes, &obj.materials, &warning, &err, &in, &libraries,
                                     /*triangulate=*/false, /*default_vcols_fallback=*/false);
    libraries.rethrow(warning);
    if (!ok) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        throw InputError(obj_name, "", "tinyobjloader: " + (err.empty() ? "parse failed" : err));
    }
    if (uses_mtl) check_usemtl_warnings(warning, obj_name, libraries.any(), text);
    for (std::size_t at = warning.find("Degenerated face found"); at != std::string::npos;
         at = warning.find("Degenerated face found", at + 1))
        ++obj.short_faces;
    for (const std::size_t n : non_finite_normals)
        if (3 * n + 2 < obj.attrib.normals.size())
            obj.attrib.normals[3 * n] = obj.attrib.normals[3 * n + 1] = obj.attrib.normals[3 * n + 2] = 0.0f;
}

// Built only on error: the face loop runs once per face. A face of three
// corners is a triangle; a larger one is named a face.
std::string face_name(std::size_t face, const tinyobj::shape_t& shape) {
    const bool triangle = face < shape.mesh.num_face_vertices.size() && shape.mesh.num_face_vertices[face] == 3;
    return (triangle ? "triangle " : "face ") + std::to_string(face + 1) +
           (shape.name.empty() ? std::string() : " of shape '" + shape.name + "'");
}

// One OBJ's faces into target.scene: indices checked, positions and normals
// transformed, degenerate triangles dropped, materials mapped. Construction
// adds the OBJ's materials: either the one override or every MTL material.
class FaceConverter {
public:
    FaceConverter(const ObjData& obj, const MeshTransform& transform,
                  const std::optional<gpu::Material>& override_material, MeshTarget& target,
                  const std::filesystem::path& file, const std::string& obj_name)
        : attrib_(obj.attrib), transform_(transform), target_(target), obj_name_(obj_name),
          override_(override_material.has_value()),
          mtl_count_(override_ ? 0 : obj.materials.size()),
          material_base_(static_cast<std::uint32_t>(target.scene.materials.size())) {
        if (override_material) {
            target_.scene.materials.push_back(*override_material);
            return;
        }
        for (std::size_t i = 0; i < obj.materials.size(); ++i) {
            const tinyobj::material_t& m = obj.materials[i];
            gpu::Material material = convert_mtl(m, obj_name_);
            add_textures(material, m, i < obj.material_folders.size() ? obj.material_folders[i] : file.parent_path());
            target_.scene.materials.push_back(material);
        }
    }

    // Triangles dropped as degenerate that were not so before the transform.
    std::size_t degenerate_by_transform() const { return degenerate_by_transform_; }

    // Returns how many of the shape's triangles were kept.
    std::size_t add_shape(const tinyobj::shape_t& shape) {
        const tinyobj::mesh_t& mesh = shape.mesh;
        std::size_t kept = 0;
        std::size_t first = 0;
        std::vector<glm::vec3> polygon;
        for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
            const std::size_t corners = mesh.num_face_vertices[f];
            const tinyobj::index_t* face = mesh.indices.data() + first;
            first += corners;
            if (corners < 3) continue;  // a line or a point: no surface
            for (std::size_t c = 0; c < corners; ++c) check_index(face[c], f, shape);
            const int mtl_id = mesh.material_ids.empty() ? -1 : mesh.material_ids[f];
            if (corners == 3) {
                kept += add_triangle({face[0], face[1], face[2]}, mtl_id, f, shape) ? 1 : 0;
                continue;
            }
            polygon.clear();
            for (std::size_t c = 0; c < corners; ++c) polygon.push_back(raw_position(face[c].vertex_index));
            for (const auto& [a, b, c] : triangulate_polygon(polygon))
                kept += add_triangle({face[a], face[b], face[c]}, mtl_id, f, shape) ? 1 : 0;
        }
        return kept;
    }

private:
    const tinyobj::attrib_t& attrib_;
    const MeshTransform& transform_;
    MeshTarget& target_;
    const std::string& obj_name_;
    bool override_;
    std::size_t mtl_count_;
    std::uint32_t material_base_;
    std::size_t degenerate_by_transform_ = 0;

    // The MTL's texture maps (docs/scene-format.md): map_Kd scales the
    // albedo (base colour), map_Ke the emission (black or absent Ke counts
    // as 1 where there is a map_Ke), norm is a tangent-space normal map.
    // Paths are relative to the MTL's folder; each file is loaded once in a
    // scene (MeshTarget::textures). A map's -s and -o scale and move its
    // texture coordinates and -clamp on clamps them (sampled_texture); its
    // other options (-t, -imfchan, -bm, -mm, -boost, -blendu, -blendv,
    // -type, -texres, -colorspace) and the maps the renderer has no use for
    // are read but not used, with a note.
    void add_textures(gpu::Material& m, const tinyobj::material_t& mtl, const std::filesystem::path& folder) {
        const std::string where = obj_name_ + ": material '" + mtl.name + "'.";
        const auto note = [&](const std::string& line) {
            if (noted_.insert(line).second) target_.scene.load_notes.push_back(line);
        };
        const auto texture = [&](const std::string& name, const char* key, std::uint32_t gpu::Material::*slot) {
            if (name.empty()) return;
            const tinyobj::texture_option_t& o = key == std::string("map_Kd")   ? mtl.diffuse_texopt
                                                 : key == std::string("norm") ? mtl.normal_texopt
                                                                              : mtl.emissive_texopt;
            const std::string field = "material '" + mtl.name + "'." + key;
            const bool plain = o.turbulence[0] == 0 && o.turbulence[1] == 0 && o.turbulence[2] == 0 &&
                               o.imfchan == 'm' && o.bump_multiplier == 1 && o.brightness == 0 && o.contrast == 1 &&
                               o.sharpness == 1 && o.blendu && o.blendv && o.type == tinyobj::TEXTURE_TYPE_NONE &&
                               o.texture_resolution == -1 && o.colorspace.empty();
            if (!plain)
                note(where + key + ": options other than -s, -o and -clamp are not applied (" +
                     (std::string(key) == "norm" ? "linear" : "sRGB") + ", bilinear)");
            for (int i = 0; i < 2; ++i)
                if (!(std::abs(o.scale[i]) <= std::numeric_limits<float>::max()) ||
                    !(std::abs(o.origin_offset[i]) <= std::numeric_limits<float>::max()))
                    throw InputError(obj_name_, field, "-s and -o must be finite numbers");
            // -s and -o act on OBJ's texture coordinates, whose v grows
            // upwards: in the renderer's (v' = 1 - v) the v offset is
            // 1 - s_v - o_v.
            TextureSampling sampling;
            sampling.uv_transform = {float(o.scale[0]), 0.0f, float(o.origin_offset[0]),
                                     0.0f, float(o.scale[1]), float(1.0 - double(o.scale[1]) - o.origin_offset[1])};
            if (o.clamp) sampling.wrap_u = sampling.wrap_v = gpu::kTextureWrapClamp;
            const std::filesystem::path path = std::filesystem::absolute(folder / name).lexically_normal();
            const auto [at, added] = target_.textures.try_emplace(path, 0u);
            if (added) {
                try {
                    at->second = load_texture(target_.scene, folder / name, obj_name_, field);
                } catch (...) {
                    target_.textures.erase(at);
                    throw;
                }
            }
            set_texture(m, slot, sampled_texture(target_.scene, at->second, sampling));
        };
        // tinyobjloader holds d, or 1 - Tr, as dissolve.
        if (mtl.dissolve < 1.0)
            note(where + "d (or Tr): transparency is not rendered, the surface is opaque");
        if (!mtl.bump_texname.empty()) note(where + "map_Bump is not used (a normal map is read from norm)");
        for (const auto& [name, key] : {std::pair{&mtl.specular_texname, "map_Ks"}, {&mtl.ambient_texname, "map_Ka"},
                                        {&mtl.specular_highlight_texname, "map_Ns"},
                                        {&mtl.displacement_texname, "disp"}, {&mtl.alpha_texname, "map_d"}})
            if (!name->empty()) note(where + key + " is not used");
        texture(mtl.diffuse_texname, "map_Kd", &gpu::Material::base_color_texture);
        texture(mtl.normal_texname, "norm", &gpu::Material::normal_texture);
        if (!mtl.emissive_texname.empty()) {
            if ((m.flags & gpu::kMaterialEmissive) == 0u) set_emission(m, glm::vec3(1.0f), false);
            texture(mtl.emissive_texname, "map_Ke", &gpu::Material::emissive_texture);
        }
    }

    // tinyobj keeps out-of-range indices (only its own triangulation of
    // quads skipped their faces, with a warning). Relative indices reaching
    // back before the first element are refused, with their line, by
    // check_obj_numbers.
    void check_index(const tinyobj::index_t& i, std::size_t f, const tinyobj::shape_t& shape) const {
        const std::size_t vertex_count = attrib_.vertices.size() / 3;
        const std::size_t normal_count = attrib_.normals.size() / 3;
        const std::size_t texcoord_count = attrib_.texcoords.size() / 2;
        if (i.vertex_index < 0 || static_cast<std::size_t>(i.vertex_index) >= vertex_count) {
            throw InputError(obj_name_, face_name(f, shape),
                             "vertex index " + std::to_string(i.vertex_index + 1) + " out of range (" +
                                 std::to_string(vertex_count) + " vertices)");
        }
        if (i.normal_index >= 0 && static_cast<std::size_t>(i.normal_index) >= normal_count) {
            throw InputError(obj_name_, face_name(f, shape),
                             "normal index " + std::to_string(i.normal_index + 1) + " out of range (" +
                                 std::to_string(normal_count) + " normals)");
        }
        if (i.texcoord_index >= 0 && static_cast<std::size_t>(i.texcoord_index) >= texcoord_count) {
            throw InputError(obj_name_, face_name(f, shape),
                             "texture coordinate index " + std::to_string(i.texcoord_index + 1) +
                                 " out of range (" + std::to_string(texcoord_count) + " vt)");
        }
    }

    // The corners' texture coordinates, v turned to grow downwards (OBJ's
    // v grows upwards, the renderer's as in glTF); zeros where a corner has
    // none.
    gpu::TriangleUvs texcoords(const Corners& idx, std::size_t f, const tinyobj::shape_t& shape) const {
        float uv[6] = {};
        for (std::size_t c = 0; c < 3; ++c) {
            if (idx[c].texcoord_index < 0) continue;
            const auto k = static_cast<std::size_t>(idx[c].texcoord_index) * 2;
            const float u = static_cast<float>(attrib_.texcoords[k]);
            const float v = static_cast<float>(attrib_.texcoords[k + 1]);
            if (!std::isfinite(u) || !std::isfinite(v))
                throw InputError(obj_name_, face_name(f, shape),
                                 "texture coordinate " + std::to_string(idx[c].texcoord_index + 1) +
                                     " must be finite");
            uv[2 * c] = u;
            uv[2 * c + 1] = 1.0f - v;
        }
        return gpu::TriangleUvs{uv[0], uv[1], uv[2], uv[3], uv[4], uv[5]};
    }

    // The vertex as the OBJ gives it, and placed by the transform.
    glm::vec3 raw_position(int index) const {
        const auto k = static_cast<std::size_t>(index) * 3;
        return glm::vec3(static_cast<float>(attrib_.vertices[k]), static_cast<float>(attrib_.vertices[k + 1]),
                         static_cast<float>(attrib_.vertices[k + 2]));
    }
    glm::vec3 position(int index) const {
        return glm::vec3(transform_.position * glm::vec4(raw_position(index), 1.0f));
    }

    glm::vec3 normal(int index) const {
        const auto k = static_cast<std::size_t>(index) * 3;
        return transform_.normal * glm::vec3(static_cast<float>(attrib_.normals[k]),
                                             static_cast<float>(attrib_.normals[k + 1]),
                                             static_cast<float>(attrib_.normals[k + 2]));
    }

    // The OBJ's vertex normals when all three corners have a usable one; a
    // zero or broken vertex normal would poison shading, so the face normal
    // is the honest fallback.
    std::array<glm::vec3, 3> shading_normals(const Corners& idx, glm::vec3 face_normal) const {
        const std::array<glm::vec3, 3> flat{face_normal, face_normal, face_normal};
        std::array<glm::vec3, 3> vn{};
        for (std::size_t c = 0; c < 3; ++c) {
            if (idx[c].normal_index < 0) return flat;
            if (!unit_vector(glm::dvec3(normal(idx[c].normal_index)), vn[c])) return flat;
        }
        return vn;
    }

    std::uint32_t material_of(int mtl_id) {
        if (override_) return material_base_;
        if (mtl_id >= 0 && static_cast<std::size_t>(mtl_id) < mtl_count_) {
            return material_base_ + static_cast<std::uint32_t>(mtl_id);
        }
        if (!target_.default_material) {
            target_.default_material = static_cast<std::uint32_t>(target_.scene.materials.size());
            target_.scene.materials.push_back(default_material());
        }
        return *target_.default_material;
    }

    // False when the triangle is degenerate and dropped.
    bool add_triangle(const Corners& face_corners, int mtl_id, std::size_t f, const tinyobj::shape_t& shape) {
        const Corners idx = transform_.file_winding(face_corners);
        const std::array<glm::vec3, 3> v{position(idx[0].vertex_index), position(idx[1].vertex_index),
                                         position(idx[2].vertex_index)};
        // A transform that takes a corner past float's range makes it
        // infinite (or NaN); the triangle would read as degenerate.
        for (int c = 0; c < 3; ++c)
            if (!fits_float(glm::dvec3(v[std::size_t(c)])) && !transform_.field.empty() &&
                fits_float(glm::dvec3(raw_position(idx[std::size_t(c)].vertex_index))))
                throw InputError(transform_.scene_file, transform_.field,
                                 "takes " + face_name(f, shape) + " of " + obj_name_ + " past float's range");
        glm::vec3 face;
        const TriangleShape shape_of = triangle_shape(v, face);
        if (shape_of == TriangleShape::too_large) throw InputError(obj_name_, face_name(f, shape), kTriangleTooLarge);
        if (shape_of == TriangleShape::degenerate) {
            ++target_.scene.degenerate_triangles_dropped;
            const std::array<glm::vec3, 3> raw{raw_position(idx[0].vertex_index), raw_position(idx[1].vertex_index),
                                               raw_position(idx[2].vertex_index)};
            glm::vec3 raw_face;
            if (triangle_shape(raw, raw_face) != TriangleShape::degenerate) ++degenerate_by_transform_;
            return false;
        }
        for (const glm::vec3& p : v) target_.geometry.grow(glm::dvec3(p));
        if (const std::string problem = extent_problem(target_.geometry); !problem.empty()) {
            throw InputError(obj_name_, face_name(f, shape), "too far from the rest of the geometry: " + problem);
        }
        const std::array<glm::vec3, 3> n = shading_normals(idx, face);
        // After the degenerate check: a dropped face must not add the default material.
        const std::uint32_t material = material_of(mtl_id);
        target_.scene.triangles.push_back(gpu::Triangle{v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z,
                                                        v[2].x, v[2].y, v[2].z, material, 0u, 0u});
        target_.scene.normals.push_back(gpu::TriangleNormals{n[0].x, n[0].y, n[0].z, n[1].x, n[1].y, n[1].z,
                                                             n[2].x, n[2].y, n[2].z, 0u, 0u, 0u});
        target_.scene.uvs.push_back(texcoords(idx, f, shape));
        const bool textured = (target_.scene.materials[material].flags & gpu::kMaterialTextured) != 0u;
        const bool uv_everywhere = std::all_of(idx.begin(), idx.end(), [](const tinyobj::index_t& i) {
            return i.texcoord_index >= 0;
        });
        if (textured && !uv_everywhere && untextured_noted_.insert(material).second)
            target_.scene.load_notes.push_back(
                obj_name_ + ": " + face_name(f, shape) +
                ": has no texture coordinates (vt) at some corner, but its material has textures: they are read "
                "at (0, 0) there (noted for the first such face of each material)");
        return true;
    }

    std::set<std::uint32_t> untextured_noted_;  // materials whose faces without vt were noted
    // The texture notes made, so each is made once (a search of the notes
    // took 20 s for 160,000 materials with a map_Bump each).
    std::set<std::string> noted_;
};

}  // namespace

void load_obj(const std::filesystem::path& file, const MeshTransform& transform,
              const std::optional<gpu::Material>& override_material, MeshTarget& target) {
    const std::string obj_name = display(file);
    ObjData obj;
    read_obj(file, obj_name, !override_material, obj);

    FaceConverter faces(obj, transform, override_material, target, file, obj_name);
    std::size_t kept = 0;
    for (const tinyobj::shape_t& shape : obj.shapes) kept += faces.add_shape(shape);
    if (const std::size_t n = obj.short_faces; n > 0)
        target.scene.load_notes.push_back(obj_name + ": " + std::to_string(n) + (n == 1 ? " face has" : " faces have") +
                                          " fewer than 3 corners (a point or a line, no surface): skipped");
    if (kept == 0 && faces.degenerate_by_transform() > 0 && !transform.field.empty())
        throw InputError(transform.scene_file, transform.field,
                         "makes every triangle of " + obj_name + " degenerate (a scale too small for floats?)");
    if (kept == 0) throw InputError(obj_name, "", "no usable triangles (after dropping degenerate ones)");
}

}  // namespace lc::loader
