// glTF materials and images (gltf_materials.h).
#include "gltf_materials.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <vector>

#include <tiny_gltf.h>

#include "lightcuts/error.h"
#include "materials.h"
#include "lc_shared/color.h"
#include "textures.h"

namespace lc::loader {
namespace {

// Material extensions this loader reads; any other is noted and ignored.
bool read_extension(const std::string& name) {
    return name == "KHR_materials_emissive_strength" || name == "KHR_materials_clearcoat" ||
           name == "KHR_materials_sheen";
}

}  // namespace

void GltfNotes::add(const std::string& field, const std::string& text) {
    const std::string line = field.empty() ? file_ + ": " + text : file_ + ": " + field + ": " + text;
    if (seen_.insert(line).second) scene_.load_notes.push_back(line);
}

std::uint32_t GltfMaterials::material(int index, const std::string& field) {
    if (index < -1 || (index >= 0 && std::size_t(index) >= model_.materials.size()))
        throw InputError(notes_.file(), field, "material " + std::to_string(index) + " out of range (" +
                                                   std::to_string(model_.materials.size()) + " materials)");
    if (const auto found = materials_.find(index); found != materials_.end()) return found->second;
    gpu::Material m;
    if (index < 0) {
        // glTF 2.0, 3.9.6: a primitive without a material gets the default
        // pbrMetallicRoughness values: base colour 1, metallic 1, roughness 1.
        DisneyParams p;
        p.base_color = glm::vec3(1.0f);
        p.metallic = 1.0f;
        p.roughness = 1.0f;
        p.sheen_tint = 0.0f;
        m = make_disney_material(p);
    } else {
        m = convert(index);
    }
    scene_.materials.push_back(m);
    const auto scene_index = std::uint32_t(scene_.materials.size() - 1);
    materials_.emplace(index, scene_index);
    return scene_index;
}

namespace {

// Checks of a material's numbers against their glTF ranges, with errors
// naming the file and the glTF path.
class FactorReader {
public:
    explicit FactorReader(const std::string& file) : file_(file) {}

    float in_range(double v, double hi, const std::string& field) const {
        if (!(v >= 0.0 && v <= hi)) {
            // The shortest text that reads back as v (std::to_string's %f
            // wrote 1e39 in 40 digits and 1e-9 as 0.000000).
            char text[32];
            const auto end = std::to_chars(text, text + sizeof text, v).ptr;
            throw InputError(file_, field, "must be from 0 to " + std::string(hi == 1.0 ? "1" : "FLT_MAX") +
                                               ", got " + std::string(text, end));
        }
        return float(v);
    }

    // The first three of `size` numbers, each of them in [0, 1] (an alpha
    // too, though the renderer does not use it).
    glm::vec3 colour(const std::vector<double>& v, std::size_t size, const std::string& field) const {
        if (v.size() != size) throw InputError(file_, field, "must have " + std::to_string(size) + " components");
        glm::vec3 c;
        for (std::size_t i = 0; i < size; ++i) {
            const float x = in_range(v[i], 1.0, field + "[" + std::to_string(i) + "]");
            if (i < 3) c[int(i)] = x;
        }
        return c;
    }

    // A number of an extension object in [0, hi]; `fallback` when absent.
    float number(const tinygltf::Value& ext, const char* key, double fallback, double hi,
                 const std::string& field) const {
        if (!ext.IsObject() || !ext.Has(key)) return float(fallback);
        const tinygltf::Value& v = ext.Get(key);
        if (!v.IsNumber()) throw InputError(file_, field + "." + key, "must be a number");
        return in_range(v.GetNumberAsDouble(), hi, field + "." + key);
    }

