// The unbiased CPU path tracer (host/path_tracer.h) and render_path, which
// runs it over the image in passes of samples.
#include "path_tracer.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <exception>
#include <numeric>
#include <stdexcept>
#include <thread>

#include "progress.h"
#include "tile_pool.h"

namespace lc::path {
namespace {

constexpr float kPi = 3.14159265358979f;

// Russian roulette only after this many bounces: the first ones carry most
// of the indirect light and stay free of its extra noise.
constexpr std::uint32_t kRouletteAfter = 3;
constexpr float kMaxSurvival = 0.95f;

// The random dimensions of one path vertex.
enum Dimension : std::uint32_t {
    kDimLightPick,   // which emitter (53 bits: a table may hold millions)
    kDimLight0,      // the point on it: barycentrics, or the environment's
    kDimLight1,      //   row and column (53 bits each) ...
    kDimLight2,      //   ... and the position within the texel
    kDimLight3,
    kDimLobe,        // Lambert or GGX
    kDimDirection0,  // the direction within the lobe
    kDimDirection1,
    kDimRoulette,
};

[[maybe_unused]] bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool black(glm::vec3 v) { return !(v.x > 0.0f || v.y > 0.0f || v.z > 0.0f); }

// Adds one contribution to a path's radiance. A contribution that is not
// finite is a bug (a zero pdf that was divided by, a degenerate vector):
// debug builds stop here; release builds let it through to the image
// rather than hide it.
void add(glm::vec3& radiance, glm::vec3 contribution) {
    assert(finite(contribution) && "path tracer: non-finite contribution");
    radiance += contribution;
}

}  // namespace

// The random numbers of one vertex of one path: sub-streams of the camera
// sample's stream (lc_sample_stream), first by bounce, then by dimension.
class PathTracer::VertexRandom {
public:
    VertexRandom(Kernel& k, std::uint32_t sample_stream, std::uint32_t bounce)
        : k_(k), stream_(k.lc_substream(sample_stream, bounce)) {}

    // 24 bits in [0, 1), as the kernels' lc_unit_float.
    float unit(Dimension d) { return gpu::lc_unit_float(k_.lc_substream(stream_, d)); }

