// The stochastic methods on the CPU (shaders/lc_shared/sampling.h): the
// probabilities tree descent gives the lights, and the unbiasedness of
// --method sampled and --method stochastic against brute force.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cpu_kernel.h"
#include "test_util.h"

namespace lc {
namespace {

using Kernel = cpu::ShadeKernel;
using test::random_unit;

// Point, spot, oriented (one- and two-sided) and directional lights in and
// above the room, of random colours and powers.
std::vector<gpu::Light> mixed_lights(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<gpu::Light> lights;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 p(-0.9f + 1.8f * u(rng), 0.1f + 1.8f * u(rng), -0.9f + 1.8f * u(rng));
        const glm::vec3 c = glm::vec3(0.2f + u(rng), 0.2f + u(rng), 0.2f + u(rng)) * (0.1f + 3.0f * u(rng) * u(rng));
        switch (i % 5) {
            case 0: lights.push_back(test::point_light(p, c)); break;
            case 1: lights.push_back(test::spot_light(p, random_unit(rng), c, 10.0f + 20.0f * u(rng), 40.0f + 40.0f * u(rng))); break;
            case 2: lights.push_back(test::oriented_light(p, random_unit(rng), c)); break;
            case 3: lights.push_back(test::oriented_light(p, random_unit(rng), c, true)); break;
            default:
                if (i % 25 == 4) lights.push_back(test::directional_light(random_unit(rng), 0.05f * c));
                else lights.push_back(test::point_light(p, c));
        }
    }
    return lights;
}

// The probability tree descent gives every light at a point, enumerated:
// the root's probability times the branch probabilities on the way down.
std::vector<double> enumerate_probabilities(Kernel& k, const Kernel::SurfacePoint& sp, const gpu::FrameParams& f,
                                            const LightTree& tree) {
    std::vector<double> p(tree.lights.size(), 0.0);
    std::function<void(std::uint32_t, double)> walk = [&](std::uint32_t node, double prob) {
        const gpu::LightNode& n = tree.nodes[node];
        if (n.flags & gpu::kNodeLeaf) {
            p[n.rep_light] += prob;
            return;
        }
        const float left = k.lc_left_probability(sp, n.left, f.light_pick, f.min_distance2);
        walk(n.left, prob * left);
        walk(n.left + 1, prob * (1.0f - left));
    };
    for (std::uint32_t t = 0; t < gpu::kLightTypeCount; ++t)
        if (f.roots[t] != gpu::kInvalidIndex) walk(f.roots[t], k.lc_root_probability(sp, f, t, f.light_pick));
    return p;
}

struct PickCase {
    const char* name;
    std::uint32_t pick;
};

class TreeDescent : public ::testing::TestWithParam<PickCase> {};

// At random shaded points of random materials: the probabilities sum to 1;
// every light drawn comes with the enumerated probability of that light;
// with the tree's importance every light that reaches the point unshadowed
// can be drawn (so the estimator misses nothing); with power, each light's
// probability is its share of the total luminance.
TEST_P(TreeDescent, ProbabilitiesSumToOneAndAreTheProductOfTheBranches) {
    const std::uint32_t pick = GetParam().pick;
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(400, 7), 8), 1);
    RenderOptions o = test::options("sampled", 8);
    gpu::FrameParams f = make_frame_params(p, o);
    f.light_pick = pick;
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    const LightTree& tree = p.tree;
    double luminance_total = 0.0;
    for (const gpu::Light& l : tree.lights) luminance_total += gpu::lc_luminance({l.r, l.g, l.b});

    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int points_with_light = 0;
    for (int trial = 0; trial < 200; ++trial) {
        Kernel::SurfacePoint sp;
        sp.p = glm::vec3(-1.0f + 2.0f * u(rng), 2.0f * u(rng), -1.0f + 2.0f * u(rng));
        sp.n = random_unit(rng);
        sp.wo = random_unit(rng);
        if (glm::dot(sp.wo, sp.n) < 0.0f) sp.wo = -sp.wo;
        gpu::Material m = trial % 2 ? test::glossy({u(rng), u(rng), u(rng)}, glm::vec3(0.5f), 0.05f + u(rng))
                                    : test::lambert({u(rng), u(rng), u(rng)});
        p.scene.materials[0] = m;
        sp = k.lc_make_surface(sp.p, sp.n, sp.wo, 0, glm::vec2(0.0f), glm::vec4(0.0f));

        const std::vector<double> prob = enumerate_probabilities(k, sp, f, tree);
        double sum = 0.0;
        for (double q : prob) sum += q;
        bool any_contribution = false;
        for (std::size_t j = 0; j < tree.lights.size(); ++j) {
            glm::vec3 wi;
            float t_max;
            const glm::vec3 unit = k.lc_light_unit(sp, tree.lights[j], f.min_distance2, wi, t_max);
            if (unit.x + unit.y + unit.z > 0.0f) {
                any_contribution = true;
                if (pick == gpu::kLightPickTree) {
                    ASSERT_GT(prob[j], 0.0) << "light " << j << ", trial " << trial;
                }
            }
            if (pick == gpu::kLightPickPower) {
                // The kernel's probability is a product of float ratios of
                // the nodes' float intensity sums down the tree; the test's
                // a double ratio: 1e-4 covers the sums' and products' rounding.
                const gpu::Light& l = tree.lights[j];
                ASSERT_NEAR(prob[j], gpu::lc_luminance({l.r, l.g, l.b}) / luminance_total, 1e-4 * prob[j])
                    << "light " << j;
            }
        }
        if (pick == gpu::kLightPickTree && !any_contribution) {
            // No light can reach the point: tree descent draws none (and
            // the sum may be 0); otherwise it must be 1.
            EXPECT_TRUE(sum == 0.0 || std::abs(sum - 1.0) < 1e-5) << sum;
            continue;
        }
        ++points_with_light;
        // Probabilities are float products down the tree (a few ulps each,
        // about 20 levels), summed here in double: 1e-5 is about 80 ulps.
        ASSERT_NEAR(sum, 1.0, 1e-5) << "trial " << trial;
        for (std::uint32_t s = 0; s < 20; ++s) {
            float pdf = -1.0f;
            const std::uint32_t light = k.lc_pick_light(sp, f, k.lc_substream(trial, s), pdf);
            ASSERT_NE(light, gpu::kInvalidIndex);
            ASSERT_NEAR(pdf, prob[light], 1e-5 * prob[light]) << "light " << light << ", trial " << trial;
        }
    }
    EXPECT_GT(points_with_light, 100);
}

