// One record of a render, printed for people and written as JSON
// (include/lightcuts/report.h).
#include "lightcuts/report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <nlohmann/json.hpp>

namespace lc {

namespace {

// A setting held as float, as the double that prints as the float does
// (0.02, not 0.019999999552965164): the shortest decimal that reads back as
// the same float.
double as_written(float v) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof(text), v).ptr;
    double d = 0.0;
    std::from_chars(text, end, d);
    return d;
}

using nlohmann::json;

// Nearest-rank percentile, p in [0, 1].
double percentile(std::vector<float> v, double p) {
    if (v.empty()) return 0.0;
    const auto k = static_cast<std::size_t>(
        std::min<double>(double(v.size() - 1), std::ceil(p * double(v.size())) - 1));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

std::string human_bytes(std::uint64_t b) {
    char buf[64];
    if (b >= (1ull << 30)) std::snprintf(buf, sizeof buf, "%.2f GiB", double(b) / double(1ull << 30));
    else if (b >= (1ull << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / double(1 << 20));
    else if (b >= 1024) std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024.0);
    else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(b));
    return buf;
}

// printf into a std::string.
template <class... Args>
std::string format(const char* fmt, Args... args) {
    const int n = std::snprintf(nullptr, 0, fmt, args...);
    std::string s(std::size_t(std::max(n, 0)), '\0');
    std::snprintf(s.data(), s.size() + 1, fmt, args...);
    return s;
}

LightcutsReport lightcuts_report(const RenderOptions& o, const PreparedScene& p, const RenderStats& s) {
    LightcutsReport l;
    l.relative_error = o.relative_error;
    l.max_cut = o.max_cut;
    l.tree_nodes = p.tree.nodes.size();
    l.tree_bytes = p.tree.nodes.size() * sizeof(gpu::LightNode);
    // Over the pixels that shade a surface (a cut of at least the root):
    // those that see only the background have none, and counting them as
    // 0 made the sky's mean cut and frozen share a pixel-count average.
    std::vector<float> cuts;
    cuts.reserve(s.cut_size.size());
    for (const float c : s.cut_size)
        if (c > 0.0f) cuts.push_back(c);
    l.shaded_pixels = cuts.size();
    if (!cuts.empty()) {
        l.cut_size_mean = std::accumulate(cuts.begin(), cuts.end(), 0.0) / double(cuts.size());
        l.cut_size_max = *std::max_element(cuts.begin(), cuts.end());
    }
    l.cut_size_p50 = percentile(cuts, 0.5);
    l.cut_size_p99 = percentile(cuts, 0.99);
    l.max_cut_samples = s.max_cut_pixels;
    const double samples = double(cuts.size()) * std::max(s.spp_done, 1u);
    l.cut_indirect_mean = samples > 0.0 ? double(s.cut_indirect_total) / samples : 0.0;
    l.cut_heap = o.cut_heap;
    l.cut_points = s.cut_points;
    l.heap_slots = s.heap_slots;
    l.heap_bytes = s.heap_shared_bytes;
    l.heap_private = s.heap_private;
    l.workgroup_size = s.workgroup_size;
    l.heap_frozen_samples = s.heap_frozen_samples;
    l.heap_paused_samples = s.heap_paused_samples;
    return l;
}