    // A colour of an extension object; black when absent.
    glm::vec3 colour(const tinygltf::Value& ext, const char* key, const std::string& field) const {
        if (!ext.IsObject() || !ext.Has(key)) return glm::vec3(0.0f);
        const tinygltf::Value& v = ext.Get(key);
        if (!v.IsArray() || v.ArrayLen() != 3) throw InputError(file_, field + "." + key, "must have 3 components");
        std::vector<double> values;
        for (int i = 0; i < 3; ++i) {
            if (!v.Get(i).IsNumber()) throw InputError(file_, field + "." + key, "must hold numbers");
            values.push_back(v.Get(i).GetNumberAsDouble());
        }
        return colour(values, 3, field + "." + key);
    }

private:
    const std::string& file_;
};

const tinygltf::Value& extension(const tinygltf::Material& g, const char* key) {
    static const tinygltf::Value none;
    const auto it = g.extensions.find(key);
    return it == g.extensions.end() ? none : it->second;
}

bool has_any(const tinygltf::Value& ext, std::initializer_list<const char*> keys) {
    for (const char* key : keys)
        if (ext.IsObject() && ext.Has(key)) return true;
    return false;
}

// Disney's sheen colour is sheen * mix(white, tint, sheen_tint), the tint
// being the base colour over its luminance (lc_disney_tint), so a tinted
// sheen is brighter than `sheen` in the base's strongest channel. The fit
// matches the glTF sheen colour s in hue by least squares (both scaled to
// a largest component of 1, where the tinted family is mix(white, c, u)
// with c = base / max(base)), turns u into the kernel's sheen_tint t, and
// sets sheen so that the colour's largest component is max(s): a sheen of
// the base colour's hue, or a grey one, comes out as s exactly.
struct SheenFit {
    float sheen = 0.0f;
    float tint = 0.0f;
};

SheenFit fit_sheen(glm::vec3 s, glm::vec3 base) {
    const float s_max = std::max({s.r, s.g, s.b});
    if (!(s_max > 0.0f)) return {};
    const float base_max = std::max({base.r, base.g, base.b});
    const float luminance = gpu::lc_luminance(base);
    if (!(base_max > 0.0f && luminance > 0.0f)) return {s_max, 0.0f};  // the tint is white
    const glm::vec3 towards = base / base_max - 1.0f;
    const float length2 = glm::dot(towards, towards);
    if (!(length2 > 1e-12f)) return {s_max, 0.0f};  // a grey base: tinting changes nothing
    const float u = std::clamp(glm::dot(s / s_max - 1.0f, towards) / length2, 0.0f, 1.0f);
    // mix(white, base / luminance, t) scaled to a largest component of 1 is
    // mix(white, c, u) for u = t M / (1 + t (M - 1)), M = max(base) / luminance.
    const float big = base_max / luminance;
    const float t = u / (u + big * (1.0f - u));
    return {s_max / (1.0f + t * (big - 1.0f)), t};
}

}  // namespace

DisneyParams GltfMaterials::params(const tinygltf::Material& g, const std::string& name) {
    const FactorReader read(notes_.file());
    const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
    const std::string pbr_name = name + ".pbrMetallicRoughness";
    DisneyParams p;
    p.base_color = read.colour(pbr.baseColorFactor, 4, pbr_name + ".baseColorFactor");
    p.metallic = read.in_range(pbr.metallicFactor, 1.0, pbr_name + ".metallicFactor");
    p.roughness = read.in_range(pbr.roughnessFactor, 1.0, pbr_name + ".roughnessFactor");
    p.specular = 0.5f;  // glTF's dielectric F0 of 0.04 is Disney's specular 0.5
    p.sheen_tint = 0.0f;

    const std::string clearcoat_name = name + ".extensions.KHR_materials_clearcoat";
    const tinygltf::Value& clearcoat = extension(g, "KHR_materials_clearcoat");
    p.clearcoat = read.number(clearcoat, "clearcoatFactor", 0.0, 1.0, clearcoat_name);
    p.clearcoat_gloss = 1.0f - read.number(clearcoat, "clearcoatRoughnessFactor", 0.0, 1.0, clearcoat_name);
    if (has_any(clearcoat, {"clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture"}))
        notes_.add(clearcoat_name, "clearcoat textures are not read; the factors apply everywhere");

    const std::string sheen_name = name + ".extensions.KHR_materials_sheen";
    const tinygltf::Value& sheen = extension(g, "KHR_materials_sheen");
    const glm::vec3 sheen_colour = read.colour(sheen, "sheenColorFactor", sheen_name);
    const SheenFit fit = fit_sheen(sheen_colour, p.base_color);
    p.sheen = fit.sheen;
    p.sheen_tint = fit.tint;
    if (read.number(sheen, "sheenRoughnessFactor", 0.0, 1.0, sheen_name) > 0.0f)
        notes_.add(sheen_name + ".sheenRoughnessFactor", "not used (Disney's sheen has no roughness)");
    if (has_any(sheen, {"sheenColorTexture", "sheenRoughnessTexture"}))
        notes_.add(sheen_name, "sheen textures are not read; the factors apply everywhere");
    return p;
}

void GltfMaterials::add_textures(gpu::Material& m, const tinygltf::Material& g, const std::string& name) {
    const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
    const std::string pbr_name = name + ".pbrMetallicRoughness";
    const auto slot = [&](std::uint32_t gpu::Material::*field, const auto& info, const std::string& path) {
        if (info.index < 0) return;
        const std::uint32_t t = texture(info.index, info.texCoord, info.extensions, path);
        if (t != gpu::kInvalidIndex) set_texture(m, field, t);
    };
    slot(&gpu::Material::base_color_texture, pbr.baseColorTexture, pbr_name + ".baseColorTexture");
    slot(&gpu::Material::metallic_roughness_texture, pbr.metallicRoughnessTexture,
         pbr_name + ".metallicRoughnessTexture");
    slot(&gpu::Material::normal_texture, g.normalTexture, name + ".normalTexture");
    if (g.normalTexture.index >= 0) {
        if (!(std::abs(g.normalTexture.scale) <= 1e6))  // also NaN
            throw InputError(notes_.file(), name + ".normalTexture.scale", "must be a number from -1e6 to 1e6");
        m.normal_scale = float(g.normalTexture.scale);
    }
    // A texture only scales the factor: with black emission it cannot emit.
    if ((m.flags & gpu::kMaterialEmissive) != 0u)
        slot(&gpu::Material::emissive_texture, g.emissiveTexture, name + ".emissiveTexture");
}

gpu::Material GltfMaterials::convert(int index) {
    const tinygltf::Material& g = model_.materials[std::size_t(index)];
    const std::string name = "materials[" + std::to_string(index) + "]";
    gpu::Material m = make_disney_material(params(g, name));

    // Emission: emissiveFactor x KHR_materials_emissive_strength (W/(sr m^2)).
    const FactorReader read(notes_.file());
    const glm::vec3 emissive = read.colour(g.emissiveFactor.empty() ? std::vector<double>{0, 0, 0} : g.emissiveFactor,
                                           3, name + ".emissiveFactor");
    const std::string strength_name = name + ".extensions.KHR_materials_emissive_strength";
    const float strength = read.number(extension(g, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0,
                                       double(std::numeric_limits<float>::max()), strength_name);
    const glm::dvec3 radiance = glm::dvec3(emissive) * double(strength);
    for (int i = 0; i < 3; ++i)
        if (radiance[i] > double(std::numeric_limits<float>::max()))
            throw InputError(notes_.file(), strength_name, "emissiveFactor x emissiveStrength overflows a float");
    set_emission(m, glm::vec3(radiance), g.doubleSided);
    add_textures(m, g, name);

    if (g.alphaMode != "OPAQUE") notes_.add(name + ".alphaMode", g.alphaMode + " is drawn as OPAQUE");
    if (g.occlusionTexture.index >= 0)
        notes_.add(name + ".occlusionTexture", "not read (the renderer computes its own shadowing)");
    for (const auto& [key, value] : g.extensions)
        if (!read_extension(key)) notes_.add(name + ".extensions." + key, "not supported; ignored");
    return m;
}

namespace {

// A number of KHR_texture_transform, finite and within a float's range.
double transform_number(const tinygltf::Value& v, const std::string& file, const std::string& field) {
    if (!v.IsNumber()) throw InputError(file, field, "must be a number");
    const double x = v.GetNumberAsDouble();
    if (!(std::abs(x) <= double(std::numeric_limits<float>::max())))
        throw InputError(file, field, "must be a finite number, got " + std::to_string(x));
    return x;
}

// Two numbers of KHR_texture_transform (offset, scale); `fallback` when absent.
glm::dvec2 transform_pair(const tinygltf::Value& ext, const char* key, glm::dvec2 fallback, const std::string& file,
                          const std::string& field) {
    if (!ext.Has(key)) return fallback;
    const tinygltf::Value& v = ext.Get(key);
    const std::string at = field + "." + key;
    if (!v.IsArray() || v.ArrayLen() != 2) throw InputError(file, at, "must be an array of 2 numbers");
    return {transform_number(v.Get(0), file, at + "[0]"), transform_number(v.Get(1), file, at + "[1]")};
}

// A glTF sampler's wrapping (wrapS, wrapT) as a TextureInfo wrap mode.
std::uint32_t wrap_mode(int wrap, const std::string& file, const std::string& field) {
    switch (wrap) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT: return gpu::kTextureWrapRepeat;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return gpu::kTextureWrapClamp;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return gpu::kTextureWrapMirror;
    default:
        throw InputError(file, field, "must be 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) or 33648 (MIRRORED_REPEAT), not " +
                                          std::to_string(wrap));
    }
}

}  // namespace

// KHR_texture_transform: uv' = T R S uv, offset T, rotation R by `rotation`
// radians, scale S. R is the matrix of the extension's example (offset [0,
// 1], rotation pi/2, scale 0.5 takes the image's lower-left quarter) and of
// the sample model TextureTransformTest, [[cos, sin], [-sin, cos]]; the
// GLSL listing of the extension's README has it transposed (glTF issue
// 1563). Its texCoord replaces the texture reference's.
void GltfMaterials::read_transform(const tinygltf::Value& ext, const std::string& field, int& tex_coord,
                                   TextureSampling& sampling) const {
    const std::string& file = notes_.file();
    if (!ext.IsObject()) throw InputError(file, field, "must be an object");
    const glm::dvec2 offset = transform_pair(ext, "offset", glm::dvec2(0.0), file, field);
    const glm::dvec2 scale = transform_pair(ext, "scale", glm::dvec2(1.0), file, field);
    const double rotation = ext.Has("rotation") ? transform_number(ext.Get("rotation"), file, field + ".rotation") : 0.0;
    if (ext.Has("texCoord")) {
        const tinygltf::Value& v = ext.Get("texCoord");
        if (!v.IsInt() || v.GetNumberAsInt() < 0)
            throw InputError(file, field + ".texCoord", "must be a whole number >= 0");
        tex_coord = v.GetNumberAsInt();
    }
    const double c = std::cos(rotation), s = std::sin(rotation);
    sampling.uv_transform = {float(scale.x * c), float(scale.y * s), float(offset.x),
                             float(-scale.x * s), float(scale.y * c), float(offset.y)};
}

std::uint32_t GltfMaterials::texture(int index, int tex_coord, const tinygltf::ExtensionMap& extensions,
                                     const std::string& field) {
    const std::string& file = notes_.file();
    if (index < 0 || std::size_t(index) >= model_.textures.size())
        throw InputError(file, field + ".index", "texture " + std::to_string(index) + " out of range (" +
                                                     std::to_string(model_.textures.size()) + " textures)");
    TextureSampling sampling;
    const auto transform = extensions.find("KHR_texture_transform");
    if (transform != extensions.end())
        read_transform(transform->second, field + ".extensions.KHR_texture_transform", tex_coord, sampling);
    if (tex_coord != 0) {
        // The set the transform's texCoord chose, where it gives one.
        const bool overridden = transform != extensions.end() && transform->second.IsObject() &&
                                transform->second.Has("texCoord");
        notes_.add(field + (overridden ? ".extensions.KHR_texture_transform.texCoord" : ".texCoord"),
                   "uses TEXCOORD_" + std::to_string(tex_coord) +
                       "; only TEXCOORD_0 is read, so the texture is left out");
        return gpu::kInvalidIndex;
    }
    const std::string name = "textures[" + std::to_string(index) + "]";
    const tinygltf::Texture& t = model_.textures[std::size_t(index)];
    if (t.source < 0) {
        notes_.add(name, "has no source image this loader can read (PNG or JPEG); the texture is left out");
        return gpu::kInvalidIndex;
    }
    if (std::size_t(t.source) >= model_.images.size())
        throw InputError(file, name + ".source", "image " + std::to_string(t.source) + " out of range (" +
                                                     std::to_string(model_.images.size()) + " images)");
    if (t.sampler >= 0) {
        if (std::size_t(t.sampler) >= model_.samplers.size())
            throw InputError(file, name + ".sampler", "sampler " + std::to_string(t.sampler) + " out of range (" +
                                                          std::to_string(model_.samplers.size()) + " samplers)");
        const std::string sampler = "samplers[" + std::to_string(t.sampler) + "]";
        const tinygltf::Sampler& s = model_.samplers[std::size_t(t.sampler)];
        sampling.wrap_u = wrap_mode(s.wrapS, file, sampler + ".wrapS");
        sampling.wrap_v = wrap_mode(s.wrapT, file, sampler + ".wrapT");
        if (s.magFilter != -1 && s.magFilter != TINYGLTF_TEXTURE_FILTER_NEAREST &&
            s.magFilter != TINYGLTF_TEXTURE_FILTER_LINEAR)
            throw InputError(file, sampler + ".magFilter",
                             "must be 9728 (NEAREST) or 9729 (LINEAR), not " + std::to_string(s.magFilter));
        if (s.minFilter != -1 && s.minFilter != TINYGLTF_TEXTURE_FILTER_NEAREST &&
            s.minFilter != TINYGLTF_TEXTURE_FILTER_LINEAR &&
            !(s.minFilter >= TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST &&
              s.minFilter <= TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR))
            throw InputError(file, sampler + ".minFilter",
                             "must be 9728 (NEAREST), 9729 (LINEAR) or 9984 to 9987 (the mipmap kinds), not " +
                                 std::to_string(s.minFilter));
        // A lookup whose footprint is under a texel (magnification) filters
        // as magFilter says (minFilter's kind where it is the only one
        // given). minFilter NEAREST or LINEAR asks for no mipmaps: every
        // lookup then filters as magnification does, and a minFilter of the
        // other kind is noted. The mipmap kinds all read trilinearly,
        // noted where another was asked for.
        const int min_filter = s.minFilter;
        const bool min_nearest = min_filter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
                                 min_filter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
                                 min_filter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR;
        sampling.nearest = s.magFilter >= 0 ? s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST : min_nearest;
        sampling.mipmaps =
            min_filter != TINYGLTF_TEXTURE_FILTER_NEAREST && min_filter != TINYGLTF_TEXTURE_FILTER_LINEAR;
        if (!sampling.mipmaps && min_nearest != sampling.nearest)
            notes_.add(sampler + ".minFilter", std::string("is ") + (min_nearest ? "nearest" : "linear") +
                                                   " but magFilter " + (sampling.nearest ? "nearest" : "linear") +
                                                   ": without mipmaps, every lookup filters as magFilter says");
        if (sampling.mipmaps && min_filter >= 0 && min_filter != TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR)
            notes_.add(sampler + ".minFilter", "is " + std::to_string(min_filter) +
                                                   ": minified lookups are trilinear (9987, LINEAR_MIPMAP_LINEAR)");
    }
    return sampled_texture(scene_, image(t.source), sampling);
}

std::uint32_t GltfMaterials::image(int index) {
    if (const auto found = images_.find(index); found != images_.end()) return found->second;
    const std::string name = "images[" + std::to_string(index) + "]";
    const tinygltf::Image& im = model_.images[std::size_t(index)];
    // tinygltf decodes PNG and JPEG with stb_image, 8 or 16 bits a channel,
    // expanded to RGBA unless told otherwise; anything else is refused.
    const int bytes = im.bits == 16 ? 2 : 1;
    if ((im.bits != 8 && im.bits != 16) || im.component < 1 || im.component > 4 || im.width < 1 || im.height < 1 ||
        im.image.size() != std::size_t(im.width) * std::size_t(im.height) * std::size_t(im.component) *
                               std::size_t(bytes))
        throw InputError(notes_.file(), name,
                         "no decoded 8- or 16-bit pixels (the image" +
                             (im.uri.empty() || im.uri.rfind("data:", 0) == 0 ? std::string() : " " + im.uri) +
                             " could not be read)");
    const std::size_t texels = std::size_t(im.width) * std::size_t(im.height);
    std::vector<std::uint8_t> rgba(texels * 4);
    for (std::size_t i = 0; i < texels; ++i) {
        std::uint8_t c[4] = {0, 0, 0, 255};
        for (int k = 0; k < im.component; ++k) {
            // 16-bit channels keep their high byte (little-endian, as stb_image returns them).
            const std::size_t at = (i * std::size_t(im.component) + std::size_t(k)) * std::size_t(bytes);
            c[k] = im.image[at + std::size_t(bytes - 1)];
        }
        if (im.component <= 2) {  // grey (+ alpha)
            c[3] = im.component == 2 ? c[1] : 255;
            c[1] = c[2] = c[0];
        }
        std::copy(c, c + 4, rgba.begin() + std::ptrdiff_t(4 * i));
    }
    const std::uint32_t texture =
        add_texture(scene_, std::uint32_t(im.width), std::uint32_t(im.height), rgba.data(), notes_.file(), name);
    images_.emplace(index, texture);
    return texture;
}

}  // namespace lc::loader