INSTANTIATE_TEST_SUITE_P(Sampling, TreeDescent,
                         ::testing::Values(PickCase{"Tree", gpu::kLightPickTree},
                                           PickCase{"Power", gpu::kLightPickPower}),
                         [](const auto& info) { return std::string(info.param.name); });

// The draws themselves follow the probabilities: 2^18 draws at one point
// over 24 lights, every light's count within 5 standard deviations of its
// expectation (a false failure about once in 10^5 seeds).
TEST(TreeDescent, DrawFrequenciesFollowTheProbabilities) {
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(24, 3), 8), 1);
    RenderOptions o = test::options("sampled", 8);
    const gpu::FrameParams f = make_frame_params(p, o);
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    const Kernel::SurfacePoint sp = k.lc_make_surface({0.1f, 0.02f, 0.2f}, {0.0f, 1.0f, 0.0f}, glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)), 0, glm::vec2(0.0f), glm::vec4(0.0f));
    const std::vector<double> prob = enumerate_probabilities(k, sp, f, p.tree);
    constexpr std::uint32_t kDraws = 1u << 18;
    std::vector<double> count(prob.size(), 0.0);
    for (std::uint32_t s = 0; s < kDraws; ++s) {
        float pdf;
        const std::uint32_t light = k.lc_pick_light(sp, f, k.lc_substream(12345u, s), pdf);
        ASSERT_NE(light, gpu::kInvalidIndex);
        count[light] += 1.0;
    }
    for (std::size_t j = 0; j < prob.size(); ++j) {
        const double expected = prob[j] * kDraws;
        const double sigma = std::sqrt(kDraws * prob[j] * (1.0 - prob[j]));
        EXPECT_NEAR(count[j], expected, 5.0 * sigma + 1e-9) << "light " << j;
    }
}