std::string lightcuts_text(const RenderReport& r, const LightcutsReport& l) {
    std::string text = format("  light tree %zu nodes (%s) built in %.3f s\n", l.tree_nodes,
                              human_bytes(l.tree_bytes).c_str(), r.seconds.light_tree_build);
    // Above 1 spp the percentiles and the largest are of each pixel's mean
    // cut, which can stay below max_cut while samples reach it.
    const std::string per_pixel = r.spp > 1 ? format(" (each pixel's mean over its %u samples)", r.spp) : "";
    const std::uint64_t pixels = std::uint64_t(r.width) * r.height;
    const std::string over = l.shaded_pixels < pixels
                                 ? format(" (over the %zu of %llu pixels that shade a surface)", l.shaded_pixels,
                                          static_cast<unsigned long long>(pixels))
                                 : "";
    text += format("  cut size%s mean %.1f, p50 %.0f, p99 %.0f, max %.0f%s; %llu samples hit max_cut %u\n",
                   per_pixel.c_str(), l.cut_size_mean, l.cut_size_p50, l.cut_size_p99, l.cut_size_max, over.c_str(),
                   static_cast<unsigned long long>(l.max_cut_samples), l.max_cut);
    if (r.indirect)
        text += format("  of the cut: %.1f direct, %.1f indirect (VPL) clusters on average\n",
                       l.cut_size_mean - l.cut_indirect_mean, l.cut_indirect_mean);
    // The shares below are of the samples of pixels that shade a surface.
    const double samples = double(std::max<std::uint64_t>(l.shaded_pixels * std::max(r.spp, 1u), 1));
    const char* const shared_by = l.cut_points == 8u ? "octet" : l.cut_points == 4u ? "quad" : "point";
    if (l.cut_points == 4u) text += "  cuts shared by the pixels of each 2x2 quad (cut_sharing)\n";
    if (l.cut_points == 8u) text += "  cuts shared by the eight pixels of each 4x2 octet (cut_sharing)\n";
    text += format("  cut heap: %u slots per %s (cut_heap %u); %llu samples (%.2f%%) froze clusters out of a full "
                   "heap\n",
                   l.heap_slots, shared_by, l.cut_heap, static_cast<unsigned long long>(l.heap_frozen_samples),
                   100.0 * double(l.heap_frozen_samples) / samples);
    if (r.device != "cpu") {
        const std::string where =
            l.heap_private ? format("cut heap in private memory: %s per invocation",
                                    human_bytes(std::uint64_t(l.heap_slots) * (l.cut_points == 4u ? sizeof(gpu::QuadCutEntry)
                                                                                : sizeof(gpu::CutEntry))).c_str())
                           : format("cut heap in shared memory: %s per workgroup of %u",
                                    human_bytes(l.heap_bytes).c_str(), l.workgroup_size);
        text += format("  %s; %llu samples (%.2f%%) paused it in global memory between dispatches\n", where.c_str(),
                       static_cast<unsigned long long>(l.heap_paused_samples),
                       100.0 * double(l.heap_paused_samples) / samples);
    }
    return text;
}

// heap_memory: where a GPU's kernels keep the heap; the CPU path's heaps
// are each worker thread's own ("cpu").
json lightcuts_json(const LightcutsReport& l, bool on_cpu) {
    return {{"relative_error", as_written(l.relative_error)},
            {"max_cut", l.max_cut},
            {"tree_nodes", l.tree_nodes},
            {"tree_bytes", l.tree_bytes},
            {"cut_size_mean", l.cut_size_mean},
            {"cut_indirect_mean", l.cut_indirect_mean},
            {"cut_size_p50", l.cut_size_p50},
            {"cut_size_p99", l.cut_size_p99},
            {"cut_size_max", l.cut_size_max},
            {"max_cut_samples", l.max_cut_samples},
            {"cut_heap", l.cut_heap},
            {"cut_sharing", l.cut_points == 8u ? "octet" : l.cut_points == 4u ? "quad" : "pixel"},
            {"heap_slots", l.heap_slots},
            {"heap_bytes_per_workgroup", l.heap_bytes},
            {"heap_memory", on_cpu ? "cpu" : l.heap_private ? "private" : "shared"},
            {"heap_frozen_samples", l.heap_frozen_samples},
            {"heap_paused_samples", l.heap_paused_samples},
            {"shaded_pixels", l.shaded_pixels}};
}

}  // namespace

std::vector<BufferBytes> scene_buffer_bytes(const PreparedScene& prepared) {
    std::vector<BufferBytes> buffers;
    for (const SceneArray& a : scene_arrays(prepared)) buffers.push_back({a.name, a.bytes()});
    return buffers;
}

