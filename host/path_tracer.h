// The unbiased CPU path tracer (--method path): the reference for indirect
// light. render_path (include/lightcuts/render.h) runs it over the image;
// this header exposes the parts the tests check on their own.
//
// Per path vertex: next-event estimation towards one true emitter
// (host/path_emitters.h) and one direction drawn from the BRDF, the two
// combined by multiple importance sampling (Veach 1997, power heuristic)
// where both can find the light: emissive triangles and the environment.
// Point, spot and directional lights are deltas, found by NEE alone.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "cpu_kernel.h"
#include "lightcuts/render.h"
#include "path_emitters.h"

namespace lc::path {

using Kernel = cpu::ShadeKernel;
using SurfacePoint = Kernel::SurfacePoint;

// Probabilities of drawing a direction from the cosine (Lambert) lobe, the
// GGX lobe and the GTR1 (clearcoat) lobe. Lambert + GGX: in proportion to
// the luminance of kd and ks; the GGX lobe only where the material has one
// and wo is above the shading normal (elsewhere lc_brdf_cos has no GGX
// term); all 0 for a black material. Disney: the cosine lobe for diffuse
// and sheen, GGX for the specular lobe, GTR1 for the clearcoat, in
// proportion to rough estimates of their reflectance; all 0 where wo is
// below the shading normal (the BRDF is zero there).
struct LobeWeights {
    float diffuse = 0.0f;
    float specular = 0.0f;
    float clearcoat = 0.0f;
};
LobeWeights lobe_weights(const gpu::Material& m, glm::vec3 n, glm::vec3 wo);

// A direction drawn from a material's lobes at a shaded point.
struct BsdfSample {
    glm::vec3 wi{0.0f};
    float pdf = 0.0f;         // of the lobe mixture, per unit solid angle; 0: none (the path ends)
    glm::vec3 weight{0.0f};   // lc_brdf_cos / pdf
};

// Lambert: cosine-weighted. GGX: a half vector h from D(h) cos(theta_h),
// wi = wo reflected about h, with density D cos(theta_h) / (4 wo.h) (Walter
// et al. 2007); GTR1 likewise with its D. `u_lobe` picks the lobe, (u1, u2) the direction; all in [0, 1).
// `k` only provides the shared BRDF formulas (no scene data is read).
BsdfSample sample_bsdf(Kernel& k, const gpu::Material& m, const LobeWeights& lobes, glm::vec3 n,
                       glm::vec3 wo, float u_lobe, float u1, float u2);

// The density sample_bsdf draws `wi` with (0 below the shading normal).
float bsdf_pdf(Kernel& k, const gpu::Material& m, const LobeWeights& lobes, glm::vec3 n, glm::vec3 wo,
               glm::vec3 wi);

// Veach's power heuristic for one sample of each of two techniques: the
// weight of the technique with density `pdf` against the other's `other`.
float power_heuristic(float pdf, float other);

// Samples a pixel the next pass takes, `done` of `spp` done: passes of 1,
// 1, 2, 4, ... (each doubling what is done), and under a time limit
// (`time_limit` > 0 seconds, `elapsed` of them gone) no more than the time
// left holds at `seconds_per_sample` (a sample a pixel, as the last pass
// took). 0 means stop: all done, or not one more sample fits. The first
// pass always takes one.
std::uint32_t next_pass_samples(std::uint32_t done, std::uint32_t spp, double time_limit, double elapsed,
                                double seconds_per_sample);

// The rays a path tracer's samples cast: shadow rays (next-event
// estimation) and the rays that continue paths after a bounce.
struct PathRays {
    std::uint64_t shadow = 0, bounce = 0;
};

// One path tracer bound to a prepared scene (which must outlive it) and a
// set of options. sample() is const and thread-safe.
class PathTracer {
public:
    PathTracer(const PreparedScene& prepared, const RenderOptions& options);

    const gpu::FrameParams& frame() const { return frame_; }

    // The radiance estimate of one path: path `j` (of light_samples) of
    // camera sample `s` of pixel (x, y), the same camera ray as every other
    // method's sample s. Its random numbers are hashes of (seed, x, y, s, j,
    // bounce, dimension), so the result depends on nothing else. Adds the
    // rays it cast to `rays`.
    glm::vec3 sample(std::uint32_t x, std::uint32_t y, std::uint32_t s, PathRays& rays, std::uint32_t j = 0) const;

private:
    class VertexRandom;

    // NEE at sp, whose geometric normal (facing_normal) is ng: the
    // emitters MIS weighs against the BRDF's rays take nothing from where
    // those rays end, into the surface.
    glm::vec3 next_event(Kernel& k, const SurfacePoint& sp, glm::vec3 ng, const LobeWeights& lobes,
                         VertexRandom& rnd, std::uint64_t& shadow_rays) const;
    glm::vec3 light_sample(Kernel& k, const SurfacePoint& sp, std::uint32_t light, float pmf,
                           std::uint64_t& shadow_rays) const;
    glm::vec3 triangle_sample(Kernel& k, const SurfacePoint& sp, glm::vec3 ng, const LobeWeights& lobes,
                              std::uint32_t tri, VertexRandom& rnd, std::uint64_t& shadow_rays) const;
    glm::vec3 environment_sample(Kernel& k, const SurfacePoint& sp, glm::vec3 ng, const LobeWeights& lobes,
                                 float pmf, VertexRandom& rnd, std::uint64_t& shadow_rays) const;
    // Density with which NEE picks the point of triangle `tri` hit at
    // distance t along wi, per unit solid angle.
    float triangle_light_pdf(std::uint32_t tri, glm::vec3 wi, float t) const;

    const PreparedScene& prepared_;
    gpu::FrameParams frame_;
    std::uint32_t max_bounces_;  // 0: unlimited
    EmitterTable emitters_;
    Kernel kernel_;              // copied per path: the kernel's functions are not const
};

}  // namespace lc::path