// Uniform picking: every light with probability 1/N.
TEST(TreeDescent, UniformPickGivesEveryLightTheSameProbability) {
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(37, 5), 8), 1);
    RenderOptions o = test::options("sampled", 8);
    o.light_pick = "uniform";
    const gpu::FrameParams f = make_frame_params(p, o);
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    const Kernel::SurfacePoint sp = k.lc_make_surface({0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0, glm::vec2(0.0f), glm::vec4(0.0f));
    std::vector<int> seen(p.tree.lights.size(), 0);
    for (std::uint32_t s = 0; s < 4000; ++s) {
        float pdf;
        const std::uint32_t light = k.lc_pick_light(sp, f, k.lc_substream(9u, s), pdf);
        ASSERT_LT(light, p.tree.lights.size());
        EXPECT_FLOAT_EQ(pdf, 1.0f / float(p.tree.lights.size()));
        seen[light] = 1;
    }
    for (std::size_t j = 0; j < seen.size(); ++j) EXPECT_EQ(seen[j], 1) << "light " << j << " never drawn";
}

// Lights whose weights differ by more than a float's precision: two point
// lights of 1e8 and 1 (whatever their places in the tree, one is the
// other's sibling) and a directional light of 1e-6 beside them. Every one
// keeps a probability, at least 2^-24 a branch, and every draw reports the
// probability it was drawn with: the enumerated product of its branches.
// (With a float probability against a 24-bit number the branch to the dim
// light rounded to 0, and a light it lit the shadow of was never drawn.)
TEST(TreeDescent, LightsFarDimmerThanTheirSiblingsKeepAProbability) {
    for (const std::uint32_t pick : {gpu::kLightPickPower, gpu::kLightPickTree}) {
        PreparedScene p = prepare_scene(test::room_scene({test::point_light({-0.5f, 1.0f, 0.0f}, glm::vec3(1e8f)),
                                                          test::point_light({0.5f, 1.0f, 0.0f}, glm::vec3(1.0f)),
                                                          test::directional_light({0.0f, -1.0f, 0.0f}, glm::vec3(1e-6f))},
                                                         8),
                                        1);
        RenderOptions o = test::options("sampled", 8);
        gpu::FrameParams f = make_frame_params(p, o);
        f.light_pick = pick;
        Kernel k = cpu::make_shade_kernel(p, nullptr);
        const Kernel::SurfacePoint sp =
            k.lc_make_surface({0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0, glm::vec2(0.0f), glm::vec4(0.0f));
        const std::vector<double> prob = enumerate_probabilities(k, sp, f, p.tree);
        ASSERT_EQ(prob.size(), 3u);
        double sum = 0.0;
        for (std::size_t j = 0; j < prob.size(); ++j) {
            EXPECT_GE(prob[j], 0x1p-24 * 0x1p-24) << "light " << j << ", pick " << pick;
            sum += prob[j];
        }
        EXPECT_NEAR(sum, 1.0, 1e-6);
        for (std::uint32_t s = 0; s < 2000; ++s) {
            float pdf = -1.0f;
            const std::uint32_t light = k.lc_pick_light(sp, f, k.lc_substream(77u, s), pdf);
            ASSERT_LT(light, prob.size());
            ASSERT_NEAR(pdf, prob[light], 1e-6 * prob[light]) << "light " << light;
        }
    }
}

// Three light types of 2e38 each: their weights' sum overflows a float, but
// each type is still drawn with its share (the sum of the types after the
// first was infinite, and the first drawn with probability 6e-8).
TEST(TreeDescent, RootsOfHugeWeightsKeepTheirShares) {
    const glm::vec3 huge(2e38f);
    std::vector<gpu::Light> lights = {test::point_light({0.0f, 1.9f, 0.0f}, huge),
                                      test::spot_light({0.1f, 1.9f, 0.0f}, {0, -1, 0}, huge, 80.0f, 89.0f),
                                      test::oriented_light({-0.1f, 1.9f, 0.0f}, {0, -1, 0}, huge)};
    PreparedScene p = prepare_scene(test::room_scene(lights, 8), 1);
    gpu::FrameParams f = make_frame_params(p, test::options("sampled", 8));
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    const Kernel::SurfacePoint sp = k.lc_make_surface({0, 0, 0}, {0, 1, 0}, {0, 1, 0}, 0, glm::vec2(0.0f), glm::vec4(0.0f));
    double sum = 0.0;
    for (const std::uint32_t type : {gpu::kLightPoint, gpu::kLightSpot, gpu::kLightOriented}) {
        const float probability = k.lc_root_probability(sp, f, type, gpu::kLightPickPower);
        std::printf("[ measured ] type %u of three of 2e38: probability %.4f\n", type, probability);
        EXPECT_GT(probability, 0.1f) << type;
        sum += probability;
    }
    EXPECT_NEAR(sum, 1.0, 1e-6);
}

// A branch's steps of 2^24: in proportion to the weights, rounded, and never
// 0 (or all) where both sides have weight.
TEST(TreeDescent, BranchStepsGiveEverySideWithWeightAShare) {
    Kernel k;
    EXPECT_EQ(k.lc_branch_steps(1.0f, 1.0f), 1u << 23);
    EXPECT_EQ(k.lc_branch_steps(1.0f, 3.0f), 1u << 22);
    EXPECT_EQ(k.lc_branch_steps(1e-9f, 1.0f), 1u);
    EXPECT_EQ(k.lc_branch_steps(1.0f, 1e-9f), (1u << 24) - 1u);
    EXPECT_EQ(k.lc_branch_steps(0.0f, 1.0f), 0u);
    EXPECT_EQ(k.lc_branch_steps(1.0f, 0.0f), 1u << 24);
    // Weights whose sum overflows a float, each in range (it was 1, the
    // least share, for two equal ones), and infinite ones.
    EXPECT_EQ(k.lc_branch_steps(3e38f, 3e38f), 1u << 23);
    EXPECT_EQ(k.lc_branch_steps(1e38f, 3e38f), 1u << 22);
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(k.lc_branch_steps(inf, 1.0f), (1u << 24) - 1u);
    EXPECT_EQ(k.lc_branch_steps(1.0f, inf), 1u);
    EXPECT_EQ(k.lc_branch_steps(inf, inf), 1u << 23);
    // Tiny weights too (their sum's division is accurate on every device).
    EXPECT_EQ(k.lc_branch_steps(1e-40f, 1e-40f), 1u << 23);
    EXPECT_EQ(k.lc_branch_steps(1e-38f, 3e-38f), 1u << 22);
    // The draw takes the side k < n: its frequency over the 2^24 values of
    // k is n / 2^24, the probability it reports.
    for (const std::uint32_t n : {1u, 12345u, (1u << 24) - 1u}) {
        float pdf_low = 1.0f, pdf_high = 1.0f;
        EXPECT_TRUE(k.lc_branch((n - 1u) << 8, n, pdf_low));
        EXPECT_FALSE(k.lc_branch(n << 8, n, pdf_high));
        EXPECT_EQ(pdf_low, float(n) * 0x1p-24f);
        EXPECT_EQ(pdf_high, float((1u << 24) - n) * 0x1p-24f);
    }
}

// Uniform picking among more lights than a 24-bit number has values: the
// index comes from all 32 bits of the hash (odd indices too, where u * n
// gave multiples of n / 2^24 only), and without the modulo's bias (for n =
// 3 * 2^30 the first third of the lights would otherwise be drawn twice as
// often as the rest: half of the draws instead of a third).
TEST(TreeDescent, UniformPickOfBillionsOfLightsIsUniform) {
    Kernel k;
    const std::uint32_t n = 3u << 30;
    constexpr int kDraws = 30000;
    int first_third = 0, odd = 0;
    for (int i = 0; i < kDraws; ++i) {
        const std::uint32_t light = k.lc_uniform_light(gpu::lc_hash(std::uint32_t(i) * 2654435761u), n);
        ASSERT_LT(light, n);
        first_third += light < (1u << 30) ? 1 : 0;
        odd += light & 1u;
    }
    const double sigma = std::sqrt(kDraws * (1.0 / 3.0) * (2.0 / 3.0));
    EXPECT_NEAR(first_third, kDraws / 3.0, 5.0 * sigma);
    EXPECT_NEAR(odd, kDraws / 2.0, 5.0 * std::sqrt(kDraws * 0.25));
}

// Luminance means over the whole image and over its four quadrants.
std::vector<double> region_means(const Image& image) {
    std::vector<double> sums(5, 0.0);
    std::vector<double> counts(5, 0.0);
    for (std::uint32_t y = 0; y < image.height; ++y)
        for (std::uint32_t x = 0; x < image.width; ++x) {
            const std::size_t i = 3 * (std::size_t(y) * image.width + x);
            const double v = gpu::lc_luminance({image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]});
            const std::size_t q = 1 + (x * 2 / image.width) + 2 * (y * 2 / image.height);
            sums[0] += v, counts[0] += 1;
            sums[q] += v, counts[q] += 1;
        }
    for (std::size_t r = 0; r < sums.size(); ++r) sums[r] /= counts[r];
    return sums;
}

