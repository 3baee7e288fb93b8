// What the light tree needs to know of a light (pbrt-v4's LightBounds):
// where it sits in its tree's box, and the cone of directions it emits
// into. With the emission switch in shaders/shared/shading.h, the only
// place the tree looks at a light's type.
//
// The cone: every light's axis lies within theta_o of `axis`, and each
// light emits only within theta_e of its own axis. Built on the host for the
// light tree's nodes; read by the kernels' lc_emission_bound.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "shared/types.h"

namespace lc {

// A plain struct, left unwritten by default construction (the tree
// builder makes millions without zeroing them): start from everywhere() or
// of_light().
struct EmissionCone {
    glm::vec3 axis;        // as the kernels decode it (see quantized())
    float theta_o;         // spread of the axes; pi: they can point anywhere
    float theta_e;
    bool two_sided;
    // Spots: the smallest max(1e-3, cos inner - cos outer) of the lights
    // (their outer angles are in theta_e). Others: 1.
    float falloff_width;

    // A light that emits everywhere (point and directional lights): axis
    // +z, theta_o pi, theta_e pi/2, one-sided, falloff width 1.
    static EmissionCone everywhere();
    // The cone of one light (spot: its axis and outer angle; oriented: its
    // normal and pi/2).
    static EmissionCone of_light(const gpu::Light& light);

    bool emits_everywhere() const { return theta_o >= 3.14159265f; }
    // cos of Walter's cone half-angle beta, for the tree metric's term
    // c^2 (1 - cos beta)^2.
    float cos_beta() const;
};

// The point a light occupies in its tree's box: the position of a point,
// spot or oriented light, the unit direction of a directional light (Walter
// 2005 §4.1 clusters directional lights as points on the unit sphere).
// Throws std::invalid_argument for an unknown type.
glm::vec3 tree_point(const gpu::Light& light);

// The smallest cone (in pbrt-v4's sense) holding both (DirectionCone::Union).
EmissionCone cone_union(const EmissionCone& a, const EmissionCone& b);

// cone_union(a, b).cos_beta() without the union's axis, for the tree
// metric, which asks it of every candidate pair: the spread as cone_union
// finds it, short of the few-ulp widening that holds both cones once the
// axis is turned (the merged cluster's own cone is cone_union's).
// cos_beta_a and cos_beta_b are a.cos_beta() and b.cos_beta(), which the
// caller keeps for its clusters.
float union_cos_beta(const EmissionCone& a, float cos_beta_a, const EmissionCone& b, float cos_beta_b);

// The cone with its axis packed as the node stores it (octahedral, two
// snorm16) and theta_o widened by the angle the packing moved the axis, so
// it still holds every light. `packed` receives the stored bits.
EmissionCone quantized(const EmissionCone& cone, std::uint32_t& packed);

}  // namespace lc