    // 53 bits in [0, 1) from two hashes, for discrete choices among many
    // entries: with 24 bits an entry of probability below 2^-24 could be
    // unreachable while its pdf says otherwise.
    double fine(Dimension d) {
        const std::uint32_t h1 = k_.lc_substream(stream_, d);
        const std::uint32_t h2 = gpu::lc_hash(h1);
        return (double(h1 >> 5) * 67108864.0 + double(h2 >> 6)) * (1.0 / 9007199254740992.0);
    }

private:
    Kernel& k_;
    std::uint32_t stream_;
};

// ---- BRDF sampling ----

namespace {

// Disney: the diffuse and sheen lobes through the cosine lobe, the specular
// lobe through GGX whose Fresnel reaches 1 at grazing angles (hence the
// floor), the clearcoat through GTR1; nothing where wo is below n, where the
// BRDF is zero.
LobeWeights disney_lobe_weights(Kernel& k, const gpu::Material& m, glm::vec3 n, glm::vec3 wo) {
    if (!(glm::dot(n, wo) > 0.0f)) return {};
    const float diffuse = gpu::lc_luminance(k.lc_kd(m)) * (1.0f - m.metallic) +
                          ((m.flags & gpu::kMaterialHasSheen) != 0u ? gpu::lc_luminance(k.lc_disney_sheen_color(m)) : 0.0f);
    const float specular = std::max(gpu::lc_luminance(k.lc_disney_spec0(m)), 0.1f);
    const float clearcoat = (m.flags & gpu::kMaterialHasClearcoat) != 0u ? 0.25f * m.clearcoat : 0.0f;
    const float total = std::max(diffuse, 0.0f) + specular + clearcoat;
    return {std::max(diffuse, 0.0f) / total, specular / total, clearcoat / total};
}

// A half vector around n at the angle theta_h (its cosine and sine) and
// azimuth phi. The sine comes from the sampled value, not as
// sqrt(1 - cos^2): near a sharp peak cos_h rounds to steps of about 1e-7,
// and sin_h from it took a few angles only (at alpha 1e-3, 0, 0.69 alpha,
// 0.98 alpha, ..., a seventh of the samples exactly on the mirror
// direction; an audit).
glm::vec3 half_vector(glm::vec3 n, glm::vec3 t, glm::vec3 b, float cos_h, float sin_h, float phi) {
    return sin_h * std::cos(phi) * t + sin_h * std::sin(phi) * b + cos_h * n;
}

}  // namespace

LobeWeights lobe_weights(const gpu::Material& m, glm::vec3 n, glm::vec3 wo) {
    if ((m.flags & gpu::kMaterialDisney) != 0u) {
        Kernel k;  // only its BRDF formulas, which read no scene data
        return disney_lobe_weights(k, m, n, wo);
    }
    const float diffuse = gpu::lc_luminance(glm::vec3(m.kd_r, m.kd_g, m.kd_b));
    const bool ggx = (m.flags & gpu::kMaterialHasSpecular) != 0u && glm::dot(n, wo) > 0.0f;
    const float specular = ggx ? gpu::lc_luminance(glm::vec3(m.ks_r, m.ks_g, m.ks_b)) : 0.0f;
    const float total = std::max(diffuse, 0.0f) + std::max(specular, 0.0f);
    if (!(total > 0.0f)) return {};
    return {std::max(diffuse, 0.0f) / total, std::max(specular, 0.0f) / total};
}

float bsdf_pdf(Kernel& k, const gpu::Material& m, const LobeWeights& lobes, glm::vec3 n, glm::vec3 wo,
               glm::vec3 wi) {
    const float cos_i = glm::dot(n, wi);
    if (!(cos_i > 0.0f)) return 0.0f;
    float pdf = lobes.diffuse * cos_i / kPi;
    if (lobes.specular > 0.0f) {
        // wo.(wi + wo) = 1 + wo.wi >= 0, so h is on wo's side of every
        // reflection and the one half vector that reflects wo into wi.
        const glm::vec3 h = glm::normalize(wi + wo);
        const glm::vec2 half_angle = k.lc_half_angle(n, h);
        const float wo_h = glm::dot(wo, h);
        if (half_angle.x > 0.0f && wo_h > 0.0f)
            pdf += lobes.specular * k.lc_ggx_d(half_angle.x, half_angle.y, m.alpha) * half_angle.x / (4.0f * wo_h);
    }
    if (lobes.clearcoat > 0.0f) {
        const glm::vec3 h = glm::normalize(wi + wo);
        const glm::vec2 half_angle = k.lc_half_angle(n, h);
        const float wo_h = glm::dot(wo, h);
        if (half_angle.x > 0.0f && wo_h > 0.0f)
            pdf += lobes.clearcoat * k.lc_gtr1_d(half_angle.x, half_angle.y, k.lc_clearcoat_alpha(m)) * half_angle.x /
                   (4.0f * wo_h);
    }
    return pdf;
}

BsdfSample sample_bsdf(Kernel& k, const gpu::Material& m, const LobeWeights& lobes, glm::vec3 n,
                       glm::vec3 wo, float u_lobe, float u1, float u2) {
    if (!(lobes.diffuse + lobes.specular + lobes.clearcoat > 0.0f)) return {};
    glm::vec3 t, b;
    k.lc_basis(n, t, b);
    const float phi = 2.0f * kPi * u2;
    glm::vec3 wi;
    if (u_lobe < lobes.diffuse) {
        // Malley's method: uniform on the disk, projected up to the hemisphere.
        const float r = std::sqrt(u1);
        wi = r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - u1)) * n;
    } else {
        float cos_h, sin_h;
        if (lobes.clearcoat <= 0.0f || u_lobe < lobes.diffuse + lobes.specular) {
            // Inverting the CDF of D cos(theta_h): tan^2 = alpha^2 u / (1 - u).
            const float tan2 = m.alpha * m.alpha * u1 / (1.0f - u1);
            cos_h = 1.0f / std::sqrt(1.0f + tan2);
            sin_h = std::sqrt(tan2) * cos_h;
        } else {
            // GTR1's (Burley 2012, appendix B): cos^2 = (1 - a^(2(1 - u))) / (1 - a^2),
            // so sin^2 = (a^(2(1 - u)) - a^2) / (1 - a^2).
            const float a2 = k.lc_clearcoat_alpha(m) * k.lc_clearcoat_alpha(m);
            const float power = std::pow(a2, 1.0f - u1);
            cos_h = std::sqrt(std::max(0.0f, (1.0f - power) / (1.0f - a2)));
            sin_h = std::sqrt(std::max(0.0f, (power - a2) / (1.0f - a2)));
        }
        const glm::vec3 h = half_vector(n, t, b, cos_h, sin_h, phi);
        const float wo_h = glm::dot(wo, h);
        if (!(wo_h > 0.0f)) return {};  // wo sees h from behind: no reflection
        wi = 2.0f * wo_h * h - wo;
    }
    wi = glm::normalize(wi);
    const float cos_i = glm::dot(n, wi);
    if (!(cos_i > 0.0f)) return {};  // below the surface: the path ends
    BsdfSample s;
    s.pdf = bsdf_pdf(k, m, lobes, n, wo, wi);
    if (!(s.pdf > 0.0f)) return {};
    s.wi = wi;
    s.weight = k.lc_brdf_cos(m, n, wi, wo, cos_i) / s.pdf;
    return s;
}

