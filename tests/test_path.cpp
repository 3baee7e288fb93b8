// The path tracer (--method path, host/path_tracer.h): its sampling
// routines on their own, then whole renders against analytic answers and
// against brute force where brute force is exact.
//
// Noise: a render's error is checked against standard errors estimated from
// the samples themselves, never against fixed tolerances tuned to one seed.
// Where the reference is exact, pixels get 6 of their standard errors and
// image means 4 (a normal beyond 4 sigma: 6e-5; beyond 6 sigma over ~1000
// pixels: 2e-6).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "path_tracer.h"
#include "scene/materials.h"
#include "test_util.h"

namespace lc {
namespace {

using path::Kernel;
constexpr double kPi = 3.14159265358979323846;

gpu::Material emitter(glm::vec3 kd, glm::vec3 emission, bool two_sided) {
    gpu::Material m = test::lambert(kd);
    m.emission_r = emission.x; m.emission_g = emission.y; m.emission_b = emission.z;
    m.flags |= gpu::kMaterialEmissive | (two_sided ? gpu::kMaterialEmitsBothSides : 0u);
    return m;
}

RenderOptions path_options(std::uint32_t size, std::uint32_t spp, std::uint32_t max_bounces) {
    RenderOptions o = test::options("path", size);
    o.spp = spp;
    o.max_bounces = max_bounces;
    return o;
}

// The mean luminance of an image and its standard error, from the spread of
// the pixels: for images whose pixels all have the same expected value.
struct Mean {
    double value = 0.0;
    double error = 0.0;
};

Mean pixel_mean(const Image& image) {
    const double n = double(image.width) * image.height;
    double sum = 0.0, sum2 = 0.0;
    for (std::uint32_t y = 0; y < image.height; ++y)
        for (std::uint32_t x = 0; x < image.width; ++x) {
            const double l = luminance(image.at(x, y));
            sum += l;
            sum2 += l * l;
        }
    const double mean = sum / n;
    const double variance = std::max(0.0, (sum2 - n * mean * mean) / (n - 1.0));
    return {mean, std::sqrt(variance / n)};
}

// `n` independent paths per pixel, all through the pixel's centre: with
// spp 1 every camera sample s is the same ray (lc_pixel_sample), and s only
// changes the random numbers. Per pixel: the mean luminance and the
// variance of that mean, estimated from the n values.
struct PixelEstimates {
    std::vector<double> mean;
    std::vector<double> variance_of_mean;
};

PixelEstimates centre_paths(const PreparedScene& p, RenderOptions o, std::uint32_t n) {
    o.spp = 1;
    const path::PathTracer tracer(p, o);
    const std::uint32_t w = tracer.frame().width, h = tracer.frame().height;
    PixelEstimates e{std::vector<double>(std::size_t(w) * h), std::vector<double>(std::size_t(w) * h)};
    auto rows = [&](std::uint32_t first) {
        path::PathRays rays;
        for (std::uint32_t y = first; y < h; y += 2)
            for (std::uint32_t x = 0; x < w; ++x) {
                double sum = 0.0, sum2 = 0.0;
                for (std::uint32_t s = 0; s < n; ++s) {
                    const double l = luminance(tracer.sample(x, y, s, rays));
                    sum += l;
                    sum2 += l * l;
                }
                const double mean = sum / n;
                e.mean[std::size_t(y) * w + x] = mean;
                e.variance_of_mean[std::size_t(y) * w + x] = std::max(0.0, (sum2 - n * mean * mean) / (n - 1.0)) / n;
            }
    };
    std::thread other(rows, 1u);
    rows(0u);
    other.join();
    return e;
}

// Path estimates against a reference image of the same camera rays: the
// image means within 4 standard errors, plus `bias` times the reference for
// references that approximate; every pixel within 6 of its own standard
// errors, plus `bias` times its reference, plus `floor` times the image's
// mean. The floor is for area lights and skies, which pixels in a penumbra
// see as a rare event: a floor point in the sphere's half-shadow reaches
// the light in 1% of its paths, so all 256 of them miss it one time in 13,
// with a spread of zero, and a few hits give a spread far below the truth.
void expect_matches(const PixelEstimates& e, const Image& reference, double bias, double floor) {
    const double n = double(reference.width) * reference.height;
    double ref_sum = 0.0;
    for (std::uint32_t y = 0; y < reference.height; ++y)
        for (std::uint32_t x = 0; x < reference.width; ++x) ref_sum += luminance(reference.at(x, y));
    const double pixel_floor = floor * ref_sum / n + 1e-7;
    double diff = 0.0, variance = 0.0;
    int outliers = 0;
    for (std::uint32_t y = 0; y < reference.height; ++y)
        for (std::uint32_t x = 0; x < reference.width; ++x) {
            const std::size_t i = std::size_t(y) * reference.width + x;
            const double ref = luminance(reference.at(x, y));
            const double d = e.mean[i] - ref;
            diff += d;
            variance += e.variance_of_mean[i];
            if (std::abs(d) > 6.0 * std::sqrt(e.variance_of_mean[i]) + bias * ref + pixel_floor && ++outliers <= 5)
                ADD_FAILURE() << "pixel " << x << "," << y << ": path " << e.mean[i] << ", reference " << ref
                              << ", standard error " << std::sqrt(e.variance_of_mean[i]);
        }
    EXPECT_LE(std::abs(diff / n), 4.0 * std::sqrt(variance) / n + bias * ref_sum / n)
        << "image mean: path " << (ref_sum + diff) / n << ", reference " << ref_sum / n;
    EXPECT_EQ(outliers, 0);
}

bool all_finite(const Image& image) {
    return std::all_of(image.rgb.begin(), image.rgb.end(), [](float v) { return std::isfinite(v); });
}

// ---- Sampling routines ----

TEST(PathEmitters, DistributionNeverPicksZeroWeights) {
    const path::Distribution1D d({0.0, 1.0, 0.0, 3.0, 0.0});
    EXPECT_DOUBLE_EQ(d.total(), 4.0);
    EXPECT_DOUBLE_EQ(d.pmf(1), 0.25);
    EXPECT_DOUBLE_EQ(d.pmf(3), 0.75);
    EXPECT_EQ(d.pmf(0) + d.pmf(2) + d.pmf(4), 0.0);
    EXPECT_EQ(d.sample(0.0), 1u);
    EXPECT_EQ(d.sample(0.2499999), 1u);
    EXPECT_EQ(d.sample(0.25), 3u);
    EXPECT_EQ(d.sample(std::nextafter(1.0, 0.0)), 3u);
}

// A kernel and frame that look up `map` (lc_environment_radiance).
struct MapLookup {
    Kernel k{};
    gpu::FrameParams f{};
    explicit MapLookup(const Environment& map) {
        k.environment = map.rgb.data();
        f.env_width = map.width;
        f.env_height = map.height;
    }
};

// A map with black texels and one bright one: every sampled direction has
// the density pdf() reports, lies in a texel that shines, and the texel's
// luminance over that density is the map's luminance integral (the sampler
// is exactly proportional to luminance x solid angle); the densities of the
// texels integrate to 1.
TEST(PathEmitters, EnvironmentSamplingFollowsLuminanceTimesSolidAngle) {
    Environment map;
    map.width = 16;
    map.height = 8;
    for (std::uint32_t i = 0; i < map.width * map.height; ++i) {
        const float v = (i % 5 == 0) ? 0.0f : 0.1f + 0.05f * float(i % 7);
        map.rgb.insert(map.rgb.end(), {v, 0.5f * v, (i % 3 == 0) ? 0.0f : v});
    }
    map.rgb[3 * 37] = 40.0f;  // a sun
    const path::EnvironmentSampler sampler(map);
    MapLookup lookup(map);
    Kernel& k = lookup.k;
    const gpu::FrameParams& f = lookup.f;

    double integral = 0.0;
    for (std::uint32_t r = 0; r < map.height; ++r) {
        const double solid_angle = 2.0 * kPi / map.width * (std::cos(kPi * r / map.height) - std::cos(kPi * (r + 1) / map.height));
        for (std::uint32_t c = 0; c < map.width; ++c) {
            const double theta = kPi * (r + 0.5) / map.height, phi = 2.0 * kPi * ((c + 0.5) / map.width - 0.5);
            const glm::vec3 centre(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                                   float(-std::sin(theta) * std::cos(phi)));
            integral += sampler.pdf(centre) * solid_angle;
            EXPECT_EQ(sampler.pdf(centre) > 0.0f, luminance(k.lc_environment_radiance(f, centre)) > 0.0f);
        }
    }
    EXPECT_NEAR(integral, 1.0, 1e-5);

    for (std::uint32_t i = 0; i < 20000; ++i) {
        const auto u = [&](std::uint32_t d) { return gpu::lc_unit_float(gpu::lc_hash(i * 4 + d)); };
        float pdf = 0.0f;
        const glm::vec3 dir = sampler.sample(u(0), u(1), u(2), u(3), pdf);
        ASSERT_NEAR(glm::length(dir), 1.0f, 1e-5f);
        ASSERT_GT(pdf, 0.0f);
        ASSERT_NEAR(sampler.pdf(dir), pdf, 1e-5f * pdf) << "sample " << i;
        ASSERT_NEAR(luminance(k.lc_environment_radiance(f, dir)) / pdf, sampler.luminance_integral(),
                    1e-4 * sampler.luminance_integral());
    }
}

// Near the poles of a tall map the direction a sample draws must still look
// up the texel it was drawn in: otherwise NEE weighs a neighbour's radiance
// by the drawn texel's density. (acos of a float cosine, spaced 6e-8 apart
// near 1, put most samples of a 2 x 8192 map's first rows in the row
// next to theirs; with a bright texel one row from the pole the path
// tracer came out 19% dark.)
TEST(PathEmitters, SamplesNearThePolesLookUpTheirOwnTexel) {
    Environment map;
    map.width = 2;
    map.height = 8192;
    map.rgb.assign(std::size_t(map.width) * map.height * 3, 0.0f);
    for (std::uint32_t r : {0u, 1u, 2u, 3u, 10u, 8190u, 8191u})
        for (std::uint32_t c = 0; c < map.width; ++c)
            for (int k = 0; k < 3; ++k) map.rgb[(std::size_t(r) * map.width + c) * 3 + k] = 1.0f + float(r % 7 + c);
    const path::EnvironmentSampler sampler(map);
    MapLookup lookup(map);
    Kernel& k = lookup.k;
    const gpu::FrameParams& f = lookup.f;
    std::uint32_t elsewhere = 0;
    const std::uint32_t samples = 20000;
    for (std::uint32_t i = 0; i < samples; ++i) {
        const auto u = [&](std::uint32_t d) { return gpu::lc_unit_float(gpu::lc_hash(i * 4 + d)); };
        float pdf = 0.0f;
        const glm::vec3 dir = sampler.sample(u(0), u(1), u(2), u(3), pdf);
        const double ratio = luminance(k.lc_environment_radiance(f, dir)) / pdf / sampler.luminance_integral();
        if (std::abs(ratio - 1.0) > 1e-4) ++elsewhere;
    }
    std::printf("[ measured ] %u of %u samples looked up another texel\n", elsewhere, samples);
    EXPECT_LE(elsewhere, samples / 1000u);
}

// E[lc_brdf_cos / pdf] over sample_bsdf's directions is the integral of
// lc_brdf_cos over the hemisphere, which a fine (theta, phi) midpoint rule
// gives independently; a wrong density anywhere would bias the mean. The
// densities integrate to at most 1 (GGX loses the reflections that go
// below the surface), exactly 1 for Lambert alone.
TEST(PathBsdf, SampledEstimateMatchesQuadrature) {
    // Disney: a rough dielectric with sheen (cosine and GGX lobes), a metal
    // (GGX), and a clearcoat whose GTR1 lobe (alpha_c = 0.07) the midpoint
    // rule still resolves.
    loader::DisneyParams sheen, metal, coat;
    sheen.base_color = {0.6f, 0.4f, 0.3f};
    sheen.roughness = 0.6f;
    sheen.sheen = 0.8f;
    metal.base_color = {0.9f, 0.7f, 0.5f};
    metal.metallic = 1.0f;
    metal.roughness = 0.3f;
    coat.base_color = glm::vec3(0.3f);
    coat.roughness = 0.5f;
    coat.clearcoat = 1.0f;
    coat.clearcoat_gloss = 0.3f;
    const gpu::Material materials[] = {test::lambert(glm::vec3(0.5f)),
                                       test::glossy({0.2f, 0.3f, 0.1f}, {0.5f, 0.4f, 0.4f}, 0.3f),
                                       test::glossy(glm::vec3(0.0f), glm::vec3(0.9f), 0.05f),
                                       loader::make_disney_material(sheen),
                                       loader::make_disney_material(metal),
                                       loader::make_disney_material(coat)};
    const glm::vec3 n(0.0f, 0.0f, 1.0f);
    Kernel k{};
    for (const gpu::Material& m : materials)
        for (float degrees : {10.0f, 60.0f, 85.0f}) {
            const float a = glm::radians(degrees);
            const glm::vec3 wo(std::sin(a), 0.0f, std::cos(a));
            const path::LobeWeights lobes = path::lobe_weights(m, n, wo);
            // Midpoint rule, 1000 x 1000 cells of 1.6e-3 rad: the narrowest
            // lobe below (alpha 0.05) is about 2 alpha = 0.1 rad wide.
            double integral = 0.0, pdf_integral = 0.0;
            test::for_hemisphere_cells(1000, [&](glm::vec3 wi, double cell) {
                integral += luminance(k.lc_brdf_cos(m, n, wi, wo, wi.z)) * cell;
                pdf_integral += path::bsdf_pdf(k, m, lobes, n, wo, wi) * cell;
            });
            EXPECT_LE(pdf_integral, 1.0 + 1e-3);
            if (lobes.specular == 0.0f) {
                EXPECT_NEAR(pdf_integral, 1.0, 1e-3);
            }
            constexpr std::uint32_t kSamples = 400000;
            double sum = 0.0, sum2 = 0.0;
            for (std::uint32_t s = 0; s < kSamples; ++s) {
                const std::uint32_t h = gpu::lc_hash(s ^ 0xabcdefu);
                const path::BsdfSample b = path::sample_bsdf(k, m, lobes, n, wo, gpu::lc_unit_float(h),
                                                             gpu::lc_unit_float(gpu::lc_hash(h)),
                                                             gpu::lc_unit_float(gpu::lc_hash(h + 1u)));
                if (b.pdf > 0.0f) {
                    // The same pdf by two float routes (the sampler's own
                    // and bsdf_pdf from the direction): 1e-4 covers their
                    // rounding at the GGX peak, where D changes fast.
                    ASSERT_NEAR(b.pdf, path::bsdf_pdf(k, m, lobes, n, wo, b.wi), 1e-4f * b.pdf);
                }
                const double v = luminance(b.weight);
                sum += v;
                sum2 += v * v;
            }
            const double mean = sum / kSamples;
            const double error = std::sqrt(std::max(0.0, sum2 / kSamples - mean * mean) / kSamples);
            // 4 standard errors of the Monte Carlo mean, plus 2e-3 for the
            // midpoint quadrature's own error, whose narrowest lobe (alpha
            // 0.05) is about 60 cells wide (that error was not measured
            // apart).
            EXPECT_NEAR(mean, integral, 4.0 * error + 2e-3 * integral)
                << "alpha " << m.alpha << ", wo at " << degrees << " degrees";
        }
}

// At the roughness floor (alpha 1e-3) the half vectors sample_bsdf draws
// follow GGX's distribution, P(theta_h < x) = x^2 / (alpha^2 + x^2) for
// small x: 5.9% within alpha / 4 of the normal, 50% within alpha. (With
// sin(theta_h) made as sqrt(1 - cos^2), cos rounding in steps of 1e-7
// left a few angles only: 15% within alpha / 4, most of them exactly on
// the normal.)
TEST(PathBsdf, SharpLobesDrawTheirHalfVectorsSmoothly) {
    const float alpha = 1e-3f;
    const gpu::Material m = test::glossy(glm::vec3(0.0f), glm::vec3(0.9f), alpha);
    const glm::vec3 n(0.0f, 0.0f, 1.0f), wo(std::sin(0.35f), 0.0f, std::cos(0.35f));
    const path::LobeWeights lobes = path::lobe_weights(m, n, wo);
    Kernel k{};
    constexpr std::uint32_t kSamples = 100000;
    std::uint32_t quarter = 0, within = 0, drawn = 0;
    for (std::uint32_t s = 0; s < kSamples; ++s) {
        const std::uint32_t h = gpu::lc_hash(s * 3u + 1u);
        const path::BsdfSample b = path::sample_bsdf(k, m, lobes, n, wo, 0.5f, gpu::lc_unit_float(h),
                                                     gpu::lc_unit_float(gpu::lc_hash(h)));
        if (!(b.pdf > 0.0f)) continue;
        ++drawn;
        const float sin2 = k.lc_half_angle(n, glm::normalize(b.wi + wo)).y;
        quarter += sin2 < 0.0625f * alpha * alpha;
        within += sin2 < alpha * alpha;
    }
    ASSERT_GT(drawn, kSamples * 99 / 100);
    std::printf("[ measured ] half vectors within alpha/4 of n: %.4f (expected 0.0588), within alpha: %.4f (0.5)\n",
                double(quarter) / drawn, double(within) / drawn);
    EXPECT_NEAR(double(quarter) / drawn, 0.0625 / 1.0625, 0.006);
    EXPECT_NEAR(double(within) / drawn, 0.5, 0.01);
}

// A grazing view of a sharp Disney surface: the mirror direction is nearly
// -wo, where normalize(wi + wo) can face away from wo in float. The BRDF
// and the sampling density agree that no microfacet reflects there, so no
// sample weighs more than the lobes' peak allows (before, weights up to
// 1e12 and a mean of 1e8 for a white dielectric whose albedo is about 1.4).
TEST(PathBsdf, GrazingViewsOfSharpLobesKeepTheirWeights) {
    loader::DisneyParams plastic;
    plastic.base_color = glm::vec3(1.0f);
    plastic.roughness = 0.0f;
    plastic.clearcoat = 1.0f;
    plastic.clearcoat_gloss = 1.0f;
    const gpu::Material materials[] = {loader::make_disney_material(plastic),
                                       test::glossy(glm::vec3(0.5f), glm::vec3(0.04f), 1e-3f)};
    Kernel k{};
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
    glm::vec3 t, b;
    k.lc_basis(n, t, b);
    for (const gpu::Material& m : materials)
        for (const float cos_o : {1e-4f, 1e-5f, 1e-6f}) {
            const float sin_o = std::sqrt(1.0f - cos_o * cos_o);
            const glm::vec3 wo = glm::normalize(0.6f * sin_o * t + 0.8f * sin_o * b + cos_o * n);
            const path::LobeWeights lobes = path::lobe_weights(m, n, wo);
            double sum = 0.0, largest = 0.0;
            constexpr std::uint32_t kSamples = 200000;
            for (std::uint32_t s = 0; s < kSamples; ++s) {
                const std::uint32_t h = gpu::lc_hash(s ^ 0x5eedu);
                const path::BsdfSample bs = path::sample_bsdf(k, m, lobes, n, wo, gpu::lc_unit_float(h),
                                                              gpu::lc_unit_float(gpu::lc_hash(h)),
                                                              gpu::lc_unit_float(gpu::lc_hash(h + 1u)));
                const double w = luminance(bs.weight);
                sum += w;
                largest = std::max(largest, w);
            }
            std::printf("[ measured ] alpha %g, cos_o %g: mean weight %.4f, largest %.1f\n", double(m.alpha),
                        double(cos_o), sum / kSamples, largest);
            EXPECT_LT(sum / kSamples, 2.0) << "cos_o " << cos_o;
            EXPECT_LT(largest, 1e4) << "cos_o " << cos_o;
        }
}

// ---- Whole renders ----

// The furnace: inside a closed box of Lambert albedo rho that emits Le on
// both sides everywhere, the radiance is Le / (1 - rho) at every point, and
// Le (1 - rho^(B+1)) / (1 - rho) with at most B reflections. The standard
// error comes from the spread of the 256 pixels, which all estimate the
// same value (about 0.005 at B = 0, less with fewer bounces).
TEST(PathRender, FurnaceGivesGeometricSeries) {
    constexpr float kRho = 0.5f, kLe = 1.0f;
    Scene s;
    s.materials = {emitter(glm::vec3(kRho), glm::vec3(kLe), true)};
    test::add_box(s, glm::vec3(-1.0f), glm::vec3(1.0f), 0);
    s.camera = test::camera({0.2f, 0.1f, 0.3f}, {1.0f, 0.3f, -0.6f}, 90.0f, 16, 16);
    s.render.area_light_samples = 1;  // the tree's samples are not used
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    double previous = kLe;
    for (std::uint32_t bounces : {1u, 2u, 3u, 0u}) {
        const RenderResult r = render_path(p, path_options(16, 64, bounces));
        const double exact = bounces == 0 ? kLe / (1.0 - kRho)
                                          : kLe * (1.0 - std::pow(kRho, bounces + 1.0)) / (1.0 - kRho);
        const Mean m = pixel_mean(r.image);
        std::printf("[ measured ] path furnace, max_bounces %u: mean %.5f (standard error %.5f), closed form %.5f\n",
                    bounces, m.value, m.error, exact);
        EXPECT_NEAR(m.value, exact, 4.0 * m.error) << "max_bounces " << bounces << ", standard error " << m.error;
        EXPECT_GT(m.value, previous) << "max_bounces " << bounces;
        EXPECT_LT(m.value, kLe / (1.0 - kRho) + 4.0 * m.error);
        EXPECT_LT(m.error, 0.02);  // the check above means something
        previous = m.value;
        EXPECT_EQ(r.stats.spp_done, 64u);
        EXPECT_EQ(r.stats.device, "cpu");
        EXPECT_EQ(r.stats.camera_rays, 16u * 16u * 64u);
        EXPECT_GT(r.stats.shadow_rays, 0u);
        // Inside the box every path bounces, each bounce's ray counted.
        if (bounces != 0u) EXPECT_EQ(r.stats.bounce_rays, r.stats.camera_rays * bounces);
        else EXPECT_GT(r.stats.bounce_rays, r.stats.camera_rays);
    }
}

// An open scene lit by a point, a spot and a directional light, with a
// glossy sphere: brute force is exact there, and one bounce of the path
// tracer estimates the same sum with one light per sample. The lights'
// powers are of one order, so that none is picked so rarely that 256 paths
// miss it; and whether a delta light reaches a camera ray's point is fixed,
// so no pixel needs a floor.
TEST(PathRender, DirectLightMatchesBruteForce) {
    Scene s;
    s.materials = {test::lambert(glm::vec3(0.6f)), test::lambert({0.7f, 0.3f, 0.2f}),
                   test::glossy({0.2f, 0.3f, 0.6f}, glm::vec3(0.5f), 0.2f)};
    test::add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    test::add_box(s, {-0.8f, 0.0f, -0.6f}, {-0.2f, 0.7f, 0.0f}, 1);
    test::add_sphere(s, {0.5f, 0.4f, 0.3f}, 0.4f, 12, 24, 2);
    s.lights = {test::point_light({0.6f, 1.8f, -0.4f}, glm::vec3(2.0f)),
                test::spot_light({-1.0f, 2.2f, 0.5f}, {0.4f, -1.0f, -0.2f}, {25.0f, 22.0f, 18.0f}, 20.0f, 35.0f),
                test::directional_light({-0.3f, -1.0f, -0.5f}, glm::vec3(1.0f))};
    s.camera = test::camera({0.0f, 2.6f, 3.2f}, {0.0f, 0.2f, 0.0f}, 50.0f, 32, 32);
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    const Image brute = render_cpu(p, test::options("brute", 32)).image;
    expect_matches(centre_paths(p, path_options(32, 1, 1), 256), brute, 0.0, 0.0);
}

// MIS with an area light: an emissive quad under the ceiling of a closed
// room with a glossy sphere, one bounce, against brute force over 65536
// point samples of the quad (Walter 2005 §5). Those are stratified over the
// quad, 0.002 apart, and every point the camera sees is at least 0.1 from
// it, so they sum the area integral to far better than the 0.5% allowed
// (measured: image means 0.2% apart, at one standard error).
TEST(PathRender, AreaLightMatchesBruteForceOverManySamples) {
    Scene s = test::room_scene({}, 24);
    const auto light = std::uint32_t(s.materials.size());
    s.materials.push_back(emitter(glm::vec3(0.5f), {6.0f, 5.0f, 4.0f}, false));
    test::add_quad(s, {-0.3f, 1.9f, -0.3f}, {0.3f, 1.9f, -0.3f}, {0.3f, 1.9f, 0.3f}, {-0.3f, 1.9f, 0.3f}, light);
    s.render.area_light_samples = 65536;
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    const Image brute = render_cpu(p, test::options("brute", 24)).image;
    expect_matches(centre_paths(p, path_options(24, 1, 1), 256), brute, 0.005, 0.05);
}

// An upward Lambert plane under an environment map, nothing else: the
// plane's radiance is rho / pi times the irradiance, which for a lat-long
// map with the horizon on a row edge is exact: a texel of row r adds
// L (pi / W)(sin^2 theta_{r+1} - sin^2 theta_r). The camera sees only the
// plane. Light comes through NEE towards the map and through BRDF rays
// that escape, weighted by MIS. A constant sky gives rho L.
void expect_plane_under_sky(const Environment& map, glm::vec3 expected_for_unit_albedo) {
    constexpr std::uint32_t kSize = 16;
    const glm::vec3 rho(0.5f, 0.6f, 0.7f);
    Scene s;
    s.materials = {test::lambert(rho)};
    test::add_quad(s, {-100, 0, -100}, {-100, 0, 100}, {100, 0, 100}, {100, 0, -100}, 0);
    s.environment = map;
    s.camera = test::camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 40.0f, kSize, kSize);
    s.render.area_light_samples = 1;
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    const RenderResult r = render_path(p, path_options(kSize, 16, 0));
    const Mean m = pixel_mean(r.image);
    const double expected = luminance(rho * expected_for_unit_albedo);
    EXPECT_NEAR(m.value, expected, 4.0 * m.error) << "standard error " << m.error;
    EXPECT_LT(m.error, 0.02 * expected);
}

TEST(PathRender, ConstantSkyOverPlaneGivesAlbedoTimesRadiance) {
    Environment sky;
    sky.width = sky.height = 1;
    sky.rgb = {0.8f, 1.0f, 1.2f};
    expect_plane_under_sky(sky, {0.8f, 1.0f, 1.2f});
}

TEST(PathRender, EnvironmentMapOverPlaneGivesItsIrradiance) {
    Environment map;
    map.width = 8;
    map.height = 6;  // the horizon between rows 2 and 3
    glm::dvec3 irradiance(0.0);
    for (std::uint32_t r = 0; r < map.height; ++r)
        for (std::uint32_t c = 0; c < map.width; ++c) {
            glm::vec3 l = (r + c) % 3 == 0 ? glm::vec3(0.0f) : glm::vec3(0.2f * float(c), 0.5f, 0.1f * float(r));
            if (r == 1 && c == 5) l = glm::vec3(30.0f, 25.0f, 20.0f);  // a sun
            map.rgb.insert(map.rgb.end(), {l.x, l.y, l.z});
            if (r < map.height / 2) {
                const double s0 = std::sin(kPi * r / map.height), s1 = std::sin(kPi * (r + 1) / map.height);
                irradiance += glm::dvec3(l) * (kPi / map.width * (s1 * s1 - s0 * s0));
            }
        }
    expect_plane_under_sky(map, glm::vec3(irradiance / kPi));
}

// The error against a long render falls as 1 / sqrt(spp). With spp N and
// 16 N the RMSE ratio is sqrt((1/N + 1/R) / (1/(16 N) + 1/R)) against a
// reference of R spp: 3.79 for N = 16, R = 2048 (the reference's own noise
// pulls it below 4). The light is kept half a unit from every surface, so
// that no path picks up a 1/d^2 spike near it: then over 24 x 24 pixels
// the ratio varies by about 0.15 between seeds (3.58 to 4.02 over eight
// triples of seeds), and [3, 5.3] fails only for a real change of rate: a
// bias pulls the ratio towards 1, correlated samples away from 4. Square
// spp throughout, so that lc_pixel_sample's strata tile the pixel.
TEST(PathRender, ErrorFallsAsInverseSquareRootOfSamples) {
    constexpr std::uint32_t kSize = 24;
    const PreparedScene p =
        prepare_scene(test::room_scene({test::point_light({-0.5f, 1.5f, 0.5f}, glm::vec3(3.0f))}, kSize), 1);
    auto render = [&](std::uint32_t spp, std::uint32_t seed) {
        RenderOptions o = path_options(kSize, spp, 0);
        o.seed = seed;
        return render_path(p, o).image;
    };
    const Image reference = render(2048, 1000);
    auto rmse = [&](const Image& image) {
        double sum = 0.0;
        for (std::size_t i = 0; i < image.rgb.size(); ++i) sum += std::pow(double(image.rgb[i]) - reference.rgb[i], 2);
        return std::sqrt(sum / double(image.rgb.size()));
    };
    const double coarse = rmse(render(16, 1)), fine = rmse(render(256, 2));
    EXPECT_GE(coarse / fine, 3.0) << "RMSE " << coarse << " at 16 spp, " << fine << " at 256 spp";
    EXPECT_LE(coarse / fine, 5.3) << "RMSE " << coarse << " at 16 spp, " << fine << " at 256 spp";
}

// A scene with every kind of emitter the path tracer samples: a point
// light, an emissive quad, and a sky outside the closed room.
// Black surfaces under an emitter and a sky: no light, and no shadow ray
// either, as the BRDF is black before any ray is traced (before, each
// light sample traced one for nothing).
TEST(PathRender, BlackSurfacesTraceNoShadowRays) {
    Scene s;
    s.materials = {test::lambert(glm::vec3(0.0f)), emitter(glm::vec3(0.0f), glm::vec3(4.0f), true)};
    test::add_quad(s, {-100, 0, -100}, {-100, 0, 100}, {100, 0, 100}, {100, 0, -100}, 0);
    test::add_quad(s, {-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}, 1);
    s.environment.width = s.environment.height = 1;
    s.environment.rgb = {0.5f, 0.6f, 0.7f};
    s.camera = test::camera({0.0f, 1.0f, 2.0f}, {0.0f, 0.0f, -1.0f}, 40.0f, 8, 8);
    s.render.area_light_samples = 1;
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    const RenderResult r = render_path(p, path_options(8, 4, 0));
    EXPECT_GT(r.stats.camera_rays, 0u);
    EXPECT_EQ(r.stats.shadow_rays, 0u);
}

PreparedScene all_emitters_scene(std::uint32_t size) {
    Scene s = test::room_scene({test::point_light({0.0f, 1.8f, 0.0f}, glm::vec3(1.0f))}, size);
    const auto light = std::uint32_t(s.materials.size());
    s.materials.push_back(emitter(glm::vec3(0.5f), glm::vec3(4.0f), true));
    test::add_quad(s, {-0.3f, 1.9f, -0.3f}, {0.3f, 1.9f, -0.3f}, {0.3f, 1.9f, 0.3f}, {-0.3f, 1.9f, 0.3f}, light);
    s.environment.width = s.environment.height = 1;
    s.environment.rgb = {0.5f, 0.6f, 0.7f};
    s.render.area_light_samples = 1;
    update_bounds(s);
    return prepare_scene(std::move(s), 1);
}

TEST(PathRender, SameSeedGivesSameImageWhateverTheThreads) {
    const PreparedScene p = all_emitters_scene(20);
    RenderOptions o = path_options(20, 6, 0);
    o.threads = 1;
    const Image one = render_path(p, o).image;
    o.threads = 2;
    const Image two = render_path(p, o).image;
    ASSERT_EQ(one.rgb.size(), two.rgb.size());
    EXPECT_EQ(std::memcmp(one.rgb.data(), two.rgb.data(), one.rgb.size() * sizeof(float)), 0);
    EXPECT_TRUE(all_finite(one));
    o.seed = 2;
    const Image other = render_path(p, o).image;
    EXPECT_NE(std::memcmp(one.rgb.data(), other.rgb.data(), one.rgb.size() * sizeof(float)), 0);
}

// A limit shorter than any pass stops after the first (one sample per
// pixel); a limit never reached changes nothing.
TEST(PathRender, TimeLimitStopsAfterAPass) {
    const PreparedScene p = all_emitters_scene(16);
    RenderOptions o = path_options(16, 64, 0);
    o.time_limit = 1e-9;
    const RenderResult limited = render_path(p, o);
    EXPECT_EQ(limited.stats.spp_done, 1u);
    EXPECT_EQ(limited.stats.camera_rays, 16u * 16u);
    EXPECT_TRUE(all_finite(limited.image));
    EXPECT_GT(pixel_mean(limited.image).value, 0.0);

    o.spp = 4;
    o.time_limit = 1e9;
    const RenderResult unlimited_pass = render_path(p, o);
    o.time_limit = 0.0;
    const RenderResult no_limit = render_path(p, o);
    EXPECT_EQ(unlimited_pass.stats.spp_done, 4u);
    EXPECT_EQ(unlimited_pass.image.rgb, no_limit.image.rgb);

    o.time_limit = -1.0;
    EXPECT_THROW(render_path(p, o), std::invalid_argument);
}

// The passes' sizes: doubling without a limit; under one, what the time
// left holds at the last pass's rate, and none once one sample a pixel
// does not fit (the doubling passes alone overran a limit by up to the
// time taken before it: 1.48 s at a limit of 0.70).
TEST(PathRender, PassesFitTheTimeLeft) {
    using path::next_pass_samples;
    EXPECT_EQ(next_pass_samples(0, 64, 0.0, 0.0, 0.0), 1u);
    EXPECT_EQ(next_pass_samples(1, 64, 0.0, 5.0, 1.0), 1u);
    EXPECT_EQ(next_pass_samples(16, 64, 0.0, 5.0, 1.0), 16u);
    EXPECT_EQ(next_pass_samples(40, 64, 0.0, 5.0, 1.0), 24u);
    EXPECT_EQ(next_pass_samples(64, 64, 0.0, 5.0, 1.0), 0u);
    // The first sample a pixel is taken whatever the limit.
    EXPECT_EQ(next_pass_samples(0, 64, 1e-9, 1.0, 0.0), 1u);
    // 16 done at 0.1 s a sample, 1 s of a 2 s limit left: 10 more, not 16.
    EXPECT_EQ(next_pass_samples(16, 64, 2.0, 1.0, 0.1), 10u);
    EXPECT_EQ(next_pass_samples(16, 64, 2.0, 1.0, 0.01), 16u);
    // Less than a sample's time left, none left, or past the limit: stop.
    EXPECT_EQ(next_pass_samples(16, 64, 2.0, 1.95, 0.1), 0u);
    EXPECT_EQ(next_pass_samples(16, 64, 2.0, 2.0, 0.0), 0u);
    EXPECT_EQ(next_pass_samples(16, 64, 2.0, 3.0, 0.1), 0u);
    // A pass too quick for the clock: the doubling pass.
    EXPECT_EQ(next_pass_samples(16, 64, 2.0, 1.0, 0.0), 16u);
}

}  // namespace
}  // namespace lc
