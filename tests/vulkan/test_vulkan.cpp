// The Vulkan compute path against analytic truth and against the CPU
// reference (render_cpu), with the validation layer on: any validation
// message makes render_vulkan throw, so every test below also checks that.
//
// Tolerances. The kernels are the same source on both sides
// (shaders/shared/*.h), but the GPU compiler may contract a*b+c into one
// FMA and has its own sqrt/inversesqrt/acos, while the CPU build rounds
// every operation; brute force split over light ranges (see
// docs/vulkan.md) also adds the ranges' sums instead of one sum. Values
// therefore differ by a few ulps per operation, and a shadow ray that
// grazes an edge, or a bound that sits exactly on the refinement
// threshold, can go either way:
//  - brute force: |gpu - cpu| <= 1e-4 * |cpu| + floor per channel on at
//    least 99.9% of pixels (floor = 1e-6 * the image's mean value: the
//    absolute rounding of a sum whose terms are of that size);
//  - lightcuts: the cut size is identical on at least 99% of pixels, and the
//    radiance is within 1e-3 relative (same floor) on at least 99.5%; a pixel
//    whose cut differs by one cluster differs by up to the error threshold.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <volk.h>

#include "lightcuts/image.h"
#include "lightcuts/render.h"
#include "cpu_kernel.h"
#include "test_util.h"
#include "vulkan_renderer.h"

namespace lc {
namespace {

using test::add_box;
using test::add_quad;

constexpr float kPi = 3.14159265358979f;


// Samples whose Lightcuts heap needs more than `shared_slots` slots.
std::uint64_t count_spilling_samples(const PreparedScene& p, const RenderOptions& o,
                                     std::uint32_t shared_slots) {
    const gpu::FrameParams f = make_frame_params(p, o);
    std::vector<gpu::CutEntry> heap(p.tree.cut_heap_capacity(f.max_cut));
    lc::cpu::ShadeKernel k = lc::cpu::make_shade_kernel(p, heap.data());
    std::uint64_t spilled = 0;
    for (std::uint32_t y = 0; y < f.height; ++y)
        for (std::uint32_t x = 0; x < f.width; ++x)
            for (std::uint32_t s = 0; s < f.spp; ++s) {
                lc::cpu::ShadeKernel::SurfacePoint sp;
                if (!k.lc_camera_hit(f, x, y, s, sp)) continue;
                lc::cpu::ShadeKernel::ShadeStats stats{0u, 0u, 0u};
                k.heap_high_water = 0;
                k.lc_shade_lightcuts(sp, f, stats);
                spilled += k.heap_high_water > shared_slots ? 1 : 0;
            }
    return spilled;
}


// --- Rendering and comparison helpers.

bool vulkan_present() {
    static const bool present = !list_vulkan_devices().empty();
    return present;
}

class Vulkan : public ::testing::Test {
protected:
    void SetUp() override {
        if (!vulkan_present())
            GTEST_SKIP() << "no Vulkan device (the loader lists none); the GPU tests need one, "
                            "lavapipe (mesa-vulkan-drivers) is enough";
        messages_before_ = vk::validation_message_total();
    }
    void TearDown() override {
        if (IsSkipped()) return;
        EXPECT_EQ(vk::validation_message_total(), messages_before_)
            << "the validation layer reported messages";
    }