RenderReport make_report(const std::string& scene_file, const RenderOptions& options,
                         const PreparedScene& prepared, const RenderResult& result, double load_seconds) {
    const RenderStats& s = result.stats;
    RenderReport r;
    r.scene = scene_file;
    r.method = options.method;
    r.device = s.device;
    r.width = result.image.width;
    r.height = result.image.height;
    r.spp = s.spp_done ? s.spp_done : options.spp;
    // The path tracer's samples are paths: light_samples along each camera ray.
    r.spp_requested = options.method == "path" ? options.spp * options.light_samples : options.spp;
    if (options.method == "path") {
        r.max_bounces = options.max_bounces;
        r.time_limit = options.time_limit;
        // light_samples paths along each camera ray (spp x light_samples paths a pixel)
        r.sampling = SamplingReport{options.light_samples, ""};
    }
    r.triangles = prepared.scene.triangles.size();
    r.lights = prepared.tree.lights.size();
    r.emissive_triangles = prepared.scene.count_emissive_triangles();
    r.environment_map = prepared.scene.environment.width > 0;
    r.bvh_nodes = prepared.bvh.nodes.size();
    r.black_lights = prepared.tree.black_lights;
    r.area_lights = prepared.area_lights;
    r.environment_lights = prepared.environment_lights;
    r.seconds.load = load_seconds;
    r.seconds.bvh_build = prepared.bvh.build_seconds;
    r.seconds.light_tree_build = prepared.tree.build_seconds;
    r.seconds.light_sampling = prepared.light_sampling_seconds;
    r.seconds.vpls = prepared.vpl_seconds;
    // Also where the paths left none (they all escaped, or met only black
    // surfaces): the report says so rather than nothing.
    if (prepared.scene.render.indirect.vpls > 0 && options.method != "path")
        r.indirect = IndirectReport{prepared.vpls, prepared.vpl_paths,
                                    prepared.scene.render.indirect.max_bounces, prepared.scene.render.indirect.clamp};
    r.seconds.render = s.seconds_total;
    r.seconds.primary = s.seconds_primary;
    r.seconds.shading = s.seconds_shading;
    r.camera_rays = s.camera_rays;
    r.shadow_rays = s.shadow_rays;
    r.bounce_rays = s.bounce_rays;
    const double pixels = double(r.width) * double(r.height);
    r.shadow_rays_per_pixel = pixels > 0.0 ? double(s.shadow_rays) / pixels : 0.0;
    r.rays_per_second = double(s.camera_rays + s.shadow_rays + s.bounce_rays) / std::max(s.seconds_total, 1e-9);
    r.loop_limit_retries = s.loop_limit_retries;
    r.work_splits = s.work_splits;
    r.buffer_bytes = scene_buffer_bytes(prepared);
    for (const auto& [name, bytes] : s.buffer_bytes) {
        auto same = std::find_if(r.buffer_bytes.begin(), r.buffer_bytes.end(),
                                 [&](const BufferBytes& b) { return b.name == name; });
        if (same != r.buffer_bytes.end()) same->bytes = bytes;
        else r.buffer_bytes.push_back({name, bytes});
    }
    if (method_selects_cuts(options.method)) r.lightcuts = lightcuts_report(options, prepared, s);
    if (options.method == "sampled") r.sampling = SamplingReport{options.light_samples, options.light_pick};
    if (options.method == "stochastic") r.sampling = SamplingReport{options.light_samples, ""};
    r.seed = options.seed;
    return r;
}

std::string report_text(const RenderReport& r) {
    std::string text = format("%s: %ux%u, %u spp, %s on %s\n", r.scene.c_str(), r.width, r.height, r.spp,
                              r.method.c_str(), r.device.c_str());
    if (r.spp != r.spp_requested)
        text += format("  stopped at the time limit after %u of %u spp\n", r.spp, r.spp_requested);
    if (r.method == "path") {
        // What was traced: a render stopped at its time limit has fewer
        // paths along each camera ray than asked for (paths go round the
        // camera rays, so some may have one more).
        const std::uint32_t along = r.sampling ? r.sampling->light_samples : 1u;
        const std::uint32_t camera_rays = std::max(1u, r.spp_requested / std::max(along, 1u));
        const std::uint32_t done = r.spp / camera_rays;
        const std::string split =
            along <= 1                   ? std::string()
            : r.spp % camera_rays == 0u ? format(" (%u along each camera ray)", done)
            : done == 0u                ? format(" (one along each of %u of the %u camera rays)", r.spp, camera_rays)
                                        : format(" (%u or %u along each of %u camera rays)", done, done + 1, camera_rays);
        text += format("  %u path(s) per pixel%s, %s\n", r.spp, split.c_str(),
                       r.max_bounces ? format("at most %u bounce(s)", r.max_bounces).c_str()
                                     : "of any length (Russian roulette)");
    }
    const std::string black =
        r.black_lights ? format(" (and %zu black, left out of the tree)", r.black_lights) : std::string();
    // The path tracer's lights are the scene's own; it samples the emissive
    // triangles and the environment map themselves, so they are named here.
    const std::string emissive =
        r.emissive_triangles ? format(" (%zu emissive)", r.emissive_triangles) : std::string();
    const char* environment = r.method == "path" && r.environment_map ? ", an environment map" : "";
    text += format("  triangles %zu%s, lights %zu%s%s, BVH %zu nodes built in %.3f s\n", r.triangles,
                   emissive.c_str(), r.lights, black.c_str(), environment, r.bvh_nodes, r.seconds.bvh_build);
    if (r.area_lights || r.environment_lights)
        text += format("  sampled: %zu area-light samples, %zu environment directions (%.3f s)%s\n", r.area_lights,
                       r.environment_lights, r.seconds.light_sampling,
                       r.black_lights ? ", the black among them left out as above" : "");
    if (r.indirect)
        text += format("  and %zu VPLs from %zu light paths (max_bounces %u, clamp %g) traced in %.3f s\n",
                       r.indirect->vpls, r.indirect->paths, r.indirect->max_bounces, double(r.indirect->clamp),
                       r.seconds.vpls);
    text += format("  render %.3f s, %.0f rays (%.2f Mrays/s), %.1f shadow rays per pixel\n", r.seconds.render,
                   double(r.camera_rays + r.shadow_rays + r.bounce_rays), r.rays_per_second * 1e-6,
                   r.shadow_rays_per_pixel);
    if (r.bounce_rays)
        text += format("  of the rays: %.0f camera, %.0f shadow, %.0f after a bounce\n", double(r.camera_rays),
                       double(r.shadow_rays), double(r.bounce_rays));
    if (r.loop_limit_retries)
        text += format("  tiles rendered again %u time(s) with the work split finer (the driver cut long loops short)\n",
                       r.loop_limit_retries);
    if (r.work_splits)
        text += format("  each pixel's work split %u time(s) over more dispatches (tiles of the smallest size "
                       "took over 4 times the target)\n",
                       r.work_splits);
    if (r.lightcuts) text += lightcuts_text(r, *r.lightcuts);
    if (r.sampling && r.method == "stochastic")
        text += format("  %u fresh representative(s) per cluster of the cut\n", r.sampling->light_samples);
    else if (r.sampling && r.method == "sampled")
        text += format("  %u light sample(s) per camera sample, picked by %s\n", r.sampling->light_samples,
                       r.sampling->light_pick.c_str());
    return text;
}

