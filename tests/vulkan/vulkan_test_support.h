// What the Vulkan tests share: the fixture (validation on, any message
// fails; no Vulkan device skips, or fails under LC_REQUIRE_VULKAN=1), the
// comparisons against the CPU reference with their measured tolerances,
// and seeded random scenes.
//
// Tolerances. The kernels are the same source on both sides
// (shaders/lc_shared/*.h), but the GPU compiler may contract a*b+c into one
// FMA and has its own sqrt/inversesqrt/acos, while the CPU build rounds
// every operation; brute force split over light ranges (docs/vulkan.md)
// also adds the ranges' sums instead of one sum. So values differ by a few
// ulps per operation, and a bound on the refinement threshold can flip a
// cluster of a cut. Each tolerance below was set at about 3x the largest
// difference measured on lavapipe (llvmpipe, LLVM 15) over every test that
// uses it; the tests print what they measure ("[ measured ]" lines).
// Re-measure before changing one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lightcuts/image.h"
#include "lightcuts/render.h"
#include "vulkan_renderer.h"

namespace lc::vulkan_test {

// Brute force, every pixel: |gpu - cpu| <= kBruteRelative * |cpu| + floor
// per channel (floor = 1e-6 of the image's mean value, the rounding of a sum
// whose terms are of that size). Measured at most 7.5e-6 (shipped room;
// random scenes 2.7e-6).
constexpr double kBruteRelative = 2e-5;
// Brute force over 70000 lights that the driver's loop limit split into
// light ranges, whose sums are added in another order. Measured 1.1e-5.
constexpr double kBruteSplitRelative = 3.5e-5;
// Lightcuts: pixels whose cut size differs from the CPU's, as a fraction of
// the image. Measured 3 of 2304 (0.13%, shipped room), none elsewhere.
// Such a pixel may differ by up to the error threshold; it is only counted.
constexpr double kCutsDifferFraction = 0.004;
// With VPLs (indirect light), cut sizes and shadow rays differ in more
// pixels: a VPL lies on the surface it was left on, so a cluster of them
// seen from a point of the same surface has a cosine bound, and its lights
// cosines, of rounding size, and each device's rounding decides whether
// the cluster contributes at all (and so is in the cut, and casts a ray).
// Measured at most 18 of 1280 pixels (1.4%, stochastic at 2 spp) and 7e-5
// of the shadow rays; about 2x and 4x that. The images still agree in every
// other pixel within kLightcutsRelative.
constexpr double kVplCutsDifferFraction = 0.03;
constexpr double kVplShadowRaysRelative = 3e-4;
// Lightcuts, every pixel whose cut is the same: as kBruteRelative.
// Measured at most 6.3e-5 (shipped room; random scenes 1.9e-5).
constexpr double kLightcutsRelative = 2e-4;
// Lightcuts, pixels where a full heap froze clusters on either device: of
// two clusters with bounds within rounding of each other, each device may
// freeze another, and the pixel then differs by the difference of their
// estimates, and of what their refinement found. Measured at most 5.4e-3
// (light-model scenes, K = 64); limit 2%, the error threshold.
constexpr double kFrozenRelative = 0.02;
// Sampled and stochastic: pixels where one device's light choice went
// another way than the other's (a random number within rounding of a branch
// probability), as a fraction of the image. Measured at most 2 of 1280
// pixels (0.16%, stochastic, all light kinds).
constexpr double kSampledDifferFraction = 0.01;
// Tree sampling: a light's probability is a product of ratios of cluster
// importances, made of square roots and (spot lights' emission bound) acos,
// asin and cos, which the device computes with its own approximations.
// Measured at most 1.3e-3 (spot lights; 6.1e-4 for the other kinds).
constexpr double kTreePdfRelative = 4e-3;
// Shadow rays counted: |gpu - cpu| <= kShadowRaysRelative * cpu + 1.
// Measured 3.4e-6 (1 of 291159, shipped room, lightcuts), equal elsewhere.
constexpr double kShadowRaysRelative = 1e-5;
// The same device with kernel features forced on that the scene does not
// need: measured identical images; a few ulps allowed.
constexpr double kFeatureSwitchRelative = 3e-7;

class Vulkan : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;

    // render_vulkan with validation on.
    static RenderResult gpu(const PreparedScene& p, const RenderOptions& o,
                            const vk::Tuning& tuning = {});

private:
    std::uint64_t messages_before_ = 0;
};

// Largest difference of `image` from `reference` over every pixel and
// channel, as |a - r| / (|r| + floor), floor as for kBruteRelative; pixels
// with skip[i] set are left out. Prints it, and writes the images and an
// error map to build/test-output/vulkan/ when it is above `tolerance`.
double max_relative_difference(const Image& image, const Image& reference,
                               const std::string& label, double tolerance,
                               const std::vector<bool>& skip = {});

// The GPU render `g` against render_cpu of the same scene and options.
void expect_brute_matches(const PreparedScene& p, const RenderOptions& o, const RenderResult& g,
                          double relative = kBruteRelative);
// Cut sizes and shadow rays with the tolerances above, or those for VPLs
// where the scene has them.
void expect_lightcuts_matches(const PreparedScene& p, const RenderOptions& o,
                              const RenderResult& g, double relative = kLightcutsRelative);

std::size_t pixels_with_different_cut(const RenderStats& a, const RenderStats& b);

// Ground plane, random boxes, random point and directional lights, Lambert
// and GGX materials; seeded.
Scene random_scene(std::uint32_t seed, std::size_t point_lights, std::size_t directional_lights,
                   std::uint32_t width, std::uint32_t height);
RenderOptions options(const std::string& method, std::uint32_t w, std::uint32_t h,
                      std::uint32_t spp = 1);

}  // namespace lc::vulkan_test
