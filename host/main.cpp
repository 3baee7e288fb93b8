// lightcuts: the command-line renderer. It parses and calls; what is valid,
// which device renders and what is reported are the library's decisions.
//   lightcuts render SCENE -o OUT.exr [options]   render to EXR (+ PNG preview)
//   lightcuts compare IMAGE REFERENCE [--heatmap]  error metrics between two EXRs
//   lightcuts info SCENE [--area-samples N]        what a scene holds
// SCENE is a scene JSON or a glTF 2.0 file (.gltf, .glb).
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <future>
#include <limits>
#include <new>
#include <optional>
#include <utility>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "lightcuts/output_set.h"
#include "lightcuts/render.h"
#include "lightcuts/report.h"
#include "lightcuts/scene.h"
#include "lightcuts/settings.h"

namespace {

struct RenderArgs {
    std::string scene, method, light_pick, cut_sharing;
    lc::SceneOptions scene_options;
    lc::RenderOutputs outputs;
    lc::DeviceChoice device;
    std::optional<std::uint32_t> spp, width, height, max_cut, cut_heap, seed, area_samples, light_samples, max_bounces;
    std::optional<std::uint32_t> vpls, vpl_bounces;
    std::optional<float> relative_error, vpl_clamp;
    std::optional<double> time_limit;
    unsigned threads = 0;
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A CLI11 check that asks the library: `problem` gives "" or what is wrong.
template <class Problem>
CLI::Validator ask(Problem problem, std::string help = "") {
    return CLI::Validator([problem](std::string& text) { return problem(text); }, std::move(help), "");
}

// The numeric settings' check (lightcuts/settings.h), so the command line
// takes the same ranges and gives the same words as a scene file. The help
// shows the range in those words too ("an integer from 1 to 65536").
CLI::Validator setting(std::string_view key) {
    std::string range = lc::setting_problem(key, kNaN);
    if (range.starts_with("must be ")) range.erase(0, 8);
    return ask(
        [key](std::string& text) {
            double value = kNaN;
            const char* end = text.data() + text.size();
            if (auto [p, ec] = std::from_chars(text.data(), end, value); ec != std::errc{} || p != end) value = kNaN;
            std::string problem = lc::setting_problem(key, value);
            // A whole number written as "4.0" or "1e1" is that integer, as in
            // a scene file; CLI11 converts integer options from digits only.
            if (problem.empty() && value == std::floor(value) && std::abs(value) < 0x1p53)
                text = std::to_string(static_cast<long long>(value));
            return problem;
        },
        range);
}

// The scene's render block and camera, overridden by what the command line gives.
lc::RenderOptions render_options(const RenderArgs& a, const lc::Scene& scene) {
    lc::RenderOptions o = lc::scene_render_options(scene);
    if (!a.method.empty()) o.method = a.method;
    o.spp = a.spp.value_or(o.spp);
    o.relative_error = a.relative_error.value_or(o.relative_error);
    o.max_cut = a.max_cut.value_or(o.max_cut);
    o.cut_heap = a.cut_heap.value_or(o.cut_heap);
    if (!a.cut_sharing.empty()) o.cut_sharing = a.cut_sharing;
    o.seed = a.seed.value_or(o.seed);
    o.light_samples = a.light_samples.value_or(o.light_samples);
    if (!a.light_pick.empty()) o.light_pick = a.light_pick;
    o.max_bounces = a.max_bounces.value_or(o.max_bounces);
    o.time_limit = a.time_limit.value_or(o.time_limit);
    o.width = a.width.value_or(o.width);
    o.height = a.height.value_or(o.height);
    o.threads = a.threads;
    o.progress = true;
    return o;
}

// The options given on the command line that the render does not use, as
// one note ("" if none): a render that ignores what it was told says so,
// and why: the method, that it makes no VPLs (their settings), or that
// the scene has no emissive surface (--area-samples).
std::string unused_options_note(const RenderArgs& a, const std::string& method, bool vpls, bool emitters) {
    const bool cuts = method == "lightcuts" || method == "stochastic";
    const bool path = method == "path";
    const struct {
        bool given, used_by_method;
        const char* name;
        bool needs_vpls, needs_emitters = false;
    } options[] = {
        {a.relative_error.has_value(), cuts, "--error", false},
        {a.max_cut.has_value(), cuts, "--max-cut", false},
        {a.cut_heap.has_value(), cuts, "--cut-heap", false},
        {!a.cut_sharing.empty(), method == "lightcuts", "--cut-sharing", false},
        {a.light_samples.has_value(), method == "sampled" || method == "stochastic" || path, "--light-samples",
         false},
        {!a.light_pick.empty(), method == "sampled", "--light-pick", false},
        {a.max_bounces.has_value(), path, "--max-bounces", false},
        {a.time_limit.has_value(), path, "--time-limit", false},
        {a.area_samples.has_value(), !path, "--area-samples", false, true},
        {a.vpls.has_value(), !path, "--vpls", false},
        {a.vpl_bounces.has_value(), !path, "--vpl-bounces", true},
        {a.vpl_clamp.has_value(), !path, "--vpl-clamp", true},
    };
    std::string by_method, by_vpls, by_emitters;
    const auto add = [](std::string& list, const char* name) { list += (list.empty() ? "" : ", ") + std::string(name); };
    for (const auto& o : options) {
        if (!o.given) continue;
        if (!o.used_by_method)
            add(by_method, o.name);
        else if (o.needs_vpls && !vpls)
            add(by_vpls, o.name);
        else if (o.needs_emitters && !emitters)
            add(by_emitters, o.name);
    }
    std::string note;
    if (!by_method.empty()) note = "method " + method + " does not use " + by_method;
    if (!by_vpls.empty())
        note += (note.empty() ? "" : "; ") + std::string("this render makes no VPLs (") +
                (a.vpls ? "--vpls 0" : "no --vpls, nor render.indirect.vpls") + "): it does not use " + by_vpls;
    if (!by_emitters.empty())
        note += (note.empty() ? "" : "; ") + std::string("the scene has no emissive surface: it does not use ") +
                by_emitters;
    return note;
}

// What the loader dropped or left out, on stderr before anything else.
void print_load_notes(const std::string& file, const lc::Scene& scene) {
    if (scene.degenerate_triangles_dropped)
        std::fprintf(stderr, "warning: %s: dropped %zu degenerate triangles\n", file.c_str(),
                     scene.degenerate_triangles_dropped);
    for (const std::string& line : scene.load_notes) std::fprintf(stderr, "note: %s\n", line.c_str());
}

// The path tracer samples the emissive surfaces and the environment
// themselves and finds indirect light itself: the point lights the others
// become, and VPLs, would only cost time and memory (4M area samples took
// 5.6 s of tree building for nothing). render and info both apply this.
void drop_what_the_method_does_not_use(lc::Scene& scene, const std::string& method) {
    if (method != "path") return;
    scene.render.indirect.vpls = 0;
    scene.render.area_light_samples = 0;
    scene.environment.directions = 0;
}

// stdout holds the report of render and all that compare and info make:
// a write to it that failed (a full disk, a closed pipe) is an error, not
// a success with an empty file.
void check_stdout() {
    if (std::fflush(stdout) != 0 || std::ferror(stdout))
        throw std::runtime_error(std::string("cannot write to standard output: ") + std::strerror(errno));
}

int run_render(RenderArgs a) {
    // Device "auto" renders through Vulkan only on a GPU, and finding out
    // loads every installed Vulkan driver (0.1 s where Mesa's are
    // installed) unless the machine has no GPU device file (probe_gpus):
    // that is done while the scene loads. Unless the command line already
    // rules Vulkan out (the scene's render block may still do so; the
    // answer then goes unread).
    if (a.device.device == "auto" && a.device.vulkan.gpu.empty() && a.method != "path")
        a.device.devices = std::async(std::launch::async, lc::probe_gpus).share();
    const auto start = std::chrono::steady_clock::now();
    a.scene_options.threads = a.threads;
    lc::Scene scene = lc::load_scene(a.scene, a.scene_options);
    const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    print_load_notes(a.scene, scene);
    const lc::RenderOptions options = render_options(a, scene);
    if (a.area_samples) scene.render.area_light_samples = *a.area_samples;
    if (a.vpls) scene.render.indirect.vpls = *a.vpls;
    if (a.vpl_bounces) scene.render.indirect.max_bounces = *a.vpl_bounces;
    if (a.vpl_clamp) scene.render.indirect.clamp = *a.vpl_clamp;
    drop_what_the_method_does_not_use(scene, options.method);
    lc::validate_render_options(options);
    if (const std::string problem = lc::vulkan_options_problem(a.device, options.method); !problem.empty())
        throw std::invalid_argument(problem);
    // Every output is checked and reserved before the render; none is left if any fails.
    lc::OutputSet outputs = lc::reserve_render_outputs(a.outputs, a.scene, options.method, scene.input_files);
    // After the checks, so that a refused command reads as one error.
    if (const std::string note =
            unused_options_note(a, options.method, scene.render.indirect.vpls > 0,
                                scene.count_emissive_triangles() > 0);
        !note.empty())
        std::fprintf(stderr, "note: %s\n", note.c_str());

    const lc::PreparedScene prepared = lc::prepare_scene(std::move(scene), options.seed, options.threads);
    a.device.note = [](const std::string& line) { std::fprintf(stderr, "note: %s\n", line.c_str()); };
    const lc::RenderResult result = lc::render(prepared, options, a.device);
    const lc::RenderReport report = lc::make_report(a.scene, options, prepared, result, load_seconds);
    std::fputs(lc::report_text(report).c_str(), stdout);
    check_stdout();  // before the outputs, which are then left unwritten
    lc::write_render_outputs(outputs, a.outputs, result, lc::report_json(report));
    return 0;
}

// A metric for compare --json: a number where finite, else the text the
// plain output prints ("inf", "-inf", "nan"; JSON has no such numbers, and
// a null would read as "no value").
nlohmann::json metric_json(double v) {
    if (std::isfinite(v)) return v;
    return std::isnan(v) ? "nan" : v > 0.0 ? "inf" : "-inf";
}

int run_compare(const std::string& image, const std::string& reference, const std::string& heatmap,
                bool as_json) {
    // The heatmap is refused before anything is read or printed where it
    // could not be written, or would replace one of the images compared.
    lc::OutputSet outputs;
    if (!heatmap.empty()) {
        if (std::filesystem::path(heatmap).extension() != ".png")
            throw std::invalid_argument("heatmap " + heatmap + ": must end in .png");
        outputs.add_input(image, "image compared");
        outputs.add_input(reference, "reference");
        outputs.add(heatmap, "heatmap");
    }
    glm::ivec2 a_origin, r_origin;
    lc::Image a = lc::read_exr(image, lc::kMaxExrPixels, &a_origin);
    lc::Image r = lc::read_exr(reference, lc::kMaxExrPixels, &r_origin);
    if (a.width != r.width || a.height != r.height)
        throw lc::InputError(image, "", "size " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                            " differs from the reference's " + std::to_string(r.width) + "x" +
                                            std::to_string(r.height));
    // Pixels are compared where they lie: two data windows of one size that
    // start apart hold different places of the image.
    if (a_origin != r_origin)
        throw lc::InputError(image, "", "pixels start at (" + std::to_string(a_origin.x) + ", " +
                                            std::to_string(a_origin.y) + "), the reference's at (" +
                                            std::to_string(r_origin.x) + ", " + std::to_string(r_origin.y) +
                                            ") (the OpenEXR data windows)");
    // A NaN or infinite pixel makes every metric NaN or infinite: refused,
    // naming the first such pixel, rather than reported as a number.
    for (const auto& [img, file] : {std::pair<const lc::Image&, const std::string&>{a, image}, {r, reference}}) {
        std::size_t bad = 0, first = 0;
        for (std::size_t i = 0; i < img.rgb.size(); ++i)
            if (!std::isfinite(img.rgb[i]) && bad++ == 0) first = i;
        if (bad == 0) continue;
        const std::size_t pixel = first / 3;
        throw lc::InputError(file, "pixel (" + std::to_string(pixel % img.width) + ", " +
                                       std::to_string(pixel / img.width) + ")." + "RGB"[first % 3],
                             std::string(std::isnan(img.rgb[first]) ? "is NaN" : "is infinite") + " (" +
                                 std::to_string(bad) + " of the image's " + std::to_string(img.rgb.size()) +
                                 " values are not finite)");
    }
    lc::CompareResult c = lc::compare_images(a, r);
    if (as_json) {
        nlohmann::json j = {{"relative_rmse", metric_json(c.relative_rmse)},
                            {"fraction_above_1pct", metric_json(c.fraction_above_1pct)},
                            {"fraction_above_2pct", metric_json(c.fraction_above_2pct)},
                            {"fraction_above_5pct", metric_json(c.fraction_above_5pct)},
                            {"max_relative_error", metric_json(c.max_relative_error)},
                            {"mean_difference", metric_json(c.mean_difference)}};
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("relative RMSE        %.6g\n", c.relative_rmse);
        std::printf("pixels above 1%%      %.4f%%\n", 100.0 * c.fraction_above_1pct);
        std::printf("pixels above 2%%      %.4f%%\n", 100.0 * c.fraction_above_2pct);
        std::printf("pixels above 5%%      %.4f%%\n", 100.0 * c.fraction_above_5pct);
        std::printf("max relative error   %.6g\n", c.max_relative_error);
        std::printf("mean difference      %+.4f%% (image mean luminance over the reference's)\n",
                    100.0 * c.mean_difference);
    }
    check_stdout();
    // The heatmap's scale runs from 0 to 10% relative luminance error.
    if (!heatmap.empty()) {
        lc::write_file(outputs.temporary(heatmap), lc::encode_heatmap_png(a.width, a.height, c.per_pixel, 0.1f, heatmap),
                       heatmap);
        outputs.commit();
    }
    return 0;
}

// What `info` takes of render's options: those that change what is
// prepared (the lights made from emissive surfaces and light paths).
struct InfoArgs {
    std::optional<std::uint32_t> area_samples, vpls, vpl_bounces, seed;
    std::string method;
};

int run_info(const std::string& file, const lc::SceneOptions& options, const InfoArgs& a) {
    lc::Scene scene = lc::load_scene(file, options);
    print_load_notes(file, scene);
    if (a.area_samples) scene.render.area_light_samples = *a.area_samples;
    if (a.vpls) scene.render.indirect.vpls = *a.vpls;
    if (a.vpl_bounces) scene.render.indirect.max_bounces = *a.vpl_bounces;
    // The render's seed, which places the area-light samples and the VPLs
    // (with seed 1 always, a scene of another seed got other VPL counts).
    const std::uint32_t seed = a.seed.value_or(scene.render.seed);
    const std::string method = a.method.empty() ? scene.render.method : a.method;
    drop_what_the_method_does_not_use(scene, method);
    RenderArgs as_render;  // the note render would print for these options
    as_render.area_samples = a.area_samples;
    as_render.vpls = a.vpls;
    as_render.vpl_bounces = a.vpl_bounces;
    const std::size_t emissive = scene.count_emissive_triangles();
    if (const std::string note = unused_options_note(as_render, method, scene.render.indirect.vpls > 0, emissive > 0);
        !note.empty())
        std::fprintf(stderr, "note: %s\n", note.c_str());
    std::printf("%s\n", file.c_str());
    std::printf("  method             %s\n", method.c_str());
    std::printf("  triangles          %zu (%zu emissive, %zu degenerate dropped)\n", scene.triangles.size(),
                emissive, scene.degenerate_triangles_dropped);
    std::printf("  materials          %zu\n", scene.materials.size());
    std::printf("  textures           %zu (%zu texels)\n", scene.textures.size(), scene.texels.size());
    std::printf("  point lights       %zu\n", scene.count_lights(lc::gpu::kLightPoint));
    std::printf("  directional lights %zu\n", scene.count_lights(lc::gpu::kLightDirectional));
    std::printf("  spot lights        %zu\n", scene.count_lights(lc::gpu::kLightSpot));
    if (scene.environment.present())
        std::printf("  environment        %ux%u, %u directions\n", scene.environment.width, scene.environment.height,
                    scene.environment.directions);
    std::printf("  bounds             [%g %g %g] - [%g %g %g]\n", scene.bounds_min.x, scene.bounds_min.y,
                scene.bounds_min.z, scene.bounds_max.x, scene.bounds_max.y, scene.bounds_max.z);
    std::printf("  image              %ux%u\n", scene.camera.width, scene.camera.height);
    const lc::PreparedScene prepared = lc::prepare_scene(std::move(scene), seed);
    std::printf("  area-light samples %zu\n", prepared.area_lights);
    if (prepared.scene.render.indirect.vpls > 0)  // also where the paths left none
        std::printf("  VPLs               %zu from %zu light paths (seed %u)\n", prepared.vpls, prepared.vpl_paths,
                    seed);
    // The arrays the kernels read, not all the process holds: the host
    // keeps the scene's own lights as well, and the tree's build holds its
    // clusters (docs/results/scale.md, "Memory per light").
    std::printf("  buffers the kernels read (the host holds the scene's lights too, 48 B a light, and at the "
                "tree's build about 330 B a light in all):\n%s",
                lc::buffer_table(lc::scene_buffer_bytes(prepared)).c_str());
    check_stdout();
    return 0;
}

// A file option given as "" (--stats "", say) names no file: refused, not
// taken for the option's absence; so are an empty camera or device name.
CLI::Validator non_empty(const std::string& what, const std::string& type) {
    return CLI::Validator(
        [what](std::string& value) { return value.empty() ? "the " + what + " is empty" : std::string(); }, type,
        what);
}
const CLI::Validator kFileName = non_empty("file name", "FILE");
const CLI::Validator kCameraName = non_empty("camera name", "NAME");
const CLI::Validator kDeviceName = non_empty("device name", "INDEX|NAME");

CLI::App* add_render_command(CLI::App& app, RenderArgs& r) {
    auto* render = app.add_subcommand("render", "Render a scene to a linear OpenEXR image and a PNG preview");
    render->add_option("scene", r.scene, "Scene file (JSON, or glTF 2.0: .gltf or .glb)")->required()->check(kFileName);
    render->add_option("--camera", r.scene_options.camera,
                       "glTF scenes: the perspective camera of this name (default: the first in node order; "
                       "none in the file: a default framing of the scene)")
        ->check(kCameraName);
    render->add_option("-o,--output", r.outputs.image, "Output .exr (a tone-mapped .png is written beside it)")
        ->required()
        ->check(kFileName);
    render->add_option("--method", r.method,
                       "brute (exact), lightcuts, sampled (lights drawn through the light tree), "
                       "stochastic (Stochastic Lightcuts) or path (the path tracer, CPU only)")
        ->check(ask(lc::method_problem));
    render->add_option("--spp", r.spp, "Camera rays per pixel")->transform(setting(lc::kSettingSpp));
    render->add_option("--width", r.width, "Image width")->transform(setting(lc::kSettingWidth));
    render->add_option("--height", r.height, "Image height")->transform(setting(lc::kSettingHeight));
    render->add_option("--error", r.relative_error,
                       "lightcuts and stochastic: relative error threshold of the cut (default 0.02)")
        ->transform(setting(lc::kSettingRelativeError));
    render->add_option("--max-cut", r.max_cut, "lightcuts and stochastic: largest cut (default 1000)")
        ->transform(setting(lc::kSettingMaxCut));
    render->add_option("--cut-heap", r.cut_heap,
                       "lightcuts and stochastic: cut-heap capacity per shaded point; a larger cut freezes "
                       "its clusters of smallest bound (default " + std::to_string(lc::kDefaultCutHeap) + ")")
        ->transform(setting(lc::kSettingCutHeap));
    render->add_option("--cut-sharing", r.cut_sharing,
                       "lightcuts: pixel (a cut per pixel), quad (the four pixels of a 2x2 block share one cut; "
                       "on Vulkan it needs subgroup quad operations), octet (the eight of a 4x2 block, CPU only: "
                       "the fastest there) or auto (octet on the CPU, pixel on Vulkan; the default)")
        ->check(ask(lc::cut_sharing_problem));
    render->add_option("--area-samples", r.area_samples,
                       "Point lights the emissive surfaces become, in all (default 65536)")
        ->transform(setting(lc::kSettingAreaLightSamples));
    render->add_option("--light-samples", r.light_samples,
                       "sampled: lights drawn per camera sample; stochastic: representatives drawn per cluster "
                       "of the cut; path: paths per camera ray (default 1)")
        ->transform(setting(lc::kSettingLightSamples));
    render->add_option("--light-pick", r.light_pick,
                       "sampled: how lights are drawn: tree (importance through the light tree, the default), "
                       "uniform or power")
        ->check(ask(lc::light_pick_problem));
    render->add_option("--vpls", r.vpls,
                       "Virtual point lights for indirect light (render.indirect.vpls; 0 = direct light only)")
        ->transform(setting(lc::kSettingVpls));
    render->add_option("--vpl-bounces", r.vpl_bounces,
                       "VPLs per light path at most (render.indirect.max_bounces, default 3; 0 = until roulette)")
        ->transform(setting(lc::kSettingMaxBounces));
    render->add_option("--vpl-clamp", r.vpl_clamp,
                       "Distance below which a VPL's 1/d^2 stops growing (render.indirect.clamp; 0 = none)")
        ->transform(setting(lc::kSettingClamp));
    render->add_option("--max-bounces", r.max_bounces,
                       "path: surface interactions per path (1 = direct light only; 0 = unlimited, the default)")
        ->transform(setting(lc::kSettingMaxBounces));
    render->add_option("--time-limit", r.time_limit,
                       "path: end the render near this many seconds, with the samples done by then (0 = none)")
        ->transform(setting(lc::kSettingTimeLimit));
    render->add_option("--seed", r.seed, "Seed for pixel jitter, light-tree representatives and light samples")
        ->transform(setting(lc::kSettingSeed));
    render->add_option("--threads", r.threads,
                       "CPU threads of the render, the reading of light lists, the area-light sampling, the VPLs "
                       "and the light tree's build (0 = all cores; at most 1024)")
        ->transform(setting(lc::kSettingThreads));
    render->add_option("--device", r.device.device,
                       "auto (a hardware GPU through Vulkan, else the CPU path), cpu or vulkan")
        ->check(ask(lc::device_problem));
    render->add_option("--gpu", r.device.vulkan.gpu, "Vulkan device index or name substring")->check(kDeviceName);
    render->add_flag("--validation", r.device.vulkan.validation, "Enable the Vulkan validation layer");
    render->add_option("--stats", r.outputs.stats, "Write statistics as JSON")->check(kFileName);
    render->add_option("--cut-heatmap", r.outputs.cut_heatmap, "Write per-pixel cut size as a false-colour PNG")
        ->check(kFileName);
    render->add_flag_callback("--no-png", [&r] { r.outputs.png_preview = false; }, "Do not write the PNG preview");
    return render;
}

}  // namespace

// The exit status: 0 done, 1 an error in the input or the work (the
// message names the file and the field), 2 a command line that does not
// parse (CLI11's own codes, 105 to 114, told its kinds apart for nobody).
constexpr int kUsageError = 2;

int main(int argc, char** argv) {
    CLI::App app{"lightcuts: many-light rendering with Lightcuts on the CPU and Vulkan compute"};
    app.require_subcommand(1);

    RenderArgs r;
    CLI::App* render = add_render_command(app, r);

    std::string cmp_image, cmp_ref, cmp_heatmap;
    bool cmp_json = false;
    auto* compare = app.add_subcommand("compare", "Error metrics of an EXR image against a reference EXR");
    compare->add_option("image", cmp_image, "Image (EXR)")->required()->check(kFileName);
    compare->add_option("reference", cmp_ref, "Reference (EXR)")->required()->check(kFileName);
    compare->add_option("--heatmap", cmp_heatmap, "Write per-pixel relative error as a PNG (scale 0 to 10%)")
        ->check(kFileName);
    compare->add_flag("--json", cmp_json, "Print the metrics as JSON");

    std::string info_scene;
    lc::SceneOptions info_options;
    auto* info = app.add_subcommand("info", "Print what a scene holds and the buffers its render reads");
    info->add_option("scene", info_scene, "Scene file (JSON, or glTF 2.0: .gltf or .glb)")->required()->check(kFileName);
    info->add_option("--camera", info_options.camera, "glTF scenes: the perspective camera of this name")
        ->check(kCameraName);
    InfoArgs info_args;
    info->add_option("--area-samples", info_args.area_samples, "Point lights the emissive surfaces become, as render's")
        ->transform(setting(lc::kSettingAreaLightSamples));
    info->add_option("--vpls", info_args.vpls, "Virtual point lights for indirect light, as render's")
        ->transform(setting(lc::kSettingVpls));
    info->add_option("--vpl-bounces", info_args.vpl_bounces, "VPLs per light path at most, as render's")
        ->transform(setting(lc::kSettingMaxBounces));
    info->add_option("--seed", info_args.seed, "Seed of the area-light samples and VPLs, as render's")
        ->transform(setting(lc::kSettingSeed));
    info->add_option("--method", info_args.method,
                     "The method to size the buffers for, as render's (path makes no area-light samples, VPLs "
                     "or environment directions)")
        ->check(ask(lc::method_problem));

    // A first word that is neither a subcommand nor an option: CLI11 would
    // say only that a subcommand is required.
    if (argc > 1 && argv[1][0] != '-') {
        const std::vector<CLI::App*> commands = app.get_subcommands([](CLI::App*) { return true; });
        if (std::none_of(commands.begin(), commands.end(), [&](CLI::App* c) { return c->check_name(argv[1]); })) {
            std::string names;
            for (const CLI::App* c : commands) names += (names.empty() ? "" : ", ") + c->get_name();
            std::fprintf(stderr, "error: unknown command '%s' (the commands are %s)\n", argv[1], names.c_str());
            return kUsageError;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and the like exit 0 and print as CLI11 does; errors read
        // as every other error does.
        if (e.get_exit_code() == 0) return app.exit(e);
        // CLI11 reports a missing command or argument before an option it
        // does not know, and an unknown option after a complete command as
        // its words left over, in reverse ("3 --bogus"): the unknown
        // option, which is more likely the mistake, is named first.
        if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr ||
            dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
            const CLI::App* command = nullptr;
            // An option is a word of a dash and a letter or of two dashes;
            // "-1" and "-.5" are (refused) values.
            const auto is_option = [](const std::string& word) {
                return word.size() > 1 && word[0] == '-' && word != "--" &&
                       !(std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.');
            };
            for (int i = 1; i < argc; ++i) {
                const std::string word = argv[i];
                if (word == "--") break;  // what follows are arguments
                if (command == nullptr && !is_option(word)) {
                    for (const CLI::App* c : app.get_subcommands([](CLI::App*) { return true; }))
                        if (c->check_name(word)) command = c;
                    continue;
                }
                if (!is_option(word)) continue;
                // "--name=value", and "-oFILE", a short option with its value attached.
                const std::string name = word[1] == '-' ? word.substr(0, word.find('=')) : word.substr(0, 2);
                const CLI::App* in = command != nullptr ? command : &app;
                if (in->get_option_no_throw(name) == nullptr && app.get_option_no_throw(name) == nullptr) {
                    std::fprintf(stderr, "error: unknown option %s%s\nRun with --help for more information.\n",
                                 name.c_str(),
                                 command == nullptr ? " (a command comes first: render, compare or info)" : "");
                    return kUsageError;
                }
            }
        }
        // An option given twice: CLI11 says "--spp: At Most 1 required but received 2".
        if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) != nullptr) {
            const std::string what = e.what();
            if (const std::size_t colon = what.find(": At Most 1 required"); colon != std::string::npos) {
                std::fprintf(stderr, "error: %s is given more than once\nRun with --help for more information.\n",
                             what.substr(0, colon).c_str());
                return kUsageError;
            }
        }
        std::fprintf(stderr, "error: %s\nRun with --help for more information.\n", e.what());
        return kUsageError;
    }
    // Ctrl-C or a kill during a render leaves no temporary beside its outputs.
    lc::remove_temporaries_on_signal();
    try {
        if (*render) return run_render(r);
        if (*compare) return run_compare(cmp_image, cmp_ref, cmp_heatmap, cmp_json);
        if (*info) return run_info(info_scene, info_options, info_args);
    } catch (const std::bad_alloc&) {
        // Where the memory went is not known here; what usually takes it is.
        if (*compare)
            std::fprintf(stderr, "error: out of memory reading the two images (their pixels are held as floats, 12 B "
                                 "a pixel each, and decoded through a second copy)\n");
        else
            std::fprintf(stderr,
                         "error: out of memory (the image's pixels and their statistics, the lights and the light "
                         "tree, area-light samples and VPLs, and each thread's cut heap, which --cut-heap and "
                         "--max-cut size, all grow with their settings; `lightcuts info SCENE` prints the buffers a "
                         "scene needs)\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 1;
}
