// lightcuts: the command-line renderer.
//   lightcuts render SCENE -o OUT.exr [options]   render to EXR (+ PNG preview)
//   lightcuts compare IMAGE REFERENCE [--heatmap]  error metrics between two EXRs
//   lightcuts info SCENE                           what a scene holds
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <optional>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "lightcuts/render.h"
#include "lightcuts/scene.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct RenderArgs {
    std::string scene, output, method, device = "auto", gpu, stats_file, cut_heatmap;
    std::optional<std::uint32_t> spp, width, height, max_cut, seed;
    std::optional<float> relative_error;
    unsigned threads = 0;
    bool validation = false;
    bool no_png = false;
};

double percentile(std::vector<float> v, double p) {
    if (v.empty()) return 0.0;
    auto k = static_cast<std::size_t>(std::min<double>(double(v.size() - 1), std::ceil(p * double(v.size())) - 1));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

std::string human_bytes(std::uint64_t b) {
    char buf[64];
    if (b >= (1ull << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / double(1 << 20));
    else if (b >= 1024) std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024.0);
    else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(b));
    return buf;
}

// Memory of the buffers both renderers read.
std::vector<std::pair<std::string, std::uint64_t>> scene_buffers(const lc::PreparedScene& p) {
    return {
        {"bvh_nodes", p.bvh.nodes.size() * sizeof(lc::gpu::BvhNode)},
        {"triangles", p.scene.triangles.size() * sizeof(lc::gpu::Triangle)},
        {"normals", p.scene.normals.size() * sizeof(lc::gpu::TriangleNormals)},
        {"materials", p.scene.materials.size() * sizeof(lc::gpu::Material)},
        {"lights", p.tree.lights.size() * sizeof(lc::gpu::Light)},
        {"light_tree_nodes", p.tree.nodes.size() * sizeof(lc::gpu::LightNode)},
    };
}

void write_json_atomically(const fs::path& file, const json& j) {
    fs::path tmp = file;
    tmp += ".tmp";
    {
        std::ofstream out(tmp);
        if (!out) throw std::runtime_error(file.string() + ": cannot open for writing");
        out << j.dump(2) << "\n";
        if (!out) throw std::runtime_error(file.string() + ": write failed");
    }
    fs::rename(tmp, file);
}

// Fails before the render, not after it, when an output cannot be written.
void check_output_folder(const std::string& file, const char* what) {
    if (file.empty()) return;
    fs::path folder = fs::path(file).parent_path();
    if (folder.empty()) folder = ".";
    if (!fs::is_directory(folder))
        throw std::runtime_error(std::string(what) + " " + file + ": folder " + folder.string() + " does not exist");
}