    static RenderResult gpu(const PreparedScene& p, const RenderOptions& o,
                            const vk::Tuning& tuning = {}) {
        VulkanOptions v;
        v.validation = true;
        return vk::render_vulkan(p, o, v, tuning);
    }

private:
    std::uint64_t messages_before_ = 0;
};

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

// Fraction of pixels whose every channel is within rel * |ref| + floor.
double fraction_within(const Image& image, const Image& reference, double rel,
                       const std::string& label, double required) {
    double mean = 0.0;
    for (float v : reference.rgb) mean += std::abs(v);
    mean /= double(std::max<std::size_t>(reference.rgb.size(), 1));
    const double floor = 1e-6 * mean;
    std::size_t good = 0;
    std::vector<float> error(std::size_t(image.width) * image.height, 0.0f);
    for (std::size_t i = 0; i < error.size(); ++i) {
        bool ok = true;
        for (int c = 0; c < 3; ++c) {
            const double a = image.rgb[3 * i + c], r = reference.rgb[3 * i + c];
            const double e = std::abs(a - r);
            ok = ok && e <= rel * std::abs(r) + floor;
            error[i] = std::max(error[i], float(e / (std::abs(r) + floor + 1e-30)));
        }
        good += ok ? 1 : 0;
    }
    const double fraction = double(good) / double(std::max<std::size_t>(error.size(), 1));
    if (fraction < required) write_failure_images(label, image, reference, error);
    return fraction;
}

double fraction_same_cut(const RenderStats& a, const RenderStats& b) {
    EXPECT_EQ(a.cut_size.size(), b.cut_size.size());
    std::size_t same = 0;
    for (std::size_t i = 0; i < std::min(a.cut_size.size(), b.cut_size.size()); ++i)
        same += a.cut_size[i] == b.cut_size[i] ? 1 : 0;
    return double(same) / double(std::max<std::size_t>(a.cut_size.size(), 1));
}

std::size_t pixels_with_different_cut(const RenderStats& a, const RenderStats& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < std::min(a.cut_size.size(), b.cut_size.size()); ++i)
        n += a.cut_size[i] != b.cut_size[i] ? 1 : 0;
    return n;
}

constexpr double kBruteRelative = 1e-4, kBruteFraction = 0.999;
constexpr double kCutFraction = 0.99;
constexpr double kLightcutsRelative = 1e-3, kLightcutsFraction = 0.995;

void expect_brute_matches(const PreparedScene& p, const RenderOptions& o, const RenderResult& g) {
    RenderResult c = render_cpu(p, o);
    ASSERT_EQ(g.image.width, c.image.width);
    ASSERT_EQ(g.image.height, c.image.height);
    EXPECT_GE(fraction_within(g.image, c.image, kBruteRelative, "brute", kBruteFraction),
              kBruteFraction);
    EXPECT_EQ(g.stats.camera_rays, c.stats.camera_rays);
    // A grazing shadow ray may be skipped on one side only (zero contribution).
    EXPECT_NEAR(double(g.stats.shadow_rays), double(c.stats.shadow_rays),
                1e-3 * double(c.stats.shadow_rays) + 1.0);
}

void expect_lightcuts_matches(const PreparedScene& p, const RenderOptions& o, const RenderResult& g) {
    RenderResult c = render_cpu(p, o);
    ASSERT_EQ(g.image.width, c.image.width);
    EXPECT_GE(fraction_same_cut(g.stats, c.stats), kCutFraction);
    EXPECT_GE(fraction_within(g.image, c.image, kLightcutsRelative, "lightcuts", kLightcutsFraction),
              kLightcutsFraction);
    EXPECT_NEAR(double(g.stats.shadow_rays), double(c.stats.shadow_rays),
                1e-2 * double(c.stats.shadow_rays) + 1.0);
    EXPECT_NEAR(double(g.stats.max_cut_pixels), double(c.stats.max_cut_pixels),
                0.01 * double(g.image.width * g.image.height) * o.spp + 1.0);
}

// Ground plane, random boxes, random point and directional lights, Lambert
// and GGX materials; seeded.
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
    add_quad(s, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, 0);
    const int boxes = 3 + int(seed % 5);
    for (int b = 0; b < boxes; ++b) {
        glm::vec3 lo(-2.0f + 3.5f * u(rng), 0.0f, -2.0f + 3.5f * u(rng));
        glm::vec3 size(0.2f + 0.6f * u(rng), 0.2f + 1.0f * u(rng), 0.2f + 0.6f * u(rng));
        if (u(rng) < 0.3f) lo.y = 0.3f + u(rng);  // some float above the ground
        add_box(s, lo, lo + size, 1 + std::uint32_t(b) % 4);
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
                      std::uint32_t spp = 1) {
    RenderOptions o;
    o.method = method;
    o.width = w;
    o.height = h;
    o.spp = spp;
    return o;
}

// --- Device choice.

TEST_F(Vulkan, DefaultDeviceIsOneOfTheListedDevices) {
    Scene s = random_scene(1, 4, 0, 8, 8);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderResult r = gpu(p, options("brute", 8, 8));
    const std::vector<std::string> names = list_vulkan_devices();
    EXPECT_NE(std::find(names.begin(), names.end(), r.stats.device), names.end()) << r.stats.device;
}

TEST_F(Vulkan, DeviceChosenByIndexAndByNameSubstring) {
    PreparedScene p = prepare_scene(random_scene(2, 4, 0, 8, 8), 1);
    const std::vector<std::string> names = list_vulkan_devices();
    VulkanOptions v;
    v.validation = true;
    for (std::size_t i = 0; i < names.size(); ++i) {
        v.gpu = std::to_string(i);
        EXPECT_EQ(render_vulkan(p, options("brute", 8, 8), v).stats.device, names[i]);
    }
    std::string upper = names[0].substr(0, 4);
    for (char& ch : upper) ch = char(std::toupper(static_cast<unsigned char>(ch)));
    v.gpu = upper;  // case-insensitive
    EXPECT_NE(render_vulkan(p, options("brute", 8, 8), v).stats.device.find(names[0].substr(0, 4)),
              std::string::npos);
}

TEST_F(Vulkan, NoMatchingDeviceListsTheDevicesAndWhy) {
    PreparedScene p = prepare_scene(random_scene(3, 4, 0, 8, 8), 1);
    VulkanOptions v;
    v.gpu = "no-such-device-anywhere";
    try {
        render_vulkan(p, options("brute", 8, 8), v);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("no Vulkan device matches 'no-such-device-anywhere'"), std::string::npos)
            << what;
        for (const std::string& name : list_vulkan_devices())
            EXPECT_NE(what.find(name), std::string::npos) << what;
        EXPECT_NE(what.find("name does not contain"), std::string::npos) << what;
    }
    v.gpu = "99";
    EXPECT_THROW(render_vulkan(p, options("brute", 8, 8), v), std::runtime_error);
}

