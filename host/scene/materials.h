// Materials as the GPU reads them, from an MTL entry or a JSON override.
#pragma once

#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "lc_shared/types.h"

namespace tinyobj {
struct material_t;
}

namespace lc::loader {

// Lambert grey for faces that name no material.
inline constexpr float kDefaultAlbedo = 0.8f;
// Roughness used by a JSON material override that gives ks but no roughness.
inline constexpr float kDefaultRoughness = 0.5f;

// kd: Lambert albedo; ks: GGX lobe reflectance (any component > 0 turns the
// lobe on); alpha: GGX roughness, clamped to [gpu::kMinGgxAlpha, 1].
gpu::Material make_material(glm::vec3 kd, glm::vec3 ks, float alpha);

// Adds emitted radiance (W/(sr m^2)), one-sided along the geometric normal
// unless both_sides; black emission leaves the material as it is.
void set_emission(gpu::Material& m, glm::vec3 radiance, bool both_sides);

// The Disney BRDF's parameters (lc_shared/types.h, Material), with Burley's
// defaults; each in [0, 1].
struct DisneyParams {
    glm::vec3 base_color{kDefaultAlbedo};
    float metallic = 0.0f;
    float roughness = 0.5f;
    float specular = 0.5f;
    float specular_tint = 0.0f;
    float sheen = 0.0f;
    float sheen_tint = 0.5f;
    float clearcoat = 0.0f;
    float clearcoat_gloss = 1.0f;
};

// A Disney material (kMaterialDisney): alpha = max(roughness^2, gpu::kMinGgxAlpha);
// sets kMaterialHasSheen and kMaterialHasClearcoat where those are > 0.
gpu::Material make_disney_material(const DisneyParams& p);

// Sets one of m's texture slots (&m.base_color_texture, ...) to texture
// `index` and marks m as textured.
void set_texture(gpu::Material& m, std::uint32_t gpu::Material::*slot, std::uint32_t index);

// The material faces get when they name none.
gpu::Material default_material();

// One MTL entry (Ke is its emission, one-sided): Lambert + GGX from Kd, Ks,
// Pr or Ns; a Disney material where any of Pm, Ps, Pc, Pcr is non-zero
// (docs/scene-format.md). Throws InputError naming obj_name and
// "material 'NAME'.KEY".
gpu::Material convert_mtl(const tinyobj::material_t& mtl, const std::string& obj_name);

}  // namespace lc::loader