int run_render(const RenderArgs& a) {
    check_output_folder(a.output, "output");
    check_output_folder(a.stats_file, "--stats");
    check_output_folder(a.cut_heatmap, "--cut-heatmap");
    if (fs::path(a.output).extension() != ".exr")
        throw std::invalid_argument("output " + a.output + ": must end in .exr");
    auto t_load = std::chrono::steady_clock::now();
    lc::Scene scene = lc::load_scene(a.scene);
    double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();
    if (scene.degenerate_triangles_dropped)
        std::fprintf(stderr, "warning: %s: dropped %zu degenerate triangles\n", a.scene.c_str(),
                     scene.degenerate_triangles_dropped);

    lc::RenderOptions o;
    o.method = a.method.empty() ? scene.render.method : a.method;
    o.spp = a.spp.value_or(scene.render.spp);
    o.relative_error = a.relative_error.value_or(scene.render.relative_error);
    o.max_cut = a.max_cut.value_or(scene.render.max_cut);
    o.seed = a.seed.value_or(scene.render.seed);
    o.width = a.width.value_or(scene.camera.width);
    o.height = a.height.value_or(scene.camera.height);
    o.threads = a.threads;
    o.progress = true;

    lc::PreparedScene prepared = lc::prepare_scene(std::move(scene), o.seed);

    lc::RenderResult result;
    // auto: a GPU if there is one (or the one --gpu names); with only a
    // software Vulkan device (lavapipe) the CPU path is the faster of the two.
    if (a.device == "auto" && a.gpu.empty() && !lc::vulkan_hardware_device_present()) {
        if (!lc::list_vulkan_devices().empty())
            std::fprintf(stderr, "note: only a software Vulkan device is present; rendering on the CPU "
                                 "(--device vulkan uses it anyway)\n");
        else
            std::fprintf(stderr, "warning: no Vulkan device; rendering on the CPU\n");
        result = lc::render_cpu(prepared, o);
    } else if (a.device == "auto") {
        try {
            result = lc::render_vulkan(prepared, o, lc::VulkanOptions{a.gpu, a.validation});
        } catch (const lc::NoVulkanDevice& e) {
            std::fprintf(stderr, "warning: %s; rendering on the CPU\n", e.what());
            result = lc::render_cpu(prepared, o);
        }
    } else if (a.device == "vulkan") {
        result = lc::render_vulkan(prepared, o, lc::VulkanOptions{a.gpu, a.validation});
    } else {
        result = lc::render_cpu(prepared, o);
    }
    const lc::RenderStats& s = result.stats;

    fs::path out(a.output);
    lc::write_exr(out, result.image);
    if (!a.no_png) lc::write_png_tonemapped(fs::path(out).replace_extension(".png"), result.image);

    std::uint64_t pixels = std::uint64_t(result.image.width) * result.image.height;
    double rays = double(s.camera_rays + s.shadow_rays);
    std::printf("%s: %ux%u, %u spp, %s on %s\n", a.scene.c_str(), result.image.width, result.image.height,
                o.spp, o.method.c_str(), s.device.c_str());
    std::printf("  triangles %zu, lights %zu, BVH %zu nodes built in %.3f s\n",
                prepared.scene.triangles.size(), prepared.tree.lights.size(), prepared.bvh.nodes.size(),
                prepared.bvh.build_seconds);
    std::printf("  render %.3f s, %.0f rays (%.2f Mrays/s), %.1f shadow rays per pixel\n", s.seconds_total,
                rays, rays / std::max(s.seconds_total, 1e-9) * 1e-6, double(s.shadow_rays) / double(pixels));

    json stats = {
        {"scene", a.scene},
        {"method", o.method},
        {"device", s.device},
        {"width", result.image.width},
        {"height", result.image.height},
        {"spp", o.spp},
        {"triangles", prepared.scene.triangles.size()},
        {"lights", prepared.tree.lights.size()},
        {"seconds", {{"load", load_seconds},
                     {"bvh_build", prepared.bvh.build_seconds},
                     {"light_tree_build", prepared.tree.build_seconds},
                     {"render", s.seconds_total},
                     {"primary", s.seconds_primary},
                     {"shading", s.seconds_shading}}},
        {"camera_rays", s.camera_rays},
        {"shadow_rays", s.shadow_rays},
        {"shadow_rays_per_pixel", double(s.shadow_rays) / double(pixels)},
        {"rays_per_second", rays / std::max(s.seconds_total, 1e-9)},
    };
    json buffers = json::object();
    for (const auto& [name, bytes] : scene_buffers(prepared)) buffers[name] = bytes;
    for (const auto& [name, bytes] : s.buffer_bytes) buffers[name] = bytes;
    stats["buffer_bytes"] = buffers;

    if (o.method == "lightcuts") {
        double mean = s.cut_size.empty() ? 0.0
                                         : std::accumulate(s.cut_size.begin(), s.cut_size.end(), 0.0) /
                                               double(s.cut_size.size());
        double p50 = percentile(s.cut_size, 0.5), p99 = percentile(s.cut_size, 0.99);
        double max = s.cut_size.empty() ? 0.0 : *std::max_element(s.cut_size.begin(), s.cut_size.end());
        std::printf("  light tree %zu nodes (%s) built in %.3f s\n", prepared.tree.nodes.size(),
                    human_bytes(prepared.tree.nodes.size() * sizeof(lc::gpu::LightNode)).c_str(),
                    prepared.tree.build_seconds);
        std::printf("  cut size mean %.1f, p50 %.0f, p99 %.0f, max %.0f; %llu samples hit max_cut %u\n", mean, p50,
                    p99, max, static_cast<unsigned long long>(s.max_cut_pixels), o.max_cut);
        if (s.device != "cpu")
            std::printf("  cut heap: %u slots per pixel in shared memory; %llu samples spilled to global memory\n",
                        s.heap_capacity_shared, static_cast<unsigned long long>(s.heap_spill_pixels));
        stats["lightcuts"] = {{"relative_error", o.relative_error},
                              {"max_cut", o.max_cut},
                              {"tree_nodes", prepared.tree.nodes.size()},
                              {"tree_bytes", prepared.tree.nodes.size() * sizeof(lc::gpu::LightNode)},
                              {"cut_size_mean", mean},
                              {"cut_size_p50", p50},
                              {"cut_size_p99", p99},
                              {"cut_size_max", max},
                              {"max_cut_samples", s.max_cut_pixels},
                              {"heap_capacity_shared", s.heap_capacity_shared},
                              {"heap_spill_samples", s.heap_spill_pixels}};
        if (!a.cut_heatmap.empty()) {
            float scale = float(std::max(1.0, max));
            lc::write_heatmap_png(a.cut_heatmap, result.image.width, result.image.height, s.cut_size, scale);
        }
    } else if (!a.cut_heatmap.empty()) {
        throw std::invalid_argument("--cut-heatmap needs --method lightcuts");
    }
    if (!a.stats_file.empty()) write_json_atomically(a.stats_file, stats);
    return 0;
}

