// Virtual point lights from light paths (host/vpls.h).
#include "vpls.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "cpu_kernel.h"
#include "path_emitters.h"
#include "run_on_threads.h"
#include "scene/light_records.h"
#include "lc_shared/color.h"

namespace lc {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr std::size_t kMaxPathsPerVpl = 64;  // give up on scenes that paths mostly miss
// Russian roulette's survival is at most this, as the path tracer's: an
// albedo of 1 in a closed scene would otherwise never end a path.
constexpr float kMaxSurvival = 0.95f;
// The pilot paths, which measure how many VPLs a path leaves so that the
// path count can be fixed before the VPLs are traced: a sixteenth of the
// VPLs asked for, within these bounds (4096 paths put the rate within about
// 1% on the shipped scenes, and cost under a tenth of 10^5 VPLs' paths).
// Their own VPLs are not kept.
constexpr std::size_t kMinPilotPaths = 1024, kMaxPilotPaths = 4096;
constexpr std::uint64_t kPilotIndexBase = std::uint64_t(1) << 62;  // apart from the paths' indices

// A path's random numbers: a hash chain from (seed, path index).
class PathRandom {
public:
    PathRandom(std::uint32_t seed, std::uint64_t path)
        : state_(gpu::lc_hash(gpu::lc_hash(seed ^ 0x2545F491u) ^
                              gpu::lc_hash(std::uint32_t(path) ^ gpu::lc_hash(std::uint32_t(path >> 32))))) {}
    float next() {
        state_ = gpu::lc_hash(state_);
        return gpu::lc_unit_float(state_);
    }
    // 53 bits in [0, 1), for the choice among millions of lights (with 24
    // bits a light of probability below 2^-24 could never be drawn).
    double fine() {
        const std::uint32_t h1 = gpu::lc_hash(state_);
        state_ = gpu::lc_hash(h1);
        return (double(h1 >> 5) * 67108864.0 + double(state_ >> 6)) * (1.0 / 9007199254740992.0);
    }

private:
    std::uint32_t state_;
};

glm::vec3 intensity(const gpu::Light& l) { return {l.r, l.g, l.b}; }
glm::vec3 axis(const gpu::Light& l) { return {l.axis_x, l.axis_y, l.axis_z}; }
std::uint32_t type_of(const gpu::Light& l) { return l.type & gpu::kLightTypeMask; }

// A unit vector at cosine `c` from n, at azimuth 2 pi u (the kernel's basis, lc_basis).
glm::vec3 around(cpu::ShadeKernel& k, glm::vec3 n, float c, float u) {
    glm::vec3 t, b;
    k.lc_basis(n, t, b);
    const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
    const float phi = 2.0f * kPi * u;
    return glm::normalize(s * std::cos(phi) * t + s * std::sin(phi) * b + c * n);
}

// Cosine-weighted direction around n (pdf cos / pi).
glm::vec3 cosine_direction(cpu::ShadeKernel& k, glm::vec3 n, PathRandom& rng) {
    const float c = std::sqrt(rng.next());
    return around(k, n, c, rng.next());
}

// What the emitters add up to, and how a path starts from one of them.
class Emitters {
public:
    Emitters(std::span<const gpu::Light> lights, const Scene& scene) : lights_(lights) {
        centre_ = 0.5f * (scene.bounds_min + scene.bounds_max);
        radius_ = std::max(0.5f * glm::length(scene.bounds_max - scene.bounds_min), 1e-6f);
        std::vector<double> weights;
        weights.reserve(lights.size());
        // The path tracer's estimate of a light's power (host/path_emitters.h):
        // any positive value keeps the flux unbiased; in proportion to the
        // real power, each path carries about the same.
        for (const gpu::Light& l : lights) weights.push_back(path::light_power(l, radius_));
        power_ = path::Distribution1D(weights);
    }

    bool empty() const { return !(power_.total() > 0.0); }