struct UnbiasedCase {
    const char* name;
    const char* method;
    const char* pick;
    float relative_error;
    std::uint32_t light_samples;
    double visible_bias;  // a bias this large (relative) would fail the test
    std::uint32_t cut_heap = kDefaultCutHeap;
};

class Unbiased : public ::testing::TestWithParam<UnbiasedCase> {};

// The mean of R = 100 renders with seeds 1..R against brute force, for the
// image's mean luminance and each quadrant's: |mean - brute| must be within
// 4.5 standard errors (estimated from the renders). The renders are
// independent and each region's mean averages many pixels, so the statistic
// is close to normal: a false failure has probability about 7e-6 per
// region, 1.7e-4 for the whole suite (5 regions, 5 cases). One spp at
// the pixel centres, so every render shades the same points as brute
// force. The test also checks that it would see a small bias: that 4.5
// standard errors of the image mean are below `visible_bias` of it (1% for
// tree sampling and stochastic lightcuts, 2.5% for the baselines, whose
// variance is larger at the same 100 light samples).
TEST_P(Unbiased, MeanOfIndependentRendersMatchesBruteForce) {
    const UnbiasedCase& c = GetParam();
    constexpr std::uint32_t kSize = 12;
    constexpr int kRenders = 100;
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(300, 21), kSize), 1);
    const std::vector<double> exact = region_means(render_cpu(p, test::options("brute", kSize)).image);

    RenderOptions o = test::options(c.method, kSize);
    o.light_pick = c.pick;
    o.light_samples = c.light_samples;
    o.relative_error = c.relative_error;
    o.cut_heap = c.cut_heap;
    std::vector<double> sum(exact.size(), 0.0), sum2(exact.size(), 0.0);
    for (int r = 0; r < kRenders; ++r) {
        o.seed = std::uint32_t(r + 1);
        const std::vector<double> means = region_means(render_cpu(p, o).image);
        for (std::size_t i = 0; i < means.size(); ++i) {
            sum[i] += means[i];
            sum2[i] += means[i] * means[i];
        }
    }
    for (std::size_t i = 0; i < exact.size(); ++i) {
        const double mean = sum[i] / kRenders;
        const double variance = std::max(0.0, (sum2[i] - kRenders * mean * mean) / (kRenders - 1));
        const double standard_error = std::sqrt(variance / kRenders);
        std::printf("[ measured ] %s region %zu: mean %.6g, brute %.6g, %.2f standard errors (se/mean %.2g)\n",
                    c.name, i, mean, exact[i], std::abs(mean - exact[i]) / standard_error, standard_error / mean);
        EXPECT_GT(standard_error, 0.0) << "the renders do not differ: the seed does not reach the method";
        EXPECT_LE(std::abs(mean - exact[i]), 4.5 * standard_error) << c.name << " region " << i;
        if (i == 0) {
            EXPECT_LT(4.5 * standard_error, c.visible_bias * exact[i]) << "the test could not see the bias";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Sampling, Unbiased,
                         ::testing::Values(UnbiasedCase{"SampledTree", "sampled", "tree", 0.02f, 100, 0.01},
                                           UnbiasedCase{"SampledUniform", "sampled", "uniform", 0.02f, 100, 0.025},
                                           UnbiasedCase{"SampledPower", "sampled", "power", 0.02f, 100, 0.025},
                                           UnbiasedCase{"Stochastic", "stochastic", "tree", 0.2f, 1, 0.01},
                                           UnbiasedCase{"StochasticThreeDraws", "stochastic", "tree", 0.5f, 3, 0.01},
                                           // A heap of 2 slots, full at nearly every pixel: the
                                           // clusters that freeze are drawn afresh too (they kept
                                           // the fixed representatives' estimates, a bias that
                                           // more samples did not shrink).
                                           UnbiasedCase{"StochasticFullHeap", "stochastic", "tree", 0.02f, 16, 0.01, 2}),
                         [](const auto& info) { return std::string(info.param.name); });

// Deterministic lightcuts at the same threshold is biased, and the
// statistic above sees it: its error (the same in every render) is many
// times what stochastic lightcuts leaves over 100 renders.
TEST(Unbiased, DeterministicLightcutsIsBiasedWhereStochasticIsNot) {
    constexpr std::uint32_t kSize = 12;
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(300, 21), kSize), 1);
    const double exact = region_means(render_cpu(p, test::options("brute", kSize)).image)[0];
    RenderOptions o = test::options("lightcuts", kSize);
    o.relative_error = 0.2f;
    const double deterministic = region_means(render_cpu(p, o).image)[0];
    o.method = "stochastic";
    double stochastic = 0.0;
    for (int r = 0; r < 100; ++r) {
        o.seed = std::uint32_t(r + 1);
        stochastic += region_means(render_cpu(p, o).image)[0] / 100.0;
    }
    std::printf("[ measured ] image mean: brute %.6g, lightcuts %.6g, stochastic (100 renders) %.6g\n", exact,
                deterministic, stochastic);
    EXPECT_GT(std::abs(deterministic - exact), 3.0 * std::abs(stochastic - exact));
}