std::string report_json(const RenderReport& r) {
    json buffers = json::object();
    for (const BufferBytes& b : r.buffer_bytes) buffers[b.name] = b.bytes;
    json j = {
        {"scene", r.scene},
        {"method", r.method},
        {"device", r.device},
        {"width", r.width},
        {"height", r.height},
        {"spp", r.spp},
        {"spp_requested", r.spp_requested},
        {"seed", r.seed},
        {"triangles", r.triangles},
        {"lights", r.lights},
        {"black_lights", r.black_lights},
        {"area_lights", r.area_lights},
        {"environment_lights", r.environment_lights},
        {"emissive_triangles", r.emissive_triangles},
        {"environment_map", r.environment_map},
        {"seconds", {{"load", r.seconds.load},
                     {"bvh_build", r.seconds.bvh_build},
                     {"light_tree_build", r.seconds.light_tree_build},
                     {"light_sampling", r.seconds.light_sampling},
                     {"vpls", r.seconds.vpls},
                     {"render", r.seconds.render},
                     {"primary", r.seconds.primary},
                     {"shading", r.seconds.shading}}},
        {"camera_rays", r.camera_rays},
        {"shadow_rays", r.shadow_rays},
        {"bounce_rays", r.bounce_rays},
        {"shadow_rays_per_pixel", r.shadow_rays_per_pixel},
        {"rays_per_second", r.rays_per_second},
        {"loop_limit_retries", r.loop_limit_retries},
        {"work_splits", r.work_splits},
        {"buffer_bytes", buffers},
    };
    if (r.lightcuts) j["lightcuts"] = lightcuts_json(*r.lightcuts, r.device == "cpu");
    if (r.method == "path") {
        j["max_bounces"] = r.max_bounces;
        j["time_limit"] = r.time_limit;
    }
    if (r.indirect)
        j["indirect"] = {{"vpls", r.indirect->vpls},
                         {"paths", r.indirect->paths},
                         {"max_bounces", r.indirect->max_bounces},
                         {"clamp", as_written(r.indirect->clamp)}};
    if (r.sampling) {
        j["sampling"] = {{"light_samples", r.sampling->light_samples}};
        if (!r.sampling->light_pick.empty()) j["sampling"]["light_pick"] = r.sampling->light_pick;
    }
    // A path that is not UTF-8 (Linux allows any bytes but '/' and NUL)
    // is written with U+FFFD for the bytes JSON cannot hold.
    return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string buffer_table(const std::vector<BufferBytes>& buffers) {
    std::string text;
    std::uint64_t total = 0;
    for (const BufferBytes& b : buffers) {
        text += format("    %-18s %s\n", b.name.c_str(), human_bytes(b.bytes).c_str());
        total += b.bytes;
    }
    return text + format("    %-18s %s\n", "total", human_bytes(total).c_str());
}

}  // namespace lc
