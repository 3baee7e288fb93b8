#include "vulkan_test_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "cpu_kernel.h"
#include "test_util.h"
#include "vulkan/require_vulkan.h"

namespace lc::vulkan_test {

namespace {

bool vulkan_present() {
    static const bool present = !list_vulkan_devices().empty();
    return present;
}

std::string test_name() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    return name;
}

// Writes image, reference and per-pixel error map for a failed comparison.
void write_failure_images(const std::string& label, const Image& image, const Image& reference,
                          const std::vector<float>& error) {
    const std::filesystem::path dir = std::filesystem::path(LC_BINARY_DIR) / "test-output" / "vulkan";
    std::filesystem::create_directories(dir);
    const std::string stem = (dir / (test_name() + "_" + label)).string();
    write_exr(stem + "_gpu.exr", image);
    write_exr(stem + "_cpu.exr", reference);
    write_heatmap_png(stem + "_error.png", image.width, image.height, error, 1e-2f);
    std::printf("comparison images written to %s_{gpu,cpu}.exr and %s_error.png\n", stem.c_str(),
                stem.c_str());
}

// `allowed`: rays the two may differ by besides, e.g. where cuts differ.
void expect_shadow_rays_match(const RenderStats& g, const RenderStats& c, const char* method,
                              double relative = kShadowRaysRelative, double allowed = 0.0) {
    const double gpu = double(g.shadow_rays), cpu = double(c.shadow_rays);
    std::printf("[ measured ] %s shadow rays: gpu %.0f, cpu %.0f, relative difference %.3g\n",
                method, gpu, cpu, std::abs(gpu - cpu) / std::max(cpu, 1.0));
    // A grazing shadow ray may be skipped on one side only (zero contribution).
    EXPECT_NEAR(gpu, cpu, relative * cpu + 1.0 + allowed) << method;
}

}  // namespace

void Vulkan::SetUp() {
    if (!vulkan_present()) {
        if (test::vulkan_required()) GTEST_FAIL() << test::kNoVulkanButRequired;
        GTEST_SKIP() << "no Vulkan device (the loader lists none); the GPU tests need one, "
                        "lavapipe (mesa-vulkan-drivers) is enough; LC_REQUIRE_VULKAN=1 fails instead";
    }
    messages_before_ = vk::validation_message_total();
}

void Vulkan::TearDown() {
    if (IsSkipped() || !vulkan_present()) return;
    EXPECT_EQ(vk::validation_message_total(), messages_before_)
        << "the validation layer reported messages";
}

RenderResult Vulkan::gpu(const PreparedScene& p, const RenderOptions& o, const vk::Tuning& tuning) {
    VulkanOptions v;
    v.validation = true;
    return vk::render_vulkan(p, o, v, tuning);
}

double max_relative_difference(const Image& image, const Image& reference,
                               const std::string& label, double tolerance,
                               const std::vector<bool>& skip) {
    double mean = 0.0;
    for (float v : reference.rgb) mean += std::abs(v);
    mean /= double(std::max<std::size_t>(reference.rgb.size(), 1));
    const double floor = 1e-6 * mean;
    std::vector<float> error(std::size_t(image.width) * image.height, 0.0f);
    double largest = 0.0;
    for (std::size_t i = 0; i < error.size(); ++i) {
        if (!skip.empty() && skip[i]) continue;
        for (int c = 0; c < 3; ++c) {
            const double a = image.rgb[3 * i + c], r = reference.rgb[3 * i + c];
            error[i] = std::max(error[i], float(std::abs(a - r) / (std::abs(r) + floor + 1e-30)));
        }
        largest = std::max(largest, double(error[i]));
    }
    std::printf("[ measured ] %s: largest relative difference %.3g (tolerance %.3g)\n",
                label.c_str(), largest, tolerance);
    if (!(largest <= tolerance)) write_failure_images(label, image, reference, error);
    return largest;
}

void expect_brute_matches(const PreparedScene& p, const RenderOptions& o, const RenderResult& g,
                          double relative) {
    const RenderResult c = render_cpu(p, o);
    ASSERT_EQ(g.image.width, c.image.width);
    ASSERT_EQ(g.image.height, c.image.height);
    EXPECT_LE(max_relative_difference(g.image, c.image, "brute", relative), relative);
    EXPECT_EQ(g.stats.camera_rays, c.stats.camera_rays);
    expect_shadow_rays_match(g.stats, c.stats, "brute");
}

