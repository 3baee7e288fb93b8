// Emissive triangles as oriented point lights (Walter et al. 2005, §5: an
// area light becomes many point samples, each a cosine emitter, that go into
// the light tree with every other light).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "shared/types.h"

namespace lc {

// `count` samples over every triangle whose material emits, distributed in
// proportion to power (emitted luminance x area, twice for two-sided
// emitters) by systematic sampling along the triangles, and stratified over
// each triangle. A sample carries I = Le * A / m along its triangle's
// geometric normal (counter-clockwise winding, right-handed), m being the
// samples its triangle got, so the samples' total power is the emitters'.
// Deterministic for a seed; as count grows the lighting converges to the
// exact area-light integral. Empty when nothing emits or count is 0.
std::vector<gpu::Light> sample_area_lights(std::span<const gpu::Triangle> triangles,
                                           std::span<const gpu::Material> materials, std::uint32_t count,
                                           std::uint32_t seed);

}  // namespace lc
