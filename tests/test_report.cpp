// The render report (lightcuts/report.h): the JSON keeps every key scripts
// read (bench/run) and adds the black lights; the text says what the JSON says.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lightcuts/report.h"
#include "test_util.h"

namespace lc {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// 20 lit lights and 3 black ones in the test room.
PreparedScene room_with_black_lights() {
    std::vector<gpu::Light> lights = test::random_point_lights(20, {-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 7);
    for (float x : {-0.5f, 0.0f, 0.5f}) lights.push_back(test::point_light({x, 1.0f, 0.0f}, glm::vec3(0.0f)));
    return prepare_scene(test::room_scene(std::move(lights), 8), 1);
}

TEST(Report, JsonHasEveryKeyScriptsReadAndTheBlackLights) {
    const PreparedScene p = room_with_black_lights();
    ASSERT_EQ(p.tree.black_lights, 3u);
    const RenderOptions o = test::options("lightcuts", 8);
    RenderResult r = render_cpu(p, o);
    r.stats.buffer_bytes = {{"lights", 7}, {"g-buffer", 99}};  // as the Vulkan renderer reports its buffers
    const RenderReport report = make_report("room.json", o, p, r, 0.25);
    const std::string json = report_json(report);
    for (const char* key : {"scene", "method", "device", "width", "height", "spp", "triangles", "lights",
                            "seconds", "load", "bvh_build", "light_tree_build", "render", "primary", "shading",
                            "camera_rays", "shadow_rays", "shadow_rays_per_pixel", "rays_per_second",
                            "buffer_bytes", "bvh_nodes", "normals", "materials", "light_tree_nodes", "lightcuts",
                            "relative_error", "max_cut", "tree_nodes", "tree_bytes", "cut_size_mean",
                            "cut_size_p50", "cut_size_p99", "cut_size_max", "max_cut_samples",
                            "cut_heap", "cut_sharing", "heap_slots", "heap_bytes_per_workgroup",
                            "heap_frozen_samples", "heap_paused_samples"}) {
        std::string quoted = "\"";
        quoted.append(key).append("\": ");
        EXPECT_THAT(json, HasSubstr(quoted));
    }
    EXPECT_THAT(json, HasSubstr("\"black_lights\": 3,"));
    EXPECT_THAT(json, HasSubstr("\"lights\": 20,"));
    EXPECT_THAT(json, HasSubstr("\"lights\": 7")) << "a device buffer replaces the scene array of its name";
    // Replaces, not joins: the JSON's map would hide a second entry.
    const auto named_lights = std::count_if(report.buffer_bytes.begin(), report.buffer_bytes.end(),
                                            [](const BufferBytes& b) { return b.name == "lights"; });
    EXPECT_EQ(named_lights, 1);
    EXPECT_THAT(json, HasSubstr("\"g-buffer\": 99"));
    EXPECT_THAT(json, HasSubstr("\"load\": 0.25"));
    // A float setting prints as it was written (it printed the float's
    // double, 0.019999999552965164).
    ASSERT_EQ(o.relative_error, 0.02f);
    EXPECT_THAT(json, HasSubstr("\"relative_error\": 0.02,"));
    EXPECT_THAT(report_text(report), HasSubstr("lights 20 (and 3 black, left out of the tree)"));
    EXPECT_THAT(report_text(report), HasSubstr("cut size mean"));
    EXPECT_THAT(json, HasSubstr("\"bounce_rays\": 0,"));
    // Cut sizes and the frozen share are of the pixels that shade a
    // surface: background pixels have no cut (they counted as 0, and the
    // sky's K table read "59.1% froze" where 99.99% of its shaded did).
    RenderResult background = r;
    ASSERT_EQ(background.stats.cut_size.size(), 64u);
    for (std::size_t i = 0; i < 64; ++i) background.stats.cut_size[i] = i < 16 ? 0.0f : 10.0f + float(i % 2);
    background.stats.heap_frozen_samples = 24;
    const RenderReport sky = make_report("room.json", o, p, background, 0.25);
    ASSERT_TRUE(sky.lightcuts.has_value());
    EXPECT_DOUBLE_EQ(sky.lightcuts->cut_size_mean, 10.5);
    EXPECT_EQ(sky.lightcuts->shaded_pixels, 48u);
    EXPECT_THAT(report_text(sky), HasSubstr("(over the 48 of 64 pixels that shade a surface)"));
    EXPECT_THAT(report_text(sky), HasSubstr("24 samples (50.00%) froze"));
    EXPECT_THAT(report_json(sky), HasSubstr("\"shaded_pixels\": 48"));
    EXPECT_THAT(report_text(report), Not(HasSubstr("pixels that shade a surface")));
    // Above 1 spp the cut sizes' percentiles are of each pixel's mean.
    RenderOptions two = o;
    two.spp = 2;
    EXPECT_THAT(report_text(make_report("room.json", two, p, render_cpu(p, two), 0.25)),
                HasSubstr("cut size (each pixel's mean over its 2 samples) mean"));
    // The CPU's default: octets share cuts, and the heap is an octet's.
    EXPECT_THAT(json, HasSubstr("\"cut_sharing\": \"octet\""));
    // A GPU's heaps are in shared or private memory; the CPU's are neither.
    EXPECT_THAT(json, HasSubstr("\"heap_memory\": \"cpu\""));
    EXPECT_THAT(report_text(report), HasSubstr("cuts shared by the eight pixels of each 4x2 octet"));
    EXPECT_THAT(report_text(report), HasSubstr("slots per octet"));
    RenderOptions quad = o;
    quad.cut_sharing = "quad";
    const RenderReport per_quad = make_report("room.json", quad, p, render_cpu(p, quad), 0.25);
    EXPECT_THAT(report_json(per_quad), HasSubstr("\"cut_sharing\": \"quad\""));
    EXPECT_THAT(report_text(per_quad), HasSubstr("cuts shared by the pixels of each 2x2 quad"));
    EXPECT_THAT(report_text(per_quad), HasSubstr("slots per quad"));
    RenderOptions pixel = o;
    pixel.cut_sharing = "pixel";
    const RenderReport per_pixel = make_report("room.json", pixel, p, render_cpu(p, pixel), 0.25);
    EXPECT_THAT(report_json(per_pixel), HasSubstr("\"cut_sharing\": \"pixel\""));
    EXPECT_THAT(report_text(per_pixel), Not(HasSubstr("2x2 quad")));
    EXPECT_THAT(report_text(per_pixel), Not(HasSubstr("octet")));
    EXPECT_THAT(report_text(per_pixel), HasSubstr("slots per point"));
}

// Sampled reports its light samples and pick; stochastic its cut and its
// draws per cluster (no pick: it always draws by intensity).
TEST(Report, StochasticMethodsReportTheirSampling) {
    Scene s = test::room_scene(test::random_point_lights(20, {-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 3), 4);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = test::options("sampled", 4);
    o.light_samples = 3;
    o.light_pick = "power";
    RenderReport report = make_report("room.json", o, p, render_cpu(p, o), 0.0);
    EXPECT_FALSE(report.lightcuts.has_value());
    EXPECT_THAT(report_json(report), HasSubstr("\"light_samples\": 3"));
    EXPECT_THAT(report_json(report), HasSubstr("\"light_pick\": \"power\""));
    EXPECT_THAT(report_text(report), HasSubstr("3 light sample(s) per camera sample, picked by power"));
    o.method = "stochastic";
    report = make_report("room.json", o, p, render_cpu(p, o), 0.0);
    EXPECT_TRUE(report.lightcuts.has_value());
    EXPECT_THAT(report_json(report), HasSubstr("\"light_samples\": 3"));
    EXPECT_THAT(report_json(report), Not(HasSubstr("\"light_pick\"")));
    EXPECT_THAT(report_text(report), HasSubstr("3 fresh representative(s) per cluster of the cut"));
    // The path tracer: its paths along each camera ray and its time limit,
    // without which spp 1 x 4 and spp 4 x 1 would read the same.
    o.method = "path";
    o.spp = 1;
    o.light_samples = 4;
    o.time_limit = 2.5f;
    report = make_report("room.json", o, p, render_cpu(p, o), 0.0);
    EXPECT_THAT(report_json(report), HasSubstr("\"light_samples\": 4"));
    EXPECT_THAT(report_json(report), HasSubstr("\"time_limit\": 2.5"));
    EXPECT_THAT(report_text(report), HasSubstr("4 path(s) per pixel (4 along each camera ray)"));
    EXPECT_THAT(report_text(report), Not(HasSubstr("light sample(s) per camera sample")));
    // Stopped by the time limit, it says what was traced, not what was
    // asked for (before: "3 path(s) per pixel (4 along each camera ray)").
    report.spp = 3;
    EXPECT_THAT(report_text(report), HasSubstr("stopped at the time limit after 3 of 4 spp"));
    EXPECT_THAT(report_text(report), HasSubstr("3 path(s) per pixel (3 along each camera ray)"));
    report.spp_requested = 8;  // two camera rays of 4 paths each, stopped after 5 paths
    report.spp = 5;
    EXPECT_THAT(report_text(report), HasSubstr("5 path(s) per pixel (2 or 3 along each of 2 camera rays)"));
    // Stopped before every camera ray had a path (before: "0 or 1 along each").
    report.spp_requested = 4096 * 16;  // 4096 camera rays of 16 paths
    report.sampling->light_samples = 16;
    report.spp = 1;
    EXPECT_THAT(report_text(report), HasSubstr("1 path(s) per pixel (one along each of 1 of the 4096 camera rays)"));
}

TEST(Report, BruteForceHasNoLightcutsPart) {
    Scene s = test::room_scene({test::point_light({0.0f, 1.5f, 0.0f}, glm::vec3(1.0f))}, 4);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    const RenderOptions o = test::options("brute", 4);
    const RenderReport report = make_report("room.json", o, p, render_cpu(p, o), 0.0);
    EXPECT_FALSE(report.lightcuts.has_value());
    EXPECT_THAT(report_json(report), Not(HasSubstr("\"lightcuts\"")));
    EXPECT_THAT(report_json(report), HasSubstr("\"black_lights\": 0,"));
    EXPECT_THAT(report_text(report), Not(HasSubstr("black")));
    EXPECT_THAT(report_text(report), Not(HasSubstr("cut size")));
}

// docs/stats.md names every key the JSON can hold: the keys of reports of
// every shape (lightcuts with VPLs, sampled, path), scene arrays aside
// (buffer_bytes' names are the kernels', listed by info).
TEST(Report, DocsNameEveryJsonKey) {
    std::ifstream in(LC_SOURCE_DIR "/docs/stats.md");
    ASSERT_TRUE(in) << "docs/stats.md";
    const std::string docs((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Scene s = test::room_scene(test::random_point_lights(20, {-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 3), 4);
    s.render.indirect.vpls = 16;
    const PreparedScene p = prepare_scene(std::move(s), 1);
    std::vector<std::string> missing;
    for (const char* method : {"lightcuts", "sampled", "path"}) {
        const RenderOptions o = test::options(method, 4);
        const nlohmann::json j = nlohmann::json::parse(report_json(make_report("room.json", o, p, render_cpu(p, o), 0.0)));
        std::vector<std::pair<std::string, const nlohmann::json*>> todo{{"", &j}};
        while (!todo.empty()) {
            const auto [parent, object] = todo.back();
            todo.pop_back();
            for (const auto& [key, value] : object->items()) {
                if (docs.find("`" + key + "`") == std::string::npos) missing.push_back(parent + key);
                if (value.is_object() && key != "buffer_bytes") todo.push_back({parent + key + ".", &value});
            }
        }
    }
    EXPECT_THAT(missing, ::testing::IsEmpty());
}

// info and the report list the same arrays: the ones the kernels read.
TEST(Report, BufferTableListsTheKernelsArraysAndTheirTotal) {
    const PreparedScene p = room_with_black_lights();
    const std::vector<BufferBytes> buffers = scene_buffer_bytes(p);
    // Each array by name, at the size of the data the kernels read.
    const std::vector<std::pair<std::string, std::uint64_t>> expected = {
        {"bvh_nodes", p.bvh.nodes.size() * sizeof(p.bvh.nodes[0])},
        {"triangles", p.scene.triangles.size() * sizeof(gpu::Triangle)},
        {"normals", p.scene.normals.size() * sizeof(gpu::TriangleNormals)},
        {"uvs", p.scene.uvs.size() * sizeof(p.scene.uvs[0])},
        {"materials", p.scene.materials.size() * sizeof(gpu::Material)},
        {"textures", p.scene.textures.size() * sizeof(gpu::TextureInfo)},
        {"texels", p.scene.texels.size() * sizeof(std::uint32_t)},
        {"lights", p.tree.lights.size() * sizeof(gpu::Light)},
        {"light_tree_nodes", p.tree.nodes.size() * sizeof(gpu::LightNode)},
        {"environment", p.scene.environment.rgb.size() * sizeof(p.scene.environment.rgb[0])},
        {"wide_bvh_nodes", p.bvh.kernel_nodes.size() * sizeof(gpu::Bvh4Node)}};
    ASSERT_EQ(buffers.size(), expected.size());
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(buffers[i].name, expected[i].first);
        EXPECT_EQ(buffers[i].bytes, expected[i].second) << expected[i].first;
        total += buffers[i].bytes;
    }
    EXPECT_EQ(buffers[7].bytes, 20u * sizeof(gpu::Light)) << "the 20 lights the tree keeps, not the 3 black ones";
    EXPECT_GT(buffers[8].bytes, 0u);
    const std::string table = buffer_table({{"a", 512}, {"b", 2048}, {"c", 3u << 20}, {"d", 5ull << 29}});
    EXPECT_THAT(table, HasSubstr("a                  512 B\n"));
    EXPECT_THAT(table, HasSubstr("b                  2.0 KiB\n"));
    EXPECT_THAT(table, HasSubstr("c                  3.0 MiB\n"));
    EXPECT_THAT(table, HasSubstr("d                  2.50 GiB\n"));
    EXPECT_THAT(table, HasSubstr("total              2.50 GiB\n"));
    EXPECT_GT(total, 0u);
}

}  // namespace
}  // namespace lc
