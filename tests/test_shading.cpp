// The BRDF against analytic truth. The CPU and Vulkan paths share
// shaders/lc_shared/shading.h, so comparing them cannot catch a wrong formula:
// these tests check the formula itself against closed forms written
// differently from the kernel's.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "cpu_kernel.h"
#include "test_util.h"

namespace lc {
namespace {

using Kernel = cpu::ShadeKernel;
constexpr double kPi = 3.14159265358979323846;

// At normal incidence and normal view (wi = wo = n, so h = n) the GGX lobe
// is D(1) G1(1)^2 / (4 cos_i cos_o) with D(1) = 1 / (pi alpha^2) and
// G1(1) = 1: f_spec = 1 / (4 pi alpha^2). A directional light of irradiance
// E along n then reflects E * (kd / pi + ks / (4 pi alpha^2)).
TEST(ShadingGgx, NormalIncidenceRadianceIsAnalytic) {
    for (float alpha : {1e-3f, 0.01f, 0.1f, 0.5f, 1.0f}) {
        std::vector<gpu::Material> materials = {test::glossy({0.3f, 0.5f, 0.7f}, {0.9f, 0.6f, 0.2f}, alpha)};
        Kernel k;
        k.materials = materials.data();
        Kernel::SurfacePoint sp;
        sp.p = glm::vec3(0.0f);
        sp.n = glm::vec3(0, 0, 1);
        sp.wo = glm::vec3(0, 0, 1);
        sp = k.lc_make_surface(sp.p, sp.n, sp.wo, 0, glm::vec2(0.0f), glm::vec4(0.0f));
        const glm::vec3 irradiance(2.0f, 3.0f, 5.0f);
        glm::vec3 wi;
        float t_max;
        const glm::vec3 unit = k.lc_light_unit(sp, test::directional_light({0, 0, -1}, irradiance), 1e-8f, wi, t_max);
        const glm::vec3 radiance = unit * irradiance;
        const double a2 = double(alpha) * double(alpha);
        for (int c = 0; c < 3; ++c) {
            const double kd = (&materials[0].kd_r)[c];
            const double ks = (&materials[0].ks_r)[c];
            const double expected = double(irradiance[c]) * (kd / kPi + ks / (4.0 * kPi * a2));
            // A handful of float operations on values near 1 (16 ulps).
            EXPECT_NEAR(radiance[c], expected, 2e-6 * expected) << "alpha " << alpha << " channel " << c;
        }
    }
}

// The GGX normal distribution is normalised over projected microfacet
// area: the integral of D(h) cos(theta_h) over the hemisphere is 1 for every
// roughness (Walter et al. 2007, eq. 4). Integrated numerically in
// cos(theta_h) (D depends on nothing else).
TEST(ShadingGgx, NormalDistributionIsNormalised) {
    Kernel k;
    for (float alpha : {0.05f, 0.2f, 0.5f, 1.0f}) {
        // The integrand peaks at mu = 1 with width ~alpha^2: integrate in
        // t = 1 - mu with steps that resolve it.
        const int steps = 400000;
        double integral = 0.0;
        for (int i = 0; i < steps; ++i) {
            const double t = (double(i) + 0.5) / steps;  // 1 - cos(theta_h)
            const double mu = 1.0 - t;
            integral += double(k.lc_ggx_d(float(mu), float(t * (2.0 - t)), alpha)) * mu * (2.0 * kPi / steps);
        }
        // The midpoint rule with D in double is off by 3.3e-7 at alpha =
        // 0.05 and less above (computed in Python); D in float adds its
        // rounding, about 1e-7 relative a step. 1e-5 allows both.
        EXPECT_NEAR(integral, 1.0, 1e-5) << "alpha " << alpha;
    }
}

// Smith's G1 for GGX in the tangent form of Walter et al. 2007 (eq. 34):
// G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)).
TEST(ShadingGgx, SmithMaskingMatchesTheTangentForm) {
    Kernel k;
    for (float alpha : {1e-3f, 0.1f, 0.5f, 1.0f})
        for (double theta = 0.0; theta < 0.5 * kPi - 1e-3; theta += 0.01) {
            const double tan_t = std::tan(theta);
            const double expected = 2.0 / (1.0 + std::sqrt(1.0 + double(alpha) * alpha * tan_t * tan_t));
            // G1 lies in [0, 1]; a few float operations and a sqrt: 1e-5
            // absolute is about 80 ulps at 1.
            EXPECT_NEAR(k.lc_smith_g1(float(std::cos(theta)), alpha), expected, 1e-5)
                << "alpha " << alpha << " theta " << theta;
        }
}

// f(wi, wo) cos_i / cos_i is symmetric in wi and wo (Helmholtz reciprocity)
// and never negative.
TEST(ShadingGgx, BrdfIsReciprocalAndNonNegative) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto hemisphere = [&]() {
        const float z = std::max(u(rng), 1e-3f), phi = 2.0f * float(kPi) * u(rng);
        const float r = std::sqrt(1.0f - z * z);
        return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    const glm::vec3 n(0, 0, 1);
    for (int trial = 0; trial < 20000; ++trial) {
        std::vector<gpu::Material> materials = {
            test::glossy({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, std::max(1e-2f, u(rng)))};
        Kernel k;
        k.materials = materials.data();
        const glm::vec3 a = hemisphere(), b = hemisphere();
        const glm::vec3 fab = k.lc_brdf_cos(materials[0], n, a, b, a.z) / a.z;
        const glm::vec3 fba = k.lc_brdf_cos(materials[0], n, b, a, b.z) / b.z;
        for (int c = 0; c < 3; ++c) {
            ASSERT_GE(fab[c], 0.0f);
            // Relative, at about 3x the largest difference measured over
            // these trials (3.1e-7: the two orders round differently).
            ASSERT_NEAR(fab[c], fba[c], 1e-6f * std::max(fab[c], fba[c])) << trial;
        }
    }
}

// Camera samples cover the whole pixel for every spp: over many seeds, each
// of 16 x 16 cells of the pixel is hit, and the mean position is the
// centre. (A grid of ceil(sqrt(spp)) columns that spp does not fill left
// cells unseen: spp 8 never reached the bottom-right ninth of a pixel.)
TEST(PixelSamples, EverySppCoversThePixel) {
    Kernel k;
    for (std::uint32_t spp : {2u, 3u, 5u, 7u, 8u, 12u, 16u, 17u}) {
        std::vector<int> hits(16 * 16, 0);
        double mx = 0.0, my = 0.0;
        const std::uint32_t seeds = 4000;  // at least 31 samples per cell on average
        for (std::uint32_t seed = 0; seed < seeds; ++seed)
            for (std::uint32_t s = 0; s < spp; ++s) {
                const glm::vec2 p = k.lc_pixel_sample(3, 5, s, spp, seed) - glm::vec2(3.0f, 5.0f);
                ASSERT_TRUE(p.x >= 0.0f && p.x < 1.0f && p.y >= 0.0f && p.y < 1.0f) << spp;
                hits[std::min(15, int(p.y * 16.0f)) * 16 + std::min(15, int(p.x * 16.0f))] += 1;
                mx += p.x;
                my += p.y;
            }
        const double n = double(seeds) * spp;
        EXPECT_EQ(std::count(hits.begin(), hits.end(), 0), 0) << "spp " << spp;
        // Uniform positions: standard error sqrt(1/12 / n), 0.0032 at spp 2
        // to 0.0008 at spp 17; four of them (stratified samples err less).
        const double se = std::sqrt(1.0 / 12.0 / n);
        EXPECT_NEAR(mx / n, 0.5, 4.0 * se) << "spp " << spp;
        EXPECT_NEAR(my / n, 0.5, 4.0 * se) << "spp " << spp;
    }
}

}  // namespace
}  // namespace lc