// A pixel whose cut differs by a cluster differs by up to the error
// threshold; the others only by rounding. Pixels where a full heap froze
// clusters (on either device) are compared at kFrozenRelative.
void expect_lightcuts_matches(const PreparedScene& p, const RenderOptions& o,
                              const RenderResult& g, double relative) {
    const RenderResult c = render_cpu(p, o);
    ASSERT_EQ(g.image.width, c.image.width);
    ASSERT_EQ(g.image.height, c.image.height);
    ASSERT_EQ(g.stats.cut_size.size(), c.stats.cut_size.size());
    ASSERT_EQ(g.stats.heap_froze.size(), c.stats.heap_froze.size());
    std::vector<bool> cut_differs(c.stats.cut_size.size()), froze(cut_differs.size()), skip_tight(cut_differs.size());
    std::size_t differing = 0;  // pixels that froze nothing and whose cut differs
    // Pixels whose cut is the same size but where one device froze clusters
    // and the other did not: both run the same rule on the same bounds, so
    // these are as rare as differing cuts. Without this count a device that
    // flagged frozen pixels wrongly would loosen its own comparison.
    std::size_t froze_differs = 0;
    for (std::size_t i = 0; i < cut_differs.size(); ++i) {
        froze[i] = g.stats.heap_froze[i] > 0.0f || c.stats.heap_froze[i] > 0.0f;
        cut_differs[i] = g.stats.cut_size[i] != c.stats.cut_size[i];
        skip_tight[i] = cut_differs[i] || froze[i];
        differing += cut_differs[i] && !froze[i] ? 1 : 0;
        froze_differs += !cut_differs[i] && (g.stats.heap_froze[i] > 0.0f) != (c.stats.heap_froze[i] > 0.0f) ? 1 : 0;
    }
    const double cuts_differ = p.vpls ? kVplCutsDifferFraction : kCutsDifferFraction;
    std::printf("[ measured ] lightcuts: cut size differs at %zu of %zu pixels that froze nothing (tolerance "
                "%.3g); %zu pixels froze clusters, %zu of them on one device only with the same cut size\n",
                differing, cut_differs.size(), cuts_differ * double(cut_differs.size()),
                std::size_t(std::count(froze.begin(), froze.end(), true)), froze_differs);
    EXPECT_LE(double(differing), cuts_differ * double(cut_differs.size()));
    EXPECT_LE(double(froze_differs), cuts_differ * double(cut_differs.size()));
    EXPECT_LE(max_relative_difference(g.image, c.image, "lightcuts", relative, skip_tight), relative);
    std::vector<bool> not_frozen(froze.size());
    for (std::size_t i = 0; i < froze.size(); ++i) not_frozen[i] = !froze[i];
    if (std::count(froze.begin(), froze.end(), true) > 0) {
        EXPECT_LE(max_relative_difference(g.image, c.image, "lightcuts, frozen", kFrozenRelative, not_frozen),
                  kFrozenRelative);
    }
    // A refinement casts at most one ray (one child inherits the parent's
    // representative), so a pixel whose cut differs by d clusters may cast
    // up to d rays more or fewer.
    double cut_steps_apart = 0.0;
    for (std::size_t i = 0; i < cut_differs.size(); ++i)
        cut_steps_apart += std::abs(double(g.stats.cut_size[i]) - double(c.stats.cut_size[i])) * double(o.spp);
    expect_shadow_rays_match(g.stats, c.stats, "lightcuts", p.vpls ? kVplShadowRaysRelative : kShadowRaysRelative,
                             cut_steps_apart);
    // Whether refinement stopped at max_cut can only differ where the cut does.
    EXPECT_NEAR(double(g.stats.max_cut_pixels), double(c.stats.max_cut_pixels),
                double(pixels_with_different_cut(g.stats, c.stats)) * o.spp + 1.0);
}

std::size_t pixels_with_different_cut(const RenderStats& a, const RenderStats& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < std::min(a.cut_size.size(), b.cut_size.size()); ++i)
        n += a.cut_size[i] != b.cut_size[i] ? 1 : 0;
    return n;
}

Scene random_scene(std::uint32_t seed, std::size_t point_lights, std::size_t directional_lights,
                   std::uint32_t width, std::uint32_t height) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Scene s;
    s.materials = {test::lambert({0.6f, 0.6f, 0.6f})};
    for (int m = 0; m < 4; ++m) {
        glm::vec3 kd(0.1f + 0.8f * u(rng), 0.1f + 0.8f * u(rng), 0.1f + 0.8f * u(rng));
        if (m % 2 == 0)
            s.materials.push_back(test::lambert(kd));
        else
            s.materials.push_back(test::glossy(kd * 0.5f, glm::vec3(0.3f + 0.5f * u(rng)),
                                               0.1f + 0.5f * u(rng)));
    }
    test::add_quad(s, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, 0);
    const int boxes = 3 + int(seed % 5);
    for (int b = 0; b < boxes; ++b) {
        glm::vec3 lo(-2.0f + 3.5f * u(rng), 0.0f, -2.0f + 3.5f * u(rng));
        glm::vec3 size(0.2f + 0.6f * u(rng), 0.2f + 1.0f * u(rng), 0.2f + 0.6f * u(rng));
        if (u(rng) < 0.3f) lo.y = 0.3f + u(rng);  // some float above the ground
        test::add_box(s, lo, lo + size, 1 + std::uint32_t(b) % 4);
    }
    s.lights = test::random_point_lights(point_lights, {-3, 0.5f, -3}, {3, 3, 3}, 20.0f, seed + 7);
    for (std::size_t d = 0; d < directional_lights; ++d) {
        glm::vec3 travel(u(rng) - 0.5f, -0.5f - u(rng), u(rng) - 0.5f);
        s.lights.push_back(test::directional_light(travel, glm::vec3(0.2f + 0.3f * u(rng))));
    }
    s.camera = test::camera({0.5f, 3.0f, 5.0f}, {0.0f, 0.3f, 0.0f}, 55.0f, width, height);
    update_bounds(s);
    return s;
}

RenderOptions options(const std::string& method, std::uint32_t w, std::uint32_t h,
                      std::uint32_t spp) {
    RenderOptions o;
    o.method = method;
    o.width = w;
    o.height = h;
    o.spp = spp;
    // The CPU reference cuts each pixel alone, as the Vulkan kernels do.
    o.cut_sharing = "pixel";
    return o;
}

}  // namespace lc::vulkan_test