float power_heuristic(float pdf, float other) {
    if (!(pdf > 0.0f)) return 0.0f;
    if (std::isinf(pdf)) return std::isinf(other) ? 0.5f : 1.0f;
    // pdf^2 / (pdf^2 + other^2) through the ratio, which cannot overflow.
    const float r = other / pdf;
    return 1.0f / (1.0f + r * r);
}

// ---- The path tracer ----

PathTracer::PathTracer(const PreparedScene& prepared, const RenderOptions& options)
    : prepared_(prepared),
      frame_(make_frame_params(prepared, options)),
      max_bounces_(options.max_bounces),
      emitters_(prepared.scene),
      kernel_(cpu::make_shade_kernel(prepared, nullptr)) {}

glm::vec3 PathTracer::sample(std::uint32_t x, std::uint32_t y, std::uint32_t s, PathRays& rays,
                             std::uint32_t j) const {
    Kernel k = kernel_;
    // lc_camera_sample's steps, keeping the triangle for its normal.
    glm::vec3 dir;
    float t0, b1_0, b2_0;
    const std::uint32_t first = k.lc_camera_trace(frame_, x, y, s, dir, t0, b1_0, b2_0);
    // What the camera ray itself finds counts fully: no other technique
    // reaches the first surface.
    if (first == gpu::kInvalidIndex) return k.lc_environment_radiance(frame_, dir);
    SurfacePoint sp = k.lc_surface_point(first, b1_0, b2_0, dir, frame_.pixel_spread * t0);
    glm::vec3 radiance = k.lc_surface_emission(first, b1_0, b2_0, dir, sp.footprint);
    glm::vec3 ng = facing_normal(prepared_.scene.triangles[first], dir, sp.n);
    std::uint32_t stream = k.lc_sample_stream(frame_.seed, x, y, s);
    if (j > 0) stream = k.lc_substream(stream, 0x70617468u + j);  // further paths of the same camera ray
    glm::vec3 throughput(1.0f);
    // Bounce b is the b-th surface interaction: light reflected there, found
    // by NEE or by the ray its BRDF sample sends, has been reflected b times.
    for (std::uint32_t bounce = 1;; ++bounce) {
        VertexRandom rnd(k, stream, bounce);
        const gpu::Material& m = sp.mat;
        const LobeWeights lobes = lobe_weights(m, sp.n, sp.wo);
        add(radiance, throughput * next_event(k, sp, ng, lobes, rnd, rays.shadow));

        const BsdfSample b = sample_bsdf(k, m, lobes, sp.n, sp.wo, rnd.unit(kDimLobe), rnd.unit(kDimDirection0),
                                         rnd.unit(kDimDirection1));
        if (!(b.pdf > 0.0f)) break;
        if (!(glm::dot(ng, b.wi) > 0.0f)) break;  // into the surface: an opaque one reflects nothing there
        throughput *= b.weight;
        float t, b1, b2;
        const std::uint32_t tri = k.lc_trace_first_hit(sp.p, b.wi, Kernel::kRayInfinity, t, b1, b2);
        ++rays.bounce;
        // Emission the BRDF ray finds, weighted against NEE's chance of
        // having found the same light.
        if (tri == gpu::kInvalidIndex) {
            const glm::vec3 sky = k.lc_environment_radiance(frame_, b.wi);
            if (!black(sky)) {
                const float light_pdf = emitters_.environment_pmf() * emitters_.environment().pdf(b.wi);
                add(radiance, throughput * sky * power_heuristic(b.pdf, light_pdf));
            }
            break;
        }
        const glm::vec3 emitted = k.lc_surface_emission(tri, b1, b2, b.wi, glm::vec4(0.0f));
        if (!black(emitted))
            add(radiance, throughput * emitted * power_heuristic(b.pdf, triangle_light_pdf(tri, b.wi, t)));

        if (bounce == max_bounces_) break;
        if (bounce >= kRouletteAfter) {
            // Russian roulette: survival in proportion to the throughput,
            // the survivors weighted up by its inverse (unbiased).
            const float q = std::min(std::max(throughput.x, std::max(throughput.y, throughput.z)), kMaxSurvival);
            if (!(rnd.unit(kDimRoulette) < q)) break;
            throughput /= q;
        }
        sp = k.lc_surface_point(tri, b1, b2, b.wi, 0.0f);
        ng = facing_normal(prepared_.scene.triangles[tri], b.wi, sp.n);
    }
    return radiance;
}