    // A ray leaving a light in proportion to power: origin, direction and
    // the flux it carries, I(w) / (P(light) pdf(w)), in double (4 pi I of a
    // float intensity may be past float's range). False when the draw
    // carries nothing.
    bool start(cpu::ShadeKernel& k, PathRandom& rng, glm::vec3& org, glm::vec3& dir, glm::dvec3& flux) const {
        const std::uint32_t i = power_.sample(rng.fine());  // never a light of zero power
        const gpu::Light& l = lights_[i];
        const double p_light = power_.pmf(i);
        if (!(p_light > 0.0)) return false;
        const glm::vec3 position(l.x, l.y, l.z);
        float emitted = 1.0f;  // I(w) / I, over pdf(w)
        switch (type_of(l)) {
            case gpu::kLightPoint: {
                const float c = 1.0f - 2.0f * rng.next();
                dir = around(k, glm::vec3(0, 0, 1), c, rng.next());
                org = position;
                emitted = 4.0f * kPi;
                break;
            }
            case gpu::kLightSpot: {
                const float c = 1.0f - rng.next() * (1.0f - l.cos_outer);
                dir = around(k, axis(l), c, rng.next());
                org = position;
                emitted = k.lc_spot_falloff(l, c) * 2.0f * kPi * (1.0f - l.cos_outer);
                break;
            }
            case gpu::kLightOriented:
            case gpu::kLightVpl: {
                glm::vec3 n = axis(l);
                float sides = 1.0f;
                if (l.type & gpu::kLightTwoSided) {
                    sides = 2.0f;
                    if (rng.next() < 0.5f) n = -n;
                }
                dir = cosine_direction(k, n, rng);
                org = offset(position, n);
                emitted = sides * kPi;
                break;
            }
            case gpu::kLightDirectional: {
                // From a disk as wide as the scene's bounding sphere, outside it.
                const glm::vec3 towards(l.x, l.y, l.z);
                dir = -towards;
                const float r = radius_ * std::sqrt(rng.next());
                const glm::vec3 across = around(k, towards, 0.0f, rng.next());
                org = centre_ + towards * (2.0f * radius_) + across * r;
                emitted = kPi * radius_ * radius_;
                break;
            }
            default:
                return false;
        }
        flux = glm::dvec3(intensity(l)) * (double(emitted) / p_light);
        return emitted > 0.0f;
    }

private:
    // A ray origin off an emitting surface, as lc_offset_hit_point moves hit points.
    static glm::vec3 offset(glm::vec3 p, glm::vec3 n) {
        const glm::vec3 m = glm::abs(p);
        return p + n * (4.0f * cpu::ShadeKernel::kHitOffsetRelative * std::max({m.x, m.y, m.z, 1e-3f}));
    }

    std::span<const gpu::Light> lights_;
    path::Distribution1D power_;
    glm::vec3 centre_;
    float radius_;
};

// One path's VPLs, their intensities times `scale` (1 / the path count),
// appended to `out` where it is given; returns how many it left.
// (`kernel` is the thread's own copy: its functions are non-const members.)
std::size_t trace_path(cpu::ShadeKernel& kernel, const Emitters& emitters, std::uint32_t seed, std::uint64_t index,
                       std::uint32_t max_bounces, double scale, std::vector<gpu::Light>* out) {
    PathRandom rng(seed, index);
    glm::vec3 org, dir;
    glm::dvec3 flux;
    if (!emitters.start(kernel, rng, org, dir, flux)) return 0;
    for (std::uint32_t bounce = 1;; ++bounce) {
        float t, b1, b2;
        const std::uint32_t tri = kernel.lc_trace_first_hit(org, dir, cpu::ShadeKernel::kRayInfinity, t, b1, b2);
        if (tri == gpu::kInvalidIndex) return bounce - 1;
        const auto sp = kernel.lc_surface_point(tri, b1, b2, dir, 0.0f);
        const gpu::Material& m = sp.mat;
        // Only the diffuse part re-emits: a Disney material's is its base
        // colour times (1 - metallic) (docs/lightcuts.md, "Indirect light").
        const glm::vec3 kd = glm::vec3(m.kd_r, m.kd_g, m.kd_b) *
                             ((m.flags & gpu::kMaterialDisney) != 0u ? 1.0f - m.metallic : 1.0f);
        const float survive = std::min(kMaxSurvival, std::max({kd.x, kd.y, kd.z}));
        if (!(survive > 0.0f)) return bounce - 1;
        // Shading normals (vertex normals, normal maps). The flux that
        // reaches the point spreads over the surface by the geometric
        // cosine, while the path tracer weighs the light arriving there by
        // the shading cosine: the ratio of the two brings the VPL to the
        // path tracer's radiance. Leaving, the light crosses the surface's
        // own plane by the geometric cosine, so the VPL emits around the
        // geometric normal, on the side the path came from, and never
        // through the surface (Veach 1997, section 5.3).
        const glm::vec3 ng = path::facing_normal(kernel.triangles[tri], dir, sp.n);
        const float cos_geometric = -glm::dot(ng, dir), cos_shading = -glm::dot(sp.n, dir);
        if (!(cos_geometric > 0.0f) || !(cos_shading > 0.0f)) return bounce - 1;
        const double shading = double(cos_shading) / double(cos_geometric);
        if (out) {
            const glm::dvec3 vpl = flux * glm::dvec3(kd) * (shading * scale / double(kPi));
            gpu::Light l{};
            l.x = sp.p.x; l.y = sp.p.y; l.z = sp.p.z;
            const glm::vec3 c = loader::without_subnormals(glm::vec3(vpl));
            l.r = c.r; l.g = c.g; l.b = c.b;
            l.axis_x = ng.x; l.axis_y = ng.y; l.axis_z = ng.z;
            l.type = gpu::kLightVpl;
            out->push_back(l);
        }
        if (max_bounces != 0 && bounce >= max_bounces) return bounce;
        if (rng.next() >= survive) return bounce;
        flux *= glm::dvec3(kd) * (shading / double(survive));
        org = sp.p;
        dir = cosine_direction(kernel, ng, rng);
    }
}

}  // namespace