int run_compare(const std::string& image, const std::string& reference, const std::string& heatmap,
                bool as_json) {
    lc::Image a = lc::read_exr(image);
    lc::Image r = lc::read_exr(reference);
    if (a.width != r.width || a.height != r.height)
        throw lc::InputError(image, "", "size " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                            " differs from the reference's " + std::to_string(r.width) + "x" +
                                            std::to_string(r.height));
    lc::CompareResult c = lc::compare_images(a, r);
    if (as_json) {
        json j = {{"relative_rmse", c.relative_rmse},
                  {"fraction_above_1pct", c.fraction_above_1pct},
                  {"fraction_above_2pct", c.fraction_above_2pct},
                  {"fraction_above_5pct", c.fraction_above_5pct},
                  {"max_relative_error", c.max_relative_error}};
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("relative RMSE        %.6g\n", c.relative_rmse);
        std::printf("pixels above 1%%      %.4f%%\n", 100.0 * c.fraction_above_1pct);
        std::printf("pixels above 2%%      %.4f%%\n", 100.0 * c.fraction_above_2pct);
        std::printf("pixels above 5%%      %.4f%%\n", 100.0 * c.fraction_above_5pct);
        std::printf("max relative error   %.6g\n", c.max_relative_error);
    }
    // The heatmap's scale runs from 0 to 10% relative luminance error.
    if (!heatmap.empty()) lc::write_heatmap_png(heatmap, a.width, a.height, c.per_pixel, 0.1f);
    return 0;
}