glm::vec3 PathTracer::next_event(Kernel& k, const SurfacePoint& sp, glm::vec3 ng, const LobeWeights& lobes,
                                 VertexRandom& rnd, std::uint64_t& shadow_rays) const {
    if (emitters_.empty()) return glm::vec3(0.0f);
    float pmf;
    const Emitter e = emitters_.pick(rnd.fine(kDimLightPick), pmf);
    switch (e.kind) {
        case EmitterKind::kLight: return light_sample(k, sp, e.index, pmf, shadow_rays);
        case EmitterKind::kTriangle: return triangle_sample(k, sp, ng, lobes, e.index, rnd, shadow_rays);
        case EmitterKind::kEnvironment: return environment_sample(k, sp, ng, lobes, pmf, rnd, shadow_rays);
    }
    return glm::vec3(0.0f);
}

// A point, spot or directional light: a delta, which no BRDF ray can find,
// so NEE takes it with weight 1. lc_light_unit is the brute-force
// renderer's exact term (with its clamp of 1/d^2 at min_distance2); as
// there, a light below the geometric normal is left to the shadow ray,
// which the surface itself blocks.
glm::vec3 PathTracer::light_sample(Kernel& k, const SurfacePoint& sp, std::uint32_t light, float pmf,
                                   std::uint64_t& shadow_rays) const {
    const gpu::Light& l = prepared_.scene.lights[light];
    glm::vec3 wi;
    float t_max;
    const glm::vec3 unit = k.lc_light_unit(sp, l, frame_.min_distance2, wi, t_max);
    if (black(unit)) return glm::vec3(0.0f);
    ++shadow_rays;
    if (k.lc_trace_shadow(sp.p, wi, t_max)) return glm::vec3(0.0f);
    return unit * k.lc_light_intensity(l) / pmf;
}

// An emissive triangle: a point uniform over its area, whose density per
// unit solid angle at sp is triangle_light_pdf (pick() gave this
// triangle with probability triangle_pmf).
glm::vec3 PathTracer::triangle_sample(Kernel& k, const SurfacePoint& sp, glm::vec3 ng, const LobeWeights& lobes,
                                      std::uint32_t tri, VertexRandom& rnd, std::uint64_t& shadow_rays) const {
    const gpu::Triangle& t = prepared_.scene.triangles[tri];
    const glm::vec3 a = k.lc_tri_v0(t), b = k.lc_tri_v1(t), c = k.lc_tri_v2(t);
    // Area-preserving square-to-triangle map (Shirley and Chiu).
    const float su = std::sqrt(rnd.unit(kDimLight0));
    const float v = rnd.unit(kDimLight1);
    const glm::vec3 to_light = (1.0f - su) * a + su * (1.0f - v) * b + su * v * c - sp.p;
    const float d = glm::length(to_light);
    if (!(d > 0.0f)) return glm::vec3(0.0f);
    const glm::vec3 wi = to_light / d;
    const float cos_i = glm::dot(sp.n, wi);
    if (!(cos_i > 0.0f) || !(glm::dot(ng, wi) > 0.0f)) return glm::vec3(0.0f);
    const glm::vec3 emitted = k.lc_surface_emission(tri, su * (1.0f - v), su * v, wi, glm::vec4(0.0f));
    if (black(emitted)) return glm::vec3(0.0f);  // sp sees its back
    const float light_pdf = triangle_light_pdf(tri, wi, d);
    if (!(light_pdf > 0.0f && std::isfinite(light_pdf))) return glm::vec3(0.0f);  // seen edge-on
    const gpu::Material& m = sp.mat;
    // No shadow ray where the BRDF is black (a black material, a view from
    // below the shading normal): it could not change the sum.
    const glm::vec3 f = k.lc_brdf_cos(m, sp.n, wi, sp.wo, cos_i);
    if (black(f)) return glm::vec3(0.0f);
    const float weight = power_heuristic(light_pdf, bsdf_pdf(k, m, lobes, sp.n, sp.wo, wi));
    ++shadow_rays;
    if (k.lc_trace_shadow(sp.p, wi, d * (1.0f - Kernel::kShadowEndRelative))) return glm::vec3(0.0f);
    return f * emitted * (weight / light_pdf);
}