VplSet trace_vpls(const Scene& scene, const Bvh& bvh, std::span<const gpu::Light> emitters,
                  const IndirectSettings& settings, std::uint32_t seed, unsigned threads) {
    VplSet set;
    const Emitters source(emitters, scene);
    if (settings.vpls == 0 || source.empty() || scene.triangles.empty()) return set;
    // Without a surface that reflects diffusely no path can leave a VPL, and
    // the pilot, finding none, would have 64 paths a VPL traced for nothing
    // (about 10^9 at the largest count).
    const bool reflects = std::any_of(scene.materials.begin(), scene.materials.end(), [](const gpu::Material& m) {
        const float kd = std::max({m.kd_r, m.kd_g, m.kd_b});
        return kd > 0.0f && ((m.flags & gpu::kMaterialDisney) == 0u || m.metallic < 1.0f ||
                             m.metallic_roughness_texture != gpu::kInvalidIndex);  // may lower the metallic
    });
    if (!reflects) return set;

    cpu::ShadeKernel k;
    k.bvh_nodes = bvh.nodes.data();
    if (cpu::cpu_has_avx2() && !bvh.wide8_nodes.empty()) {  // closest hits through the 8-wide tree, as make_shade_kernel
        k.wide8_nodes = bvh.wide8_nodes.data();
        k.wide8_leaves = bvh.wide8_leaves.data();
    }
    k.triangles = scene.triangles.data();
    k.normals = scene.normals.data();
    k.uvs = scene.uvs.data();
    k.materials = scene.materials.data();
    k.textures = scene.textures.data();
    k.texels = scene.texels.data();

    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t wanted = settings.vpls;

    // The pilot: how many VPLs a path leaves. The path count follows from
    // it and is fixed before the paths are traced, so that dividing by it
    // keeps the flux unbiased (stopping where the VPL count is reached
    // would not: the count of paths would then depend on what they found).
    const std::size_t pilot = std::clamp(wanted / 16, kMinPilotPaths, kMaxPilotPaths);
    std::vector<std::size_t> pilot_vpls(threads, 0);
    run_on_threads(threads, [&](unsigned t) {
        cpu::ShadeKernel kernel = k;
        for (std::size_t p = pilot * t / threads; p < pilot * (t + 1) / threads; ++p)
            pilot_vpls[t] += trace_path(kernel, source, seed, kPilotIndexBase + p, settings.max_bounces, 0.0, nullptr);
    });
    std::size_t found = 0;
    for (std::size_t n : pilot_vpls) found += n;
    const double rate = double(found) / double(pilot);  // VPLs a path
    const std::size_t max_paths = kMaxPathsPerVpl * wanted;
    const std::size_t paths =
        rate > 0.0 ? std::clamp<std::size_t>(std::size_t(std::ceil(double(wanted) / rate)), 1, max_paths) : max_paths;

    // The paths, one contiguous range per thread, joined in path order: the
    // same VPLs whatever the thread count.
    std::vector<std::vector<gpu::Light>> per_thread(threads);
    const double scale = 1.0 / double(paths);
    run_on_threads(threads, [&](unsigned t) {
        const std::size_t first = paths * t / threads, last = paths * (t + 1) / threads;
        per_thread[t].reserve(std::size_t(double(last - first) * rate * 1.1) + 16);
        cpu::ShadeKernel kernel = k;
        for (std::size_t p = first; p < last; ++p)
            trace_path(kernel, source, seed, p, settings.max_bounces, scale, &per_thread[t]);
    });
    std::size_t total = 0;
    for (const auto& v : per_thread) total += v.size();
    set.lights.reserve(total);
    for (auto& v : per_thread) {
        set.lights.insert(set.lights.end(), v.begin(), v.end());
        std::vector<gpu::Light>().swap(v);
    }
    set.paths = paths;
    return set;
}

}  // namespace lc
