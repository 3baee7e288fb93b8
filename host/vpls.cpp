// Virtual point lights from light paths (host/vpls.h).
#include "vpls.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "cpu_kernel.h"
#include "path_emitters.h"
#include "run_on_threads.h"
#include "shared/color.h"

namespace lc {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr std::size_t kMaxPathsPerVpl = 64;  // give up on scenes that paths mostly miss

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
    // the flux it carries, I(w) / (P(light) pdf(w)). False when the draw
    // carries nothing.
    bool start(cpu::ShadeKernel& k, PathRandom& rng, glm::vec3& org, glm::vec3& dir, glm::vec3& flux) const {
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
        flux = intensity(l) * float(double(emitted) / p_light);
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

// One path's VPLs, intensities not yet divided by the path count.
// (`kernel` is the thread's own copy: its functions are non-const members.)
void trace_path(cpu::ShadeKernel& kernel, const Emitters& emitters, std::uint32_t seed, std::uint64_t index,
                std::uint32_t max_bounces, std::vector<gpu::Light>& out) {
    PathRandom rng(seed, index);
    glm::vec3 org, dir, flux;
    if (!emitters.start(kernel, rng, org, dir, flux)) return;
    for (std::uint32_t bounce = 1;; ++bounce) {
        float t, b1, b2;
        const std::uint32_t tri = kernel.lc_trace_first_hit(org, dir, cpu::ShadeKernel::kRayInfinity, t, b1, b2);
        if (tri == gpu::kInvalidIndex) return;
        const auto sp = kernel.lc_surface_point(tri, b1, b2, dir);
        const gpu::Material& m = sp.mat;
        // Only the diffuse part re-emits: a Disney material's is its base
        // colour times (1 - metallic) (docs/lightcuts.md, "Indirect light").
        const glm::vec3 kd = glm::vec3(m.kd_r, m.kd_g, m.kd_b) *
                             ((m.flags & gpu::kMaterialDisney) != 0u ? 1.0f - m.metallic : 1.0f);
        const float survive = std::min(1.0f, std::max({kd.x, kd.y, kd.z}));
        if (!(survive > 0.0f)) return;
        const glm::vec3 vpl = flux * kd * (1.0f / kPi);
        gpu::Light l{};
        l.x = sp.p.x; l.y = sp.p.y; l.z = sp.p.z;
        l.r = vpl.x; l.g = vpl.y; l.b = vpl.z;
        l.axis_x = sp.n.x; l.axis_y = sp.n.y; l.axis_z = sp.n.z;
        l.type = gpu::kLightVpl;
        out.push_back(l);
        if (max_bounces != 0 && bounce >= max_bounces) return;
        if (rng.next() >= survive) return;
        flux *= kd / survive;
        org = sp.p;
        dir = cosine_direction(kernel, sp.n, rng);
    }
}

}  // namespace

VplSet trace_vpls(const Scene& scene, const Bvh& bvh, std::span<const gpu::Light> emitters,
                  const IndirectSettings& settings, std::uint32_t seed, unsigned threads) {
    VplSet set;
    const Emitters source(emitters, scene);
    if (settings.vpls == 0 || source.empty() || scene.triangles.empty()) return set;

    cpu::ShadeKernel k;
    k.bvh_nodes = bvh.nodes.data();
    k.triangles = scene.triangles.data();
    k.normals = scene.normals.data();
    k.uvs = scene.uvs.data();
    k.materials = scene.materials.data();
    k.textures = scene.textures.data();
    k.texels = scene.texels.data();

    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t wanted = settings.vpls;
    const std::size_t max_paths = kMaxPathsPerVpl * wanted;
    // Rounds of paths, each split into one contiguous range per thread, so
    // that the VPLs come out in path order whatever the thread count.
    std::vector<std::vector<gpu::Light>> found(threads);
    std::vector<std::vector<std::uint32_t>> per_path(threads);
    std::size_t paths = 0;
    while (set.lights.size() < wanted && paths < max_paths) {
        // Enough paths for the VPLs still wanted at the rate seen so far.
        const double rate = paths > 0 ? std::max(double(set.lights.size()) / double(paths), 0.05) : 1.0;
        const std::size_t round =
            std::min(max_paths - paths,
                     std::max<std::size_t>(1024, std::size_t(double(wanted - set.lights.size()) / rate * 1.05)));
        run_on_threads(threads, [&](unsigned t) {
            found[t].clear();
            per_path[t].clear();
            const std::size_t first = paths + round * t / threads, last = paths + round * (t + 1) / threads;
            // Room for the VPLs the rate so far expects, and a tenth more.
            found[t].reserve(std::size_t(double(last - first) * rate * 1.1) + 16);
            per_path[t].reserve(last - first);
            cpu::ShadeKernel kernel = k;
            for (std::size_t p = first; p < last; ++p) {
                const std::size_t before = found[t].size();
                trace_path(kernel, source, seed, p, settings.max_bounces, found[t]);
                per_path[t].push_back(std::uint32_t(found[t].size() - before));
            }
        });
        // Whole paths, in order, until the count is reached.
        for (unsigned t = 0; t < threads && set.lights.size() < wanted; ++t) {
            std::size_t at = 0;
            for (std::uint32_t n : per_path[t]) {
                set.lights.insert(set.lights.end(), found[t].begin() + at, found[t].begin() + at + n);
                at += n;
                ++paths;
                if (set.lights.size() >= wanted) break;
            }
        }
    }
    set.paths = paths;
    const float scale = 1.0f / float(paths);
    for (gpu::Light& l : set.lights) {
        l.r *= scale;
        l.g *= scale;
        l.b *= scale;
    }
    return set;
}

}  // namespace lc