float PathTracer::triangle_light_pdf(std::uint32_t tri, glm::vec3 wi, float t) const {
    const float pmf = emitters_.triangle_pmf(tri);
    if (!(pmf > 0.0f)) return 0.0f;
    const gpu::Triangle& tr = prepared_.scene.triangles[tri];
    const glm::vec3 a(tr.v0_x, tr.v0_y, tr.v0_z), b(tr.v1_x, tr.v1_y, tr.v1_z), c(tr.v2_x, tr.v2_y, tr.v2_z);
    const glm::vec3 n2 = glm::cross(b - a, c - a);  // twice the area, along the normal
    const float twice_area_cos = std::abs(glm::dot(n2, wi));
    // Infinite edge-on, which power_heuristic takes as certainty.
    return pmf * 2.0f * t * t / twice_area_cos;
}

// The environment: a direction by luminance x solid angle (EnvironmentSampler).
glm::vec3 PathTracer::environment_sample(Kernel& k, const SurfacePoint& sp, glm::vec3 ng, const LobeWeights& lobes,
                                         float pmf, VertexRandom& rnd, std::uint64_t& shadow_rays) const {
    float direction_pdf;
    const glm::vec3 wi = emitters_.environment().sample(rnd.fine(kDimLight0), rnd.fine(kDimLight1),
                                                        rnd.unit(kDimLight2), rnd.unit(kDimLight3), direction_pdf);
    const float cos_i = glm::dot(sp.n, wi);
    const float light_pdf = pmf * direction_pdf;
    if (!(cos_i > 0.0f) || !(glm::dot(ng, wi) > 0.0f) || !(light_pdf > 0.0f)) return glm::vec3(0.0f);
    const glm::vec3 sky = k.lc_environment_radiance(frame_, wi);
    if (black(sky)) return glm::vec3(0.0f);
    const gpu::Material& m = sp.mat;
    const glm::vec3 f = k.lc_brdf_cos(m, sp.n, wi, sp.wo, cos_i);
    if (black(f)) return glm::vec3(0.0f);  // as for a triangle
    const float weight = power_heuristic(light_pdf, bsdf_pdf(k, m, lobes, sp.n, sp.wo, wi));
    ++shadow_rays;
    if (k.lc_trace_shadow(sp.p, wi, Kernel::kRayInfinity)) return glm::vec3(0.0f);
    return f * sky * (weight / light_pdf);
}

std::uint32_t next_pass_samples(std::uint32_t done, std::uint32_t spp, double time_limit, double elapsed,
                                double seconds_per_sample) {
    if (done >= spp) return 0;
    const std::uint32_t doubling = std::min(std::max(done, 1u), spp - done);
    if (!(time_limit > 0.0) || done == 0) return doubling;
    // NaN (no time left and no time measured) and negative counts stop too.
    const double fits = (time_limit - elapsed) / seconds_per_sample;
    if (!(fits >= 1.0)) return 0;
    return fits >= double(doubling) ? doubling : std::uint32_t(fits);
}

}  // namespace lc::path

// ---- render_path: the image in passes of samples ----

