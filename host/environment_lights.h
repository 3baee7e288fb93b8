// An HDR environment map as directional lights (Walter et al. 2005, §5: the
// environment becomes many directional lights in the light tree).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lightcuts/scene.h"
#include "lc_shared/types.h"

namespace lc {

// The map is lat-long (docs/scene-format.md): for a unit world direction d
// (+Y up), u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi, column
// floor(u W), row floor(v H), row 0 at the top.
// The unit direction through map position (u, v) in [0, 1]^2.
void environment_direction(float u, float v, float out[3]);

// `count` directional lights chosen by stratified importance sampling of
// luminance x solid angle: the map is split recursively (along the side
// that is longer in angle, at its middle) and each part gets a share of the
// samples in proportion to its power, at least one if it has any, until a
// part holds one sample. Each light points at the power-weighted mean
// direction of its part and carries the part's irradiance (the integral of
// L over its solid angle), so the lights' total is the map's. A texel that
// gets several samples splits into a stratified grid of directions. Rows
// much taller in angle than a sample's share of the sphere (maps of a few
// rows, or a 2:1 map of H rows with more than about 1.3 H^2 samples) are
// first cut into bands of equal solid angle.
std::vector<gpu::Light> environment_lights(const Environment& map, std::uint32_t count);

}  // namespace lc
