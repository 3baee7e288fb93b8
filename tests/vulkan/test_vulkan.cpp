// The Vulkan compute path against analytic truth and against the CPU
// reference (render_cpu), with the validation layer on: any validation
// message makes render_vulkan throw, so every test below also checks that.
// Tolerances: vulkan_test_support.h.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <random>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "cpu_kernel.h"
#include "lightcuts/error.h"
#include "scene/materials.h"
#include "scene/textures.h"
#include "test_util.h"
#include "vulkan_test_support.h"

namespace lc {
namespace {

using test::add_quad;
using vulkan_test::expect_brute_matches;
using vulkan_test::expect_lightcuts_matches;
using vulkan_test::options;
using vulkan_test::pixels_with_different_cut;
using vulkan_test::random_scene;
using vulkan_test::Vulkan;

constexpr float kPi = 3.14159265358979f;

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

// A VulkanRenderer keeps its device open across renders: each render is
// render_vulkan's, image and stats, whatever came before it on the device
// (another scene, another method, a render that failed), and renders asked
// for from two threads at once come out as they do one by one.
TEST_F(Vulkan, RendererKeptOpenRendersAsRenderVulkanDoes) {
    PreparedScene lit = prepare_scene(random_scene(5, 40, 3, 24, 16), 7);
    PreparedScene other = prepare_scene(random_scene(6, 9, 2, 16, 16), 3);
    VulkanOptions v;
    v.validation = true;
    VulkanRenderer renderer(v);
    const RenderOptions cuts = options("lightcuts", 24, 16, 2);
    const RenderOptions brute = options("brute", 16, 16);
    const RenderResult cuts_once = render_vulkan(lit, cuts, v);
    const RenderResult brute_once = render_vulkan(other, brute, v);
    EXPECT_EQ(renderer.device_name(), cuts_once.stats.device);

    const auto expect_same = [](const RenderResult& r, const RenderResult& once, const char* what) {
        EXPECT_EQ(r.image.width, once.image.width) << what;
        EXPECT_EQ(r.image.rgb, once.image.rgb) << what;
        EXPECT_EQ(r.stats.shadow_rays, once.stats.shadow_rays) << what;
        EXPECT_EQ(r.stats.cut_size, once.stats.cut_size) << what;
        EXPECT_EQ(r.stats.device, once.stats.device) << what;
    };
    expect_same(renderer.render(lit, cuts), cuts_once, "first render");
    expect_same(renderer.render(other, brute), brute_once, "another scene and method");
    RenderOptions bad = cuts;
    bad.relative_error = -1.0f;
    EXPECT_THROW(renderer.render(lit, bad), std::invalid_argument);
    RenderOptions path = cuts;
    path.method = "path";
    EXPECT_THROW(renderer.render(lit, path), std::invalid_argument);
    // Refused on the device, with its command pool and fence made.
    RenderOptions octets = cuts;
    octets.cut_sharing = "octet";
    EXPECT_THROW(renderer.render(lit, octets), std::invalid_argument);
    expect_same(renderer.render(lit, cuts), cuts_once, "after refused options");

    std::future<RenderResult> a = std::async(std::launch::async, [&] { return renderer.render(lit, cuts); });
    std::future<RenderResult> b = std::async(std::launch::async, [&] { return renderer.render(other, brute); });
    expect_same(a.get(), cuts_once, "from one of two threads");
    expect_same(b.get(), brute_once, "from the other thread");
}

// A gpu that names no device is the caller's mistake, as for render_vulkan:
// an error, not "no device" (which the CLI's device "auto" takes as a cue
// to render on the CPU).
TEST_F(Vulkan, RendererForAGpuNamingNoDeviceRefusesIt) {
    VulkanOptions v;
    v.gpu = "no-such-device-anywhere";
    try {
        VulkanRenderer renderer(v);
        FAIL() << "expected an exception";
    } catch (const NoVulkanDevice& e) {
        FAIL() << "not NoVulkanDevice: " << e.what();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("no Vulkan device matches 'no-such-device-anywhere'"),
                  std::string::npos)
            << e.what();
    }
}

// Device "auto" decides from an answer of probe_gpus given early (the CLI
// asks while the scene loads) instead of asking again: told of no device,
// of a software one only, or of no GPU device file (no driver loaded), it
// renders on the CPU and says which, whatever this machine has.
TEST(DeviceChoiceAuto, DecidesFromTheDevicesFoundEarly) {
    PreparedScene p = prepare_scene(random_scene(6, 4, 0, 8, 8), 1);
    const RenderOptions o = options("lightcuts", 8, 8);
    const std::pair<GpuProbe, std::string> cases[] = {
        {GpuProbe{VulkanDevices{}, false}, "no Vulkan device; rendering on the CPU"},
        {GpuProbe{VulkanDevices{{"a software rasterizer"}, false}, false},
         "only a software Vulkan device is present; rendering on the CPU (device \"vulkan\" uses it anyway)"},
        {GpuProbe{VulkanDevices{}, true},
         "no GPU on this machine (no device file in /dev that a GPU's driver uses); rendering on the CPU"},
    };
    for (const auto& [told, expected] : cases) {
        std::promise<GpuProbe> answer;
        answer.set_value(told);
        DeviceChoice choice;
        choice.devices = answer.get_future().share();
        std::string said;
        choice.note = [&](const std::string& line) { said = line; };
        EXPECT_EQ(render(p, o, choice).stats.device, "cpu");
        EXPECT_EQ(said, expected);
    }
}

// Told of a hardware GPU, device "auto" renders through Vulkan (here on
// whatever device this machine has, which the answer claims is one); cuts
// shared by octets, which the kernels do not make, fall back to the CPU
// with a note that names the setting.
TEST_F(Vulkan, AutoRendersOnAHardwareGpuAndFallsBackForOctets) {
    PreparedScene p = prepare_scene(random_scene(6, 4, 0, 8, 8), 1);
    const auto told_of_a_gpu = [] {
        std::promise<GpuProbe> answer;
        answer.set_value(GpuProbe{VulkanDevices{list_vulkan_devices(), true}, false});
        DeviceChoice choice;
        choice.devices = answer.get_future().share();
        return choice;
    };
    DeviceChoice choice = told_of_a_gpu();
    std::string said;
    choice.note = [&](const std::string& line) { said = line; };
    const RenderResult pixel = render(p, options("lightcuts", 8, 8), choice);
    const std::vector<std::string> names = list_vulkan_devices();
    EXPECT_NE(std::find(names.begin(), names.end(), pixel.stats.device), names.end()) << pixel.stats.device;
    EXPECT_EQ(said, "");
    RenderOptions octets = options("lightcuts", 8, 8);
    octets.cut_sharing = "octet";
    choice = told_of_a_gpu();
    choice.note = [&](const std::string& line) { said = line; };
    EXPECT_EQ(render(p, octets, choice).stats.device, "cpu");
    EXPECT_NE(said.find("cut_sharing \"octet\""), std::string::npos) << said;
    EXPECT_NE(said.find("rendering on the CPU"), std::string::npos) << said;
}

// The device files a GPU's driver would use, found under a /dev of our
// making: render nodes under dri/ (not card nodes), NVIDIA's, WSL's, and
// none of the rest.
TEST(DeviceChoiceAuto, FindsTheDeviceFilesOfGpus) {
    const std::filesystem::path dev = std::filesystem::temp_directory_path() /
                                      ("lc_dev_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dev);
    std::filesystem::create_directories(dev / "dri");
    auto touch = [&](const std::string& name) { std::ofstream(dev / name).put('x'); };
    EXPECT_TRUE(gpu_device_files(dev.string()).empty());
    for (const char* name : {"null", "tty0", "dri/card0", "nvme0"}) touch(name);
    EXPECT_TRUE(gpu_device_files(dev.string()).empty());
    for (const char* name : {"dri/renderD128", "nvidia0", "nvidiactl", "dxg"}) touch(name);
    EXPECT_EQ(gpu_device_files(dev.string()),
              (std::vector<std::string>{"dri/renderD128", "dxg", "nvidia0", "nvidiactl"}));
    EXPECT_TRUE(gpu_device_files((dev / "absent").string()).empty());
    std::filesystem::remove_all(dev);
}

// probe_gpus loads no driver exactly where this machine has no GPU device
// file and the loader is not pointed at drivers; pointed at some (here the
// drivers this machine lists, through VK_DRIVER_FILES), it asks the
// loader, whatever /dev holds.
TEST(DeviceChoiceAuto, ProbesTheDriversUnlessNoGpuCouldAnswer) {
    const char* driver_files = std::getenv("VK_DRIVER_FILES");
    const char* icd_filenames = std::getenv("VK_ICD_FILENAMES");
    const bool named = driver_files != nullptr || icd_filenames != nullptr;
    const GpuProbe probe = probe_gpus();
    EXPECT_EQ(probe.skipped, !named && gpu_device_files().empty());
    if (probe.skipped) EXPECT_TRUE(probe.devices.names.empty() && !probe.devices.hardware);
    else EXPECT_EQ(probe.devices.names, list_vulkan_devices());
    if (named) return;
    const std::string all_drivers = "/usr/share/vulkan/icd.d";
    if (!std::filesystem::is_directory(all_drivers)) return;  // no driver installed to point the loader at
    ::setenv("VK_DRIVER_FILES", all_drivers.c_str(), 1);
    const GpuProbe pointed = probe_gpus();
    ::unsetenv("VK_DRIVER_FILES");
    EXPECT_FALSE(pointed.skipped);
    EXPECT_EQ(pointed.devices.names, list_vulkan_devices());
}

// The LC_VK_* switches take the values docs/vulkan.md names and refuse
// any other, naming the variable: a misspelt switch must not quietly time
// the default (bench/spec_switches.sh once printed rows for "shadow" that
// forced nothing).
TEST(TuningFromEnvironment, TakesTheNamedValuesAndRefusesOthers) {
    const auto with = [](const char* name, const char* value) {
        ::setenv(name, value, 1);
        struct Unset {
            const char* name;
            ~Unset() { ::unsetenv(name); }
        } unset{name};
        return vk::Tuning::from_environment();
    };
    const auto refused = [&](const char* name, const char* value) {
        try {
            with(name, value);
        } catch (const InputError& e) {
            return std::string(e.what()).find(name) != std::string::npos;
        }
        return false;
    };
    const vk::Tuning forced = with("LC_VK_FORCE_FEATURES", "ggx,disney");
    EXPECT_TRUE(forced.force_ggx && forced.force_disney);
    EXPECT_FALSE(forced.force_shadows || forced.force_sheen);
    const vk::Tuning all = with("LC_VK_FORCE_FEATURES", "all");
    EXPECT_TRUE(all.force_shadows && all.force_oriented && all.force_textures && all.force_clearcoat);
    EXPECT_FALSE(with("LC_VK_FORCE_FEATURES", "none").force_ggx);
    EXPECT_EQ(with("LC_VK_HEAP_MEMORY", "shared").heap_memory, vk::Tuning::HeapMemory::kShared);
    EXPECT_EQ(with("LC_VK_SPLIT_SLOW_TILES", "auto").split_slow_tiles, vk::Tuning::SplitSlowTiles::kAuto);
    EXPECT_EQ(with("LC_VK_MAX_TILE_PIXELS", "4096").max_tile_pixels, 4096u);
    EXPECT_FALSE(with("LC_VK_HOST_IMPORT", "0").host_import);
    EXPECT_DOUBLE_EQ(with("LC_VK_TARGET_MS", "200").target_dispatch_ms, 200.0);
    EXPECT_TRUE(refused("LC_VK_FORCE_FEATURES", "shadow"));
    EXPECT_TRUE(refused("LC_VK_HEAP_MEMORY", "on"));
    EXPECT_TRUE(refused("LC_VK_TEXEL_READS", "yes"));
    EXPECT_TRUE(refused("LC_VK_MAX_TILE_PIXELS", "12x"));
    EXPECT_TRUE(refused("LC_VK_MIN_TILE_PIXELS", "-1"));
    EXPECT_TRUE(refused("LC_VK_SPLIT_BYTES", "1e6"));
    EXPECT_TRUE(refused("LC_VK_HOST_IMPORT", "yes"));
    EXPECT_TRUE(refused("LC_VK_TARGET_MS", "0"));
    EXPECT_TRUE(refused("LC_VK_TARGET_MS", "inf"));
}

// --- Analytic truth (pbrt-v4 style): a point light of intensity pi * h^2 at
// height h straight above the point the centre pixel sees, on a Lambert
// plane of albedo 0.5, gives radiance kd/pi * I * cos / d^2 = 0.5 there.
// The shaded point sits kHitOffsetRelative (2^-20) of the triangle's largest
// coordinate (2) above the plane (shaders/lc_shared/trace.h, against
// self-intersection), which raises 1/d^2 by 2.5e-6 relative: the expected
// value is 0.5 (h / (h - offset))^2, within 1e-7 (two float steps at 0.5;
// measured 2e-8).
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
    const double offset = double(cpu::ShadeKernel::kHitOffsetRelative) * 2.0;
    const double expected = 0.5 * (h / (h - offset)) * (h / (h - offset));
    for (const char* method : {"brute", "lightcuts"}) {
        RenderResult r = gpu(p, options(method, 33, 33));
        const glm::vec3 c = r.image.at(16, 16);
        std::printf("[ measured ] %s: radiance - expected = %.3g\n", method, double(c.x) - expected);
        for (int channel = 0; channel < 3; ++channel)
            EXPECT_NEAR(c[channel], expected, 1e-7) << method;
    }
}

// One plane, its shading normals tilted 30 degrees, a point light under
// it: the tilt turns the light's cosine positive at the plane's top, and
// only the plane itself, as a blocker, keeps the light out. The kernels
// may leave shadow rays out only where nothing can block a light
// (PreparedScene::has_occluders); here they must trace them, and the plane
// is black on both devices (before, lavapipe lit it through itself).
TEST_F(Vulkan, PlaneWithTiltedNormalsShadowsALightBehindIt) {
    Scene s;
    s.materials = {test::lambert(glm::vec3(0.5f))};
    add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    for (gpu::TriangleNormals& n : s.normals) {
        n.n0_x = n.n1_x = n.n2_x = 0.5f;
        n.n0_y = n.n1_y = n.n2_y = 0.8660254f;
        n.n0_z = n.n1_z = n.n2_z = 0.0f;
    }
    s.lights = {test::point_light({1.0f, -0.5f, 0.0f}, glm::vec3(10.0f))};
    s.camera = test::camera({0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 40.0f, 16, 16);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    EXPECT_TRUE(p.has_occluders);
    for (const char* method : {"brute", "lightcuts"}) {
        const RenderResult r = gpu(p, options(method, 16, 16));
        const RenderResult c = render_cpu(p, options(method, 16, 16));
        for (std::uint32_t y = 0; y < 16; ++y)
            for (std::uint32_t x = 0; x < 16; ++x) {
                ASSERT_EQ(r.image.at(x, y), glm::vec3(0.0f)) << method << " pixel " << x << "," << y;
                ASSERT_EQ(c.image.at(x, y), glm::vec3(0.0f)) << method << " pixel " << x << "," << y;
            }
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

// The kernels' brute force keeps every light too (compensated summation,
// shaders/lc_shared/brute.h): 65,536 lights each about 2^-27 of the sum of
// eight bright ones, which a plain float sum rounds away (5e-4 of the
// light, 15 times the tolerance), match the CPU's double sum
// (BruteForce.ManyDimLightsBesideBrightOnesAllCount) to the tolerance of
// a sum the loop limit splits into ranges.
TEST_F(Vulkan, BruteForceKeepsManyDimLightsBesideBrightOnes) {
    const PreparedScene p = prepare_scene(test::room_scene(test::many_dim_lights(), 4), 1);
    const RenderOptions o = options("brute", 4, 4);
    expect_brute_matches(p, o, gpu(p, o), vulkan_test::kBruteSplitRelative);
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
        EXPECT_EQ(g.stats.heap_slots, std::min(kDefaultCutHeap, p.tree.cut_heap_capacity(o.max_cut)));
    }
}

// Cuts shared by the pixels of 2x2 quads (quadcuts.comp) against the CPU's
// (host/quad_cut.h), at odd image sizes (quads cut by the right and bottom
// edges, lanes without a pixel). "auto" cuts each pixel alone on Vulkan;
// "octet", the CPU's default sharing, is refused there, naming the setting.
TEST_F(Vulkan, QuadCutsMatchCpu) {
    for (std::uint32_t seed = 20; seed < 23; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        PreparedScene p = prepare_scene(random_scene(seed, 200, 3, 41, 31), seed);
        RenderOptions o = options("lightcuts", 41, 31);
        o.seed = seed;
        o.max_cut = 100;
        o.cut_sharing = "quad";
        RenderResult g = gpu(p, o);
        EXPECT_EQ(g.stats.cut_points, 4u);
        expect_lightcuts_matches(p, o, g);
        EXPECT_EQ(g.stats.heap_slots, std::min(4 * kDefaultCutHeap, p.tree.cut_heap_capacity(o.max_cut)));
        o.cut_sharing = "auto";
        EXPECT_EQ(gpu(p, o).stats.cut_points, 1u);
    }
    PreparedScene p = prepare_scene(random_scene(20, 50, 1, 8, 8), 20);
    RenderOptions o = options("lightcuts", 8, 8);
    o.cut_sharing = "octet";
    try {
        gpu(p, o);
        ADD_FAILURE() << "cut_sharing \"octet\" rendered on Vulkan";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("cut_sharing \"octet\""), std::string::npos) << e.what();
    }
}

// A quad's cut paused between dispatches (a few refinements each, its heap
// of 4 x 4 slots freezing clusters), over several samples and tiles smaller
// than a workgroup: the same image as in one dispatch, bit for bit (the
// pause keeps everything the next step reads), and the CPU's.
TEST_F(Vulkan, QuadCutsSplitOverDispatchesMatchCpu) {
    PreparedScene p = prepare_scene(random_scene(71, 300, 2, 25, 19), 9);
    RenderOptions o = options("lightcuts", 25, 19, 2);
    o.cut_sharing = "quad";
    o.relative_error = 0.0f;
    o.max_cut = 200;
    o.cut_heap = 4;
    vk::Tuning split;
    split.refinements_per_dispatch = 16;
    split.max_tile_pixels = 50;
    vk::Tuning whole;
    whole.max_tile_pixels = 50;
    const RenderResult g = gpu(p, o, split);
    EXPECT_GT(g.stats.heap_paused_samples, 0u);
    EXPECT_GT(g.stats.heap_frozen_samples, 0u);
    EXPECT_EQ(g.stats.heap_slots, 16u);
    const RenderResult once = gpu(p, o, whole);
    EXPECT_EQ(once.stats.heap_paused_samples, 0u);
    EXPECT_EQ(vulkan_test::max_relative_difference(g.image, once.image, "quads paused", 0.0), 0.0);
    EXPECT_EQ(g.stats.shadow_rays, once.stats.shadow_rays);
    expect_lightcuts_matches(p, o, g);
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

// Cuts far larger than the heap: relative error 0 refines to single lights
// wherever a bound is non-zero, so a heap of 4 slots freezes clusters at
// most points. The GPU freezes as the CPU reference does: same image, and
// the same count of samples that froze (but for pixels whose cut differs by
// a rounding), with the heap in the device's default memory (private).
TEST_F(Vulkan, BoundedHeapFreezesAsTheCpuDoes) {
    PreparedScene p = prepare_scene(random_scene(41, 400, 0, 24, 20), 5);
    RenderOptions o = options("lightcuts", 24, 20, 2);
    o.relative_error = 0.0f;
    o.max_cut = 1000;
    o.cut_heap = 4;
    vk::Tuning tiles;
    tiles.max_tile_pixels = 128;  // several tiles reuse the buffers
    RenderResult g = gpu(p, o, tiles);
    expect_lightcuts_matches(p, o, g);
    EXPECT_EQ(g.stats.heap_slots, 4u);
    RenderResult c = render_cpu(p, o);
    EXPECT_EQ(c.stats.heap_slots, 4u);
    EXPECT_GT(c.stats.heap_frozen_samples, std::uint64_t(24 * 20) * o.spp / 2) << "most heaps should fill";
    const double slack = double(pixels_with_different_cut(g.stats, c.stats)) * o.spp;
    std::printf("K = 4: %llu samples froze clusters on the GPU, %llu on the CPU\n",
                static_cast<unsigned long long>(g.stats.heap_frozen_samples),
                static_cast<unsigned long long>(c.stats.heap_frozen_samples));
    EXPECT_NEAR(double(g.stats.heap_frozen_samples), double(c.stats.heap_frozen_samples), slack);
}

// The work of a pixel split over several dispatches, as on drivers that cut
// long loops short (lavapipe): brute force over light ranges, Lightcuts with
// a few refinements per dispatch, the heap saved in between.
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
        // Cuts of more than 16 refinements wait between dispatches, their
        // heaps in global memory; the CPU reference freezes the same clusters.
        EXPECT_GT(g.stats.heap_paused_samples, 0u);
        RenderResult c = render_cpu(p, o);
        EXPECT_GT(c.stats.heap_frozen_samples, 0u);
        EXPECT_NEAR(double(g.stats.heap_frozen_samples), double(c.stats.heap_frozen_samples),
                    double(pixels_with_different_cut(g.stats, c.stats)) * o.spp);
    }
}

// Tiles of the smallest size whose shading takes over 4x the dispatch
// target (here every tile: each shading dispatch taken as 100 ms against a
// target of 1 ms, whatever the clock says) split each pixel's work over
// more dispatches for the tiles after them, as on GPUs, where a tile too
// small to fill the device takes one pixel's time whatever its size: the
// images stay the CPU's. An image of one tile has no tile after it, and
// switched off nothing is split.
TEST_F(Vulkan, SlowSmallTilesSplitTheWorkFiner) {
    PreparedScene p = prepare_scene(random_scene(72, 300, 2, 24, 20), 9);
    vk::Tuning slow;
    slow.split_slow_tiles = vk::Tuning::SplitSlowTiles::kOn;
    slow.target_dispatch_ms = 1.0;
    slow.shading_ms_for_split = 100.0;
    slow.min_tile_pixels = 64;
    slow.max_tile_pixels = 64;
    {
        RenderOptions o = options("brute", 24, 20, 2);
        const RenderResult g = gpu(p, o, slow);
        EXPECT_GT(g.stats.work_splits, 0u);
        expect_brute_matches(p, o, g, vulkan_test::kBruteSplitRelative);
    }
    RenderOptions o = options("lightcuts", 24, 20, 2);
    o.relative_error = 0.0f;
    o.max_cut = 200;
    const RenderResult g = gpu(p, o, slow);
    EXPECT_GT(g.stats.work_splits, 0u);
    EXPECT_GT(g.stats.heap_paused_samples, 0u);
    expect_lightcuts_matches(p, o, g);
    EXPECT_EQ(gpu(p, options("lightcuts", 8, 8), slow).stats.work_splits, 0u);
    slow.split_slow_tiles = vk::Tuning::SplitSlowTiles::kOff;
    EXPECT_EQ(gpu(p, o, slow).stats.work_splits, 0u);
}

// max_cut 1 keeps both roots, so the cut (and its heap) has two clusters.
TEST_F(Vulkan, TinyMaxCutMatchesCpu) {
    PreparedScene p = prepare_scene(random_scene(51, 50, 2, 24, 20), 5);
    RenderOptions o = options("lightcuts", 24, 20);
    o.max_cut = 1;
    expect_lightcuts_matches(p, o, gpu(p, o));
}

// Specialization constants switch GGX, shadow rays, the spot/oriented
// light code and the Disney lobes off for scenes that cannot use them; forcing them on must not
// change the image.
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
    ASSERT_FALSE(p.has_oriented);
    vk::Tuning all;
    all.force_ggx = true;
    all.force_shadows = true;
    all.force_oriented = true;
    all.force_textures = true;
    all.force_disney = true;
    all.force_sheen = true;
    all.force_clearcoat = true;
    for (const char* method : {"brute", "lightcuts"}) {
        RenderOptions o = options(method, 24, 24);
        RenderResult off = gpu(p, o), on = gpu(p, o, all);
        EXPECT_LE(vulkan_test::max_relative_difference(on.image, off.image, "switches",
                                                       vulkan_test::kFeatureSwitchRelative),
                  vulkan_test::kFeatureSwitchRelative)
            << method;
        if (std::string(method) == "brute") expect_brute_matches(p, o, off);
        else expect_lightcuts_matches(p, o, off);
    }
}

