// The true emitters of a scene, as the path tracer samples them: the scene
// file's own point, spot and directional lights, every emissive triangle and
// the environment map. Not the light tree: its area-light samples and
// environment directions are lightcuts' discretisation, and a path tracer
// that used them would converge to that approximation, not to the scene.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "lightcuts/scene.h"
#include "scene/float_limits.h"
#include "lc_shared/types.h"

namespace lc::path {

// A discrete distribution over entries in proportion to non-negative
// weights (pbrt-v4's PiecewiseConstant1D without the continuous part).
class Distribution1D {
public:
    Distribution1D() = default;
    explicit Distribution1D(const std::vector<double>& weights);

    double total() const { return total_; }  // sum of the weights; 0: nothing to sample
    std::size_t size() const { return pmf_.size(); }

    // The entry whose cumulative interval holds u in [0, 1). Only entries of
    // positive weight are ever returned. Requires total() > 0.
    std::uint32_t sample(double u) const;
    double pmf(std::uint32_t i) const { return pmf_[i]; }

private:
    std::vector<double> cdf_;  // size() + 1 values from 0 to 1
    std::vector<double> pmf_;  // weight / total
    double total_ = 0.0;
};

// Importance sampling of a lat-long environment map: a texel in proportion
// to luminance x solid angle (rows by their marginal, then a column of the
// row), then a direction uniform in solid angle within it. Every texel of
// positive luminance has positive probability (short of a share of the map
// below double precision, which MIS leaves to BRDF sampling). Directions
// map to texels as lc_environment_radiance maps them (shading.h).
class EnvironmentSampler {
public:
    EnvironmentSampler() = default;
    explicit EnvironmentSampler(const Environment& map);

    bool empty() const { return !(rows_.total() > 0.0); }
    // The integral of the luminance over the sphere, sum of lum(L) dw.
    double luminance_integral() const { return rows_.total(); }

    // A direction for the random numbers (u_row, u_column pick the texel,
    // u_theta, u_phi the point in it) and its probability density per unit
    // solid angle. Requires !empty().
    glm::vec3 sample(double u_row, double u_column, float u_theta, float u_phi, float& pdf) const;
    // The density sample() draws `dir` with (0 where the texel is black).
    float pdf(glm::vec3 dir) const;

private:
    float texel_pdf(std::uint32_t row, std::uint32_t column) const;

    std::uint32_t width_ = 0, height_ = 0;
    Distribution1D rows_;
    std::vector<Distribution1D> columns_;  // per row
    std::vector<double> cos_edge_;         // cos(theta) at the top of row r, r = 0 .. height
};

// What NEE can pick: one of the scene's lights (index into Scene::lights),
// one triangle (index in BVH order), or the environment.
enum class EmitterKind : std::uint32_t { kLight, kTriangle, kEnvironment };

struct Emitter {
    EmitterKind kind;
    std::uint32_t index;  // unused for the environment
};

// Every emitter of a scene with a probability in proportion to its power:
//   point        4 pi lum(I)
//   spot         2 pi (1 - (cos_inner + cos_outer) / 2) lum(I), the solid
//                angle of the cone halfway through its falloff
//   oriented     pi lum(I), twice if two-sided
//   directional  pi R^2 lum(E), R the radius of the sphere around the
//                scene's bounds: what falls on the scene
//   triangle     pi A lum(Le), twice if two-sided
//   environment  pi R^2 (integral of lum(L) dw)
// Only a heuristic for where to send shadow rays: any positive weight for
// every emitter that can contribute keeps NEE unbiased.
class EmitterTable {
public:
    explicit EmitterTable(const Scene& scene);

    bool empty() const { return emitters_.empty(); }
    // One emitter for u in [0, 1), and the probability it had. Requires !empty().
    Emitter pick(double u, float& pmf) const;
    // Probability that pick() returns triangle `tri` (0 if it does not emit)
    // or the environment: what MIS needs for a BSDF ray that finds them.
    float triangle_pmf(std::uint32_t tri) const { return triangle_pmf_.empty() ? 0.0f : triangle_pmf_[tri]; }
    float environment_pmf() const { return environment_pmf_; }
    const EnvironmentSampler& environment() const { return environment_; }

private:
    std::vector<Emitter> emitters_;
    Distribution1D power_;
    std::vector<float> triangle_pmf_;  // per triangle; empty when none emits
    float environment_pmf_ = 0.0f;
    EnvironmentSampler environment_;
};

// The weight EmitterTable gives one of the scene's lights; `radius` is that
// of the sphere around the scene, for directional lights. The light paths
// that leave VPLs (host/vpls.cpp) choose their lights by it too, from all
// the tree's lights (oriented area-light samples included).
double light_power(const gpu::Light& light, double radius);

// The unit geometric normal of `tri` (its winding's) turned to the side a
// ray along `ray_dir` arrives from, as lc_surface_point turns it; `fallback`
// for a triangle of no area. Light paths and the path tracer's bounces
// reflect only into this side: a shading normal (vertex normals, a normal
// map) may lean past it, but an opaque surface reflects nothing through
// itself (Veach 1997, section 5.3; pbrt's BSDF::f tests the same side).
inline glm::vec3 facing_normal(const gpu::Triangle& tri, glm::vec3 ray_dir, glm::vec3 fallback) {
    // In double: a tiny triangle's float cross product has a squared length
    // that underflows, and divided by it a normal (a VPL's axis) came out
    // up to 1.5 long.
    glm::vec3 n = fallback;
    loader::face_normal({glm::vec3(tri.v0_x, tri.v0_y, tri.v0_z), glm::vec3(tri.v1_x, tri.v1_y, tri.v1_z),
                         glm::vec3(tri.v2_x, tri.v2_y, tri.v2_z)},
                        n);
    return glm::dot(n, ray_dir) > 0.0f ? -n : n;
}

}  // namespace lc::path