// The seed decides the light samples, so a render is the same for the same
// seed (and thread count does not matter), and differs for another seed.
// Every pixel of an image has its own random stream at each camera sample
// (lc_pixel_key): x ^ lc_hash(y ^ ...) gave whole rows another row's
// streams, e.g. row 4 at x and row 15448 at x ^ 9999 for every x of a
// 16384-wide image, so their noise was alike.
TEST(Sampling, EveryPixelHasItsOwnStream) {
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(4, 7), 8), 1);
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    for (std::uint32_t x = 0; x < 16384; ++x)
        ASSERT_NE(k.lc_sample_stream(1u, x, 4u, 0u), k.lc_sample_stream(1u, x ^ 9999u, 15448u, 0u)) << x;
    // Exhaustively over a 2048 x 2048 image, for two samples: no two pixels alike.
    for (std::uint32_t s : {0u, 5u}) {
        std::vector<std::uint32_t> streams;
        streams.reserve(std::size_t(2048) * 2048);
        for (std::uint32_t y = 0; y < 2048; ++y)
            for (std::uint32_t x = 0; x < 2048; ++x) streams.push_back(k.lc_sample_stream(3u, x, y, s));
        std::sort(streams.begin(), streams.end());
        EXPECT_EQ(std::adjacent_find(streams.begin(), streams.end()), streams.end()) << s;
    }
}

