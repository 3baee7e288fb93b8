// Indirect light as virtual point lights (instant radiosity, Keller 1997;
// Walter et al. 2005, section 5): light paths traced from the lights leave
// a VPL at every diffuse bounce, and the VPLs go into the light tree as one
// more light type (kLightVpl), so lightcuts renders one-bounce-and-more
// indirect light with the same cuts that render direct light.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lightcuts/bvh.h"
#include "lightcuts/scene.h"
#include "lc_shared/types.h"

namespace lc {

struct VplSet {
    std::vector<gpu::Light> lights;  // kLightVpl records
    std::size_t paths = 0;           // light paths traced to leave them
};

// Traces light paths from `emitters` to leave about settings.vpls VPLs: the
// number of paths is fixed before they are traced, from pilot paths'
// count of VPLs a path (at most 64 paths a VPL, for scenes that paths
// mostly miss), so that dividing by it keeps the flux unbiased.
//
// `emitters` are the lights the tree holds: the scene's, the area-light
// samples and the environment's directions, so the VPLs carry exactly the
// light that lightcuts' direct lighting sees. A path starts at a light
// chosen in proportion to its power, in a direction drawn from its
// emission (uniform for a point light, within the cone for a spot,
// cosine-weighted for an oriented light, from a disk as wide as the scene
// for a directional light), carrying flux Phi = I(w) / (P(light) pdf(w)).
// Where it hits a surface with Lambert albedo kd it leaves a one-sided
// cosine emitter on the side it came from, of intensity Phi s kd / pi along
// the triangle's geometric normal, divided by the number of paths; then it
// continues in a direction cosine-weighted around that normal with flux
// Phi s kd / q, where q = min(0.95, max(kd)) is the chance it survives
// Russian roulette, until it has left settings.max_bounces VPLs (0: until
// roulette ends it). s = cos(shading) / cos(geometric) of the direction it
// arrived along corrects for shading normals (docs/lightcuts.md).
//
// Only the Lambert lobe reflects light along a path: light that a glossy
// lobe would reflect on to other surfaces is missing (docs/lightcuts.md);
// glossy receivers still shade the VPLs with their full BRDF.
//
// `scene` holds the triangles in `bvh`'s leaf order. Deterministic for a
// seed whatever the thread count (0 = all cores).
VplSet trace_vpls(const Scene& scene, const Bvh& bvh, std::span<const gpu::Light> emitters,
                  const IndirectSettings& settings, std::uint32_t seed, unsigned threads = 0);

}  // namespace lc