namespace lc {
namespace {

using Clock = std::chrono::steady_clock;


// The order a pixel's camera samples are taken in: the i-th is sample
// (i * stride) mod spp, the stride coprime to spp and near spp / golden
// ratio. lc_pixel_sample stratifies sample s over a grid filled row by row,
// so samples taken in order would leave a render stopped by its time limit
// with the top rows of every pixel only; with this stride (a Fibonacci-like
// rank-1 lattice) every prefix spreads over the whole pixel. A full render
// takes every sample once, as the other methods do.
class SampleOrder {
public:
    explicit SampleOrder(std::uint32_t spp) : spp_(spp) {
        const auto nearest = std::int64_t(std::llround(0.6180339887498949 * spp));
        for (std::int64_t d = 0; d <= std::int64_t(spp); ++d) {
            for (std::int64_t g : {nearest - d, nearest + d}) {
                if (g >= 1 && g < std::int64_t(spp) && std::gcd(g, std::int64_t(spp)) == 1) {
                    stride_ = std::uint64_t(g);
                    return;
                }
            }
        }
    }
    std::uint32_t operator()(std::uint32_t i) const { return std::uint32_t(std::uint64_t(i) * stride_ % spp_); }

private:
    std::uint64_t spp_;
    std::uint64_t stride_ = 1;  // spp 1 and 2
};

// A worker thread's counters, on a cache line of its own.
struct alignas(64) Worker {
    path::PathRays rays;
};


}  // namespace

RenderResult render_path(const PreparedScene& prepared, const RenderOptions& options) {
    validate_render_options(options);
    const auto start = Clock::now();
    const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    const path::PathTracer tracer(prepared, options);
    const gpu::FrameParams& frame = tracer.frame();
    // Paths per pixel: light_samples paths along each of the spp camera
    // rays (--spp 1 --light-samples N: N paths through the pixel centre, the
    // reference for the other methods at 1 spp).
    const std::uint32_t camera_spp = frame.spp;
    const std::uint32_t spp = camera_spp * std::max(frame.light_samples, 1u);

    const std::uint32_t tiles_x = (frame.width + kTile - 1) / kTile;
    const std::uint32_t tile_count = tiles_x * ((frame.height + kTile - 1) / kTile);
    const unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
    std::vector<Worker> workers(std::max(1u, std::min(threads, tile_count)));
    // Per-pixel sums in double: at high spp a float sum would lose the
    // last samples' bits. Each pixel adds its samples in one fixed order,
    // so the image does not depend on the thread count.
    std::vector<glm::dvec3> sums(std::size_t(frame.width) * frame.height, glm::dvec3(0.0));
    const SampleOrder order(spp);
    Progress progress(options.progress);

    // The passes end near a time limit instead of overrunning it by up to
    // the time already taken, as doubling passes alone would.
    std::uint32_t done = 0;
    double seconds_per_sample = 0.0;  // a sample a pixel, measured on the last pass
    while (const std::uint32_t take =
               path::next_pass_samples(done, spp, options.time_limit, elapsed(), seconds_per_sample)) {
        const std::uint32_t end = done + take;
        const double pass_start = elapsed();
        std::atomic<std::uint32_t> tiles_done{0};
        for_each_tile(tile_count, workers, [&](std::uint32_t tile, Worker& w) {
            const std::uint32_t x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
            for (std::uint32_t y = y0; y < std::min(y0 + kTile, frame.height); ++y)
                for (std::uint32_t x = x0; x < std::min(x0 + kTile, frame.width); ++x) {
                    glm::dvec3& sum = sums[std::size_t(y) * frame.width + x];
                    for (std::uint32_t i = done; i < end; ++i) {
                        const std::uint32_t k = order(i);
                        sum += glm::dvec3(tracer.sample(x, y, k % camera_spp, w.rays, k / camera_spp));
                    }
                }
            // Done: the samples' share, or the time limit's if that ends the render sooner.
            const double tiles = double(tiles_done.fetch_add(1) + 1) / tile_count;
            double fraction = (done + (end - done) * tiles) / spp;
            if (options.time_limit > 0.0) fraction = std::max(fraction, elapsed() / options.time_limit);
            progress.update(std::min(fraction, 1.0));
        });
        seconds_per_sample = (elapsed() - pass_start) / double(take);
        done = end;
    }
    progress.finish();

    RenderResult result;
    result.image = Image(frame.width, frame.height);
    for (std::uint32_t y = 0; y < frame.height; ++y)
        for (std::uint32_t x = 0; x < frame.width; ++x)
            result.image.set(x, y, glm::vec3(sums[std::size_t(y) * frame.width + x] / double(done)));
    RenderStats& stats = result.stats;
    stats.device = "cpu";
    stats.spp_done = done;
    stats.camera_rays = std::uint64_t(frame.width) * frame.height * done;
    for (const Worker& w : workers) {
        stats.shadow_rays += w.rays.shadow;
        stats.bounce_rays += w.rays.bounce;
    }
    stats.seconds_total = elapsed();
    stats.seconds_shading = stats.seconds_total;  // the CPU does not time the stages apart
    return result;
}

}  // namespace lc