// Every texture slot on both devices: base colour, metallic-roughness and
// normal maps on every material of the random scene (planar UVs that wrap
// several times), and an emissive quad with a texture, whose area-light
// samples carry it. Roughness texels stay in [128, 255]: near-mirror GGX
// lobes (alpha ~ 1e-3) turn the last-bit differences of the two devices'
// normals into large relative ones, and are not what this test is about.
TEST_F(Vulkan, TexturedSceneMatchesCpu) {
    Scene s = random_scene(61, 30, 1, 40, 32);
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> byte(0, 255), tilt(90, 166), rough(128, 255);
    const auto add = [&](std::uint32_t w, std::uint32_t h, bool normal) {
        std::vector<std::uint8_t> rgba;
        for (std::uint32_t i = 0; i < w * h; ++i) {
            const int r = normal ? tilt(rng) : byte(rng), g = normal ? tilt(rng) : rough(rng);
            rgba.insert(rgba.end(), {std::uint8_t(r), std::uint8_t(g), std::uint8_t(normal ? 230 : byte(rng)), 255});
        }
        return loader::add_texture(s, w, h, rgba.data(), "test", "texture");
    };
    const std::uint32_t colour = add(16, 16, false), mr = add(8, 4, false), bumps = add(8, 8, true);
    const std::uint32_t glow = add(4, 4, false);
    for (gpu::Material& m : s.materials) {
        loader::set_texture(m, &gpu::Material::base_color_texture, colour);
        loader::set_texture(m, &gpu::Material::metallic_roughness_texture, mr);
        loader::set_texture(m, &gpu::Material::normal_texture, bumps);
    }
    gpu::Material lamp = loader::make_material(glm::vec3(0.2f), glm::vec3(0.0f), 1.0f);
    loader::set_emission(lamp, {3.0f, 2.0f, 1.0f}, false);
    loader::set_texture(lamp, &gpu::Material::emissive_texture, glow);
    s.materials.push_back(lamp);
    add_quad(s, {-1, 3.5f, -1}, {1, 3.5f, -1}, {1, 3.5f, 1}, {-1, 3.5f, 1}, std::uint32_t(s.materials.size() - 1));
    s.render.area_light_samples = 400;
    s.uvs.clear();
    for (const gpu::Triangle& t : s.triangles) {
        const auto uv = [](float x, float z) { return glm::vec2(0.37f * x + 0.1f, 0.29f * z - 0.2f); };
        const glm::vec2 a = uv(t.v0_x, t.v0_z), b = uv(t.v1_x, t.v1_z + 0.3f * t.v1_y), c = uv(t.v2_x + t.v2_y, t.v2_z);
        s.uvs.push_back({a.x, a.y, b.x, b.y, c.x, c.y});
    }
    PreparedScene p = prepare_scene(std::move(s), 1);
    ASSERT_TRUE(p.has_textures);
    ASSERT_GT(p.area_lights, 0u);
    // A texture turns the last-bit differences of the devices' texture
    // coordinates (FMA contraction in the barycentric sums) into value
    // differences of up to (texels per unit) x (texel contrast) x 1 ulp:
    // here 16 noise texels per unit, dark channels of 1/255 beside bright
    // ones. Measured: 1.25e-4 on lavapipe (a 1 x 1 texture: below 2e-5, as
    // without textures), 2.77e-4 on an H200 (NVIDIA 580), brute force and
    // Lightcuts alike, as their cuts are the same. About 2x the larger.
    constexpr double kTexturedRelative = 6e-4;
    const RenderOptions brute = options("brute", 40, 32);
    expect_brute_matches(p, brute, gpu(p, brute), kTexturedRelative);
    RenderOptions lc = options("lightcuts", 40, 32);
    lc.max_cut = 200;
    expect_lightcuts_matches(p, lc, gpu(p, lc), kTexturedRelative);
}

// The shipped demo room (GGX torus, 1000 point lights) at reduced size.
TEST_F(Vulkan, ShippedRoomSceneMatchesCpu) {
    const std::filesystem::path file = std::filesystem::path(LC_SOURCE_DIR) / "scenes/room/room.json";
    ASSERT_TRUE(std::filesystem::exists(file)) << file << " is committed";
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

}  // namespace
}  // namespace lc