int run_info(const std::string& file) {
    lc::Scene scene = lc::load_scene(file);
    std::printf("%s\n", file.c_str());
    std::printf("  triangles          %zu (%zu degenerate dropped)\n", scene.triangles.size(),
                scene.degenerate_triangles_dropped);
    std::printf("  materials          %zu\n", scene.materials.size());
    std::printf("  point lights       %zu\n", scene.count_lights(lc::gpu::kLightPoint));
    std::printf("  directional lights %zu\n", scene.count_lights(lc::gpu::kLightDirectional));
    std::printf("  bounds             [%g %g %g] - [%g %g %g]\n", scene.bounds_min.x, scene.bounds_min.y,
                scene.bounds_min.z, scene.bounds_max.x, scene.bounds_max.y, scene.bounds_max.z);
    std::printf("  image              %ux%u\n", scene.camera.width, scene.camera.height);
    lc::PreparedScene prepared = lc::prepare_scene(std::move(scene), 1);
    std::printf("  buffers:\n");
    std::uint64_t total = 0;
    for (const auto& [name, bytes] : scene_buffers(prepared)) {
        std::printf("    %-18s %s\n", name.c_str(), human_bytes(bytes).c_str());
        total += bytes;
    }
    std::printf("    %-18s %s\n", "total", human_bytes(total).c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"lightcuts: many-light rendering with Lightcuts on the CPU and Vulkan compute"};
    app.require_subcommand(1);

    RenderArgs r;
    auto* render = app.add_subcommand("render", "Render a scene to a linear OpenEXR image and a PNG preview");
    render->add_option("scene", r.scene, "Scene file (JSON)")->required();
    render->add_option("-o,--output", r.output, "Output .exr (a tone-mapped .png is written beside it)")->required();
    render->add_option("--method", r.method, "brute (exact) or lightcuts")->check(CLI::IsMember({"brute", "lightcuts"}));
    render->add_option("--spp", r.spp, "Camera rays per pixel")->check(CLI::Range(1u, 1u << 16));
    render->add_option("--width", r.width, "Image width")->check(CLI::Range(1u, 16384u));
    render->add_option("--height", r.height, "Image height")->check(CLI::Range(1u, 16384u));
    render->add_option("--error", r.relative_error, "Lightcuts relative error threshold (default 0.02)")
        ->check(CLI::Range(0.0f, 1.0f));
    render->add_option("--max-cut", r.max_cut, "Lightcuts largest cut (default 1000)")->check(CLI::Range(1u, 1u << 20));
    render->add_option("--seed", r.seed, "Seed for pixel jitter and light-tree representatives");
    render->add_option("--threads", r.threads, "CPU threads (0 = all cores)");
    render->add_option("--device", r.device, "auto (a hardware GPU through Vulkan, else the CPU path), cpu or vulkan")
        ->check(CLI::IsMember({"auto", "cpu", "vulkan"}));
    render->add_option("--gpu", r.gpu, "Vulkan device index or name substring");
    render->add_flag("--validation", r.validation, "Enable the Vulkan validation layer");
    render->add_option("--stats", r.stats_file, "Write statistics as JSON");
    render->add_option("--cut-heatmap", r.cut_heatmap, "Write per-pixel cut size as a false-colour PNG");
    render->add_flag("--no-png", r.no_png, "Do not write the PNG preview");

    std::string cmp_image, cmp_ref, cmp_heatmap;
    bool cmp_json = false;
    auto* compare = app.add_subcommand("compare", "Error metrics of an EXR image against a reference EXR");
    compare->add_option("image", cmp_image, "Image (EXR)")->required();
    compare->add_option("reference", cmp_ref, "Reference (EXR)")->required();
    compare->add_option("--heatmap", cmp_heatmap, "Write per-pixel relative error as a PNG (scale 0 to 10%)");
    compare->add_flag("--json", cmp_json, "Print the metrics as JSON");

    std::string info_scene;
    auto* info = app.add_subcommand("info", "Print what a scene holds and the memory it needs");
    info->add_option("scene", info_scene, "Scene file (JSON)")->required();

    CLI11_PARSE(app, argc, argv);
    try {
        if (*render) return run_render(r);
        if (*compare) return run_compare(cmp_image, cmp_ref, cmp_heatmap, cmp_json);
        if (*info) return run_info(info_scene);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 1;
}