TEST(Sampling, SameSeedSameImageWhateverTheThreads) {
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(100, 2), 16), 1);
    for (const char* method : {"sampled", "stochastic"}) {
        RenderOptions o = test::options(method, 16);
        o.spp = 2;
        o.threads = 1;
        const RenderResult a = render_cpu(p, o);
        o.threads = 2;
        const RenderResult b = render_cpu(p, o);
        EXPECT_EQ(a.image.rgb, b.image.rgb) << method;
        o.seed = 2;
        EXPECT_NE(render_cpu(p, o).image.rgb, a.image.rgb) << method;
    }
}

// Stochastic lightcuts selects the same cut as lightcuts (the cut sizes are
// equal) and shades each cluster that is not a single light with one more
// shadow ray, so it needs at most twice the rays.
TEST(Sampling, StochasticSelectsTheLightcutsCut) {
    PreparedScene p = prepare_scene(test::room_scene(mixed_lights(300, 4), 16), 1);
    RenderOptions o = test::options("lightcuts", 16);
    o.cut_sharing = "pixel";  // stochastic cuts each pixel alone
    const RenderResult lightcuts = render_cpu(p, o);
    o.method = "stochastic";
    const RenderResult stochastic = render_cpu(p, o);
    EXPECT_EQ(lightcuts.stats.cut_size, stochastic.stats.cut_size);
    EXPECT_GT(stochastic.stats.shadow_rays, lightcuts.stats.shadow_rays);
    EXPECT_LE(stochastic.stats.shadow_rays, 2 * lightcuts.stats.shadow_rays);
}

}  // namespace
}  // namespace lc