// --- Analytic truth (pbrt-v4 style): a point light of intensity pi * h^2 at
// height h straight above the point the centre pixel sees, on a Lambert
// plane of albedo 0.5, gives radiance kd/pi * I * cos / d^2 = 0.5 there.
// The shaded point sits 1/65536 above the plane (trace.h's offset against
// self-intersection), which raises 1/d^2 by 2e-5 relative: tolerance 4e-5.
TEST_F(Vulkan, PointLightAbovePlaneGivesAnalyticRadiance) {
    Scene s;
    s.materials = {test::lambert(glm::vec3(0.5f))};
    add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    const float h = 1.5f;
    s.lights = {test::point_light({0.0f, h, 0.0f}, glm::vec3(kPi * h * h))};
    s.camera = test::camera({0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 40.0f, 33, 33);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    EXPECT_FALSE(p.has_occluders);
    for (const char* method : {"brute", "lightcuts"}) {
        RenderResult r = gpu(p, options(method, 33, 33));
        const glm::vec3 c = r.image.at(16, 16);
        EXPECT_NEAR(c.x, 0.5f, 2e-5f) << method;
        EXPECT_NEAR(c.y, 0.5f, 2e-5f) << method;
        EXPECT_NEAR(c.z, 0.5f, 2e-5f) << method;
    }
}

// --- Against the CPU reference.

TEST_F(Vulkan, BruteMatchesCpuOnRandomScenes) {
    for (std::uint32_t seed = 10; seed < 14; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        PreparedScene p = prepare_scene(random_scene(seed, 24, 2, 40, 32), seed);
        RenderOptions o = options("brute", 40, 32);
        o.seed = seed;
        expect_brute_matches(p, o, gpu(p, o));
    }
}

TEST_F(Vulkan, LightcutsMatchesCpuOnRandomScenes) {
    for (std::uint32_t seed = 20; seed < 24; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        PreparedScene p = prepare_scene(random_scene(seed, 200, 3, 40, 32), seed);
        RenderOptions o = options("lightcuts", 40, 32);
        o.seed = seed;
        o.max_cut = 100;
        RenderResult g = gpu(p, o);
        expect_lightcuts_matches(p, o, g);
        EXPECT_GT(g.stats.heap_capacity_shared, 0u);
    }
}

// Odd image size, several samples and tiles far smaller than the image (and
// than a workgroup), so tile edges and partial workgroups are exercised.
TEST_F(Vulkan, SmallTilesAndSeveralSamplesMatchCpu) {
    PreparedScene p = prepare_scene(random_scene(31, 60, 1, 37, 23), 3);
    vk::Tuning small_tiles;
    small_tiles.max_tile_pixels = 50;
    {
        RenderOptions o = options("brute", 37, 23, 4);
        expect_brute_matches(p, o, gpu(p, o, small_tiles));
    }
    {
        RenderOptions o = options("lightcuts", 37, 23, 3);
        expect_lightcuts_matches(p, o, gpu(p, o, small_tiles));
    }
}

// Cuts far larger than the shared-memory part of the heap: relative error 0
// refines to single lights wherever a bound is non-zero. The result must
// still match, and every sample whose heap outgrew the shared slots counted.
TEST_F(Vulkan, HeapSpillingToGlobalMemoryStaysExactAndIsCounted) {
    PreparedScene p = prepare_scene(random_scene(41, 400, 0, 24, 20), 5);
    RenderOptions o = options("lightcuts", 24, 20, 2);
    o.relative_error = 0.0f;
    o.max_cut = 1000;
    vk::Tuning tiles;
    tiles.max_tile_pixels = 128;  // several tiles reuse the spill buffer
    RenderResult g = gpu(p, o, tiles);
    expect_lightcuts_matches(p, o, g);

    const std::uint32_t k = g.stats.heap_capacity_shared;
    ASSERT_GT(k, 0u);
    const std::uint64_t expected = count_spilling_samples(p, o, k);
    EXPECT_GT(expected, 0u) << "the scene should make heaps outgrow " << k << " shared slots";
    RenderResult c = render_cpu(p, o);
    const double slack = double(pixels_with_different_cut(g.stats, c.stats)) * o.spp;
    std::printf("K = %u: %llu samples spilled on the GPU, %llu by the CPU count\n", k,
                static_cast<unsigned long long>(g.stats.heap_spill_pixels),
                static_cast<unsigned long long>(expected));
    EXPECT_NEAR(double(g.stats.heap_spill_pixels), double(expected), slack)
        << "K = " << k << ", samples = " << std::uint64_t(24 * 20) * o.spp;
    const float largest = *std::max_element(g.stats.cut_size.begin(), g.stats.cut_size.end());
    EXPECT_GT(largest, float(k));
}

// The work of a pixel split over several dispatches, as on drivers that cut
// long loops short (lavapipe): brute force over light ranges, Lightcuts with
// a few refinements per dispatch, the heap's shared part saved in between.
TEST_F(Vulkan, WorkSplitOverDispatchesMatchesCpu) {
    PreparedScene p = prepare_scene(random_scene(71, 300, 2, 24, 20), 9);
    vk::Tuning split;
    split.lights_per_dispatch = 40;
    split.refinements_per_dispatch = 16;
    split.max_tile_pixels = 200;
    {
        RenderOptions o = options("brute", 24, 20, 2);
        expect_brute_matches(p, o, gpu(p, o, split));
    }
    {
        RenderOptions o = options("lightcuts", 24, 20, 2);
        o.relative_error = 0.0f;
        o.max_cut = 200;
        RenderResult g = gpu(p, o, split);
        expect_lightcuts_matches(p, o, g);
        const std::uint64_t expected = count_spilling_samples(p, o, g.stats.heap_capacity_shared);
        EXPECT_GT(expected, 0u);
        RenderResult c = render_cpu(p, o);
        EXPECT_NEAR(double(g.stats.heap_spill_pixels), double(expected),
                    double(pixels_with_different_cut(g.stats, c.stats)) * o.spp);
    }
}

// max_cut 1 keeps two roots: the heap capacity is max(max_cut, 2).
TEST_F(Vulkan, TinyMaxCutMatchesCpu) {
    PreparedScene p = prepare_scene(random_scene(51, 50, 2, 24, 20), 5);
    RenderOptions o = options("lightcuts", 24, 20);
    o.max_cut = 1;
    expect_lightcuts_matches(p, o, gpu(p, o));
}

// Specialization constants switch GGX and shadow rays off for scenes that
// cannot use them; forcing them on must not change the image.
TEST_F(Vulkan, FeatureSwitchesDoNotChangeTheImage) {
    Scene s;
    s.materials = {test::lambert({0.7f, 0.6f, 0.5f})};
    add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    s.lights = test::random_point_lights(30, {-2, 0.5f, -2}, {2, 2, 2}, 10.0f, 3);
    s.camera = test::camera({0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 50.0f, 24, 24);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    ASSERT_FALSE(p.has_specular);
    ASSERT_FALSE(p.has_occluders);
    vk::Tuning all;
    all.force_ggx = true;
    all.force_shadows = true;
    for (const char* method : {"brute", "lightcuts"}) {
        RenderOptions o = options(method, 24, 24);
        RenderResult off = gpu(p, o), on = gpu(p, o, all);
        EXPECT_GE(fraction_within(on.image, off.image, kBruteRelative, "switches", kBruteFraction),
                  kBruteFraction)
            << method;
        if (std::string(method) == "brute") expect_brute_matches(p, o, off);
        else expect_lightcuts_matches(p, o, off);
    }
}

// The shipped demo room (GGX torus, 1000 point lights) at reduced size.
TEST_F(Vulkan, ShippedRoomSceneMatchesCpu) {
    const std::filesystem::path file = std::filesystem::path(LC_SOURCE_DIR) / "scenes/room/room.json";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is missing";
    PreparedScene p = prepare_scene(load_scene(file), 1);
    {
        RenderOptions o = options("brute", 32, 32);
        expect_brute_matches(p, o, gpu(p, o));
    }
    {
        RenderOptions o = options("lightcuts", 48, 48);
        RenderResult g = gpu(p, o);
        expect_lightcuts_matches(p, o, g);
        EXPECT_GT(g.stats.seconds_shading, 0.0);
        EXPECT_GT(g.stats.seconds_primary, 0.0);
        EXPECT_FALSE(g.stats.buffer_bytes.empty());
    }
}

// A cut heap that cannot fit a single workgroup's spill region is refused
// with a message naming the buffer, its size and the limit.
TEST_F(Vulkan, OversizedHeapIsRefusedClearly) {
    PreparedScene p = prepare_scene(random_scene(61, 8, 0, 8, 8), 1);
    RenderOptions o = options("lightcuts", 8, 8);
    o.max_cut = 2'000'000'000u;
    try {
        gpu(p, o);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("heap spill"), std::string::npos) << what;
        EXPECT_NE(what.find("bytes"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace lc
