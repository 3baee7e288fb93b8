// MTL entries and JSON overrides to gpu::Material (docs/scene-format.md, "Materials from MTL").
#include "materials.h"

#include <algorithm>
#include <cmath>
#include <charconv>
#include <string>

#include <tiny_obj_loader.h>

#include "lightcuts/error.h"

namespace lc::loader {

gpu::Material make_material(glm::vec3 kd, glm::vec3 ks, float alpha) {
    gpu::Material m{};
    m.kd_r = kd.r;
    m.kd_g = kd.g;
    m.kd_b = kd.b;
    m.ks_r = ks.r;
    m.ks_g = ks.g;
    m.ks_b = ks.b;
    m.alpha = std::clamp(alpha, gpu::kMinGgxAlpha, 1.0f);
    m.roughness = std::sqrt(m.alpha);
    m.flags = (ks.r > 0.0f || ks.g > 0.0f || ks.b > 0.0f) ? gpu::kMaterialHasSpecular : 0u;
    m.specular = 0.5f;
    m.normal_scale = 1.0f;
    m.base_color_texture = m.metallic_roughness_texture = m.emissive_texture = m.normal_texture = gpu::kInvalidIndex;
    return m;
}

gpu::Material make_disney_material(const DisneyParams& p) {
    gpu::Material m = make_material(p.base_color, glm::vec3(0.0f), p.roughness * p.roughness);
    m.flags = gpu::kMaterialDisney | (p.sheen > 0.0f ? gpu::kMaterialHasSheen : 0u) |
              (p.clearcoat > 0.0f ? gpu::kMaterialHasClearcoat : 0u);
    m.roughness = p.roughness;
    m.metallic = p.metallic;
    m.specular = p.specular;
    m.specular_tint = p.specular_tint;
    m.sheen = p.sheen;
    m.sheen_tint = p.sheen_tint;
    m.clearcoat = p.clearcoat;
    m.clearcoat_gloss = p.clearcoat_gloss;
    return m;
}

void set_texture(gpu::Material& m, std::uint32_t gpu::Material::*slot, std::uint32_t index) {
    m.*slot = index;
    m.flags |= gpu::kMaterialTextured;
}

void set_emission(gpu::Material& m, glm::vec3 radiance, bool both_sides) {
    m.emission_r = radiance.r;
    m.emission_g = radiance.g;
    m.emission_b = radiance.b;
    m.flags &= ~(gpu::kMaterialEmissive | gpu::kMaterialEmitsBothSides);
    if (radiance.r > 0.0f || radiance.g > 0.0f || radiance.b > 0.0f)
        m.flags |= gpu::kMaterialEmissive | (both_sides ? gpu::kMaterialEmitsBothSides : 0u);
}

gpu::Material default_material() { return make_material(glm::vec3(kDefaultAlbedo), glm::vec3(0.0f), 1.0f); }

namespace {

// An MTL value as a message shows it: tinyobjloader has read it into a
// float, so a number past float's range (1e39) arrives as infinity.
std::string shown(tinyobj::real_t v) {
    if (std::isinf(v)) return v > 0 ? "a number beyond float's range" : "a negative number beyond float's range";
    char text[32];
    // The shortest text that reads back as the same float: 1.0000001, not
    // %g's 1; 1e-07, not 9.99999997e-08.
    const auto end = std::to_chars(text, text + sizeof text, static_cast<float>(v)).ptr;
    return std::string(text, end);
}

}  // namespace

gpu::Material convert_mtl(const tinyobj::material_t& mtl, const std::string& obj_name) {
    const std::string field = "material '" + mtl.name + "'";
    const auto rgb = [&](const tinyobj::real_t* v, const char* key) {
        glm::vec3 c;
        for (int i = 0; i < 3; ++i) {
            if (!std::isfinite(v[i]) || v[i] < 0.0 || v[i] > 1.0) {
                throw InputError(obj_name, field + "." + key,
                                 "components must be in [0, 1], got " + shown(v[i]));
            }
            c[i] = static_cast<float>(v[i]);
        }
        return c;
    };
    const glm::vec3 kd = rgb(mtl.diffuse, "Kd");
    glm::vec3 ke;
    for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(mtl.emission[i]) || mtl.emission[i] < 0.0 || mtl.emission[i] > 3.4e38) {
            throw InputError(obj_name, field + ".Ke",
                             "components must be from 0 to 3.4e38, got " + shown(mtl.emission[i]));
        }
        ke[i] = static_cast<float>(mtl.emission[i]);
    }
    const auto unit = [&](tinyobj::real_t v, const char* key) {
        if (!std::isfinite(v) || v < 0.0 || v > 1.0) {
            throw InputError(obj_name, field + "." + key, "must be in [0, 1], got " + shown(v));
        }
        return static_cast<float>(v);
    };
    // The PBR extension (Pm, Ps, Pc, Pcr) makes a Disney material. tinyobj
    // reports an absent key as 0, so only a non-zero value counts as given.
    const float metallic = unit(mtl.metallic, "Pm");
    const float sheen = unit(mtl.sheen, "Ps");
    const float clearcoat = unit(mtl.clearcoat_thickness, "Pc");
    const float clearcoat_roughness = unit(mtl.clearcoat_roughness, "Pcr");
    if (metallic > 0.0f || sheen > 0.0f || clearcoat > 0.0f || clearcoat_roughness > 0.0f) {
        DisneyParams p;
        p.base_color = kd;
        p.roughness = mtl.roughness != 0.0 ? unit(mtl.roughness, "Pr") : kDefaultRoughness;
        p.metallic = metallic;
        p.sheen = sheen;
        p.clearcoat = clearcoat;
        p.clearcoat_gloss = 1.0f - clearcoat_roughness;
        gpu::Material m = make_disney_material(p);
        set_emission(m, ke, false);
        return m;
    }
    const glm::vec3 ks = rgb(mtl.specular, "Ks");
    // tinyobj leaves roughness at 0 when the MTL has no "Pr", so Pr = 0 means
    // "not given" and the Blinn-Phong exponent decides (Walter et al. 2007);
    // any other value was given, and must be in range.
    float alpha = 1.0f;
    if (mtl.roughness != 0.0) {
        if (!std::isfinite(mtl.roughness) || mtl.roughness < 0.0 || mtl.roughness > 1.0) {
            throw InputError(obj_name, field + ".Pr", "must be in [0, 1]");
        }
        alpha = static_cast<float>(mtl.roughness * mtl.roughness);
    } else {
        if (!std::isfinite(mtl.shininess) || mtl.shininess < 0.0) {
            throw InputError(obj_name, field + ".Ns", "must be a finite number >= 0");
        }
        alpha = static_cast<float>(std::sqrt(2.0 / (mtl.shininess + 2.0)));
    }
    gpu::Material m = make_material(kd, ks, alpha);
    set_emission(m, ke, false);
    return m;
}

}  // namespace lc::loader
