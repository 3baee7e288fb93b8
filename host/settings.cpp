// One definition of the valid render settings (include/lightcuts/settings.h).
#include "lightcuts/settings.h"

#include "lightcuts/render.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace lc {
namespace {

std::string integer_problem(double value, double lo, double hi) {
    auto text = [](double v) { return std::to_string(static_cast<long long>(v)); };
    if (!std::isfinite(value) || value != std::floor(value) || value < lo || value > hi)
        return "must be an integer from " + text(lo) + " to " + text(hi);
    return "";
}

// "1" rather than std::to_string's "1.000000".
std::string shortest(float v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", double(v));
    return text;
}

}  // namespace

// lc_pixel_key (shaders/lc_shared/shading.h) packs a pixel's x and y in 14 bits each.
static_assert(kMaxImageSide <= (1u << 14), "image sides past 2^14 need another pixel key");

std::string setting_problem(std::string_view key, double value) {
    constexpr double kMaxU32 = double(std::numeric_limits<std::uint32_t>::max());
    if (key == kSettingSpp) return integer_problem(value, 1, kMaxSpp);
    if (key == kSettingMaxCut || key == kSettingCutHeap) return integer_problem(value, 1, kMaxU32);
    if (key == kSettingSeed) return integer_problem(value, 0, kMaxU32);
    if (key == kSettingWidth || key == kSettingHeight) return integer_problem(value, 1, kMaxImageSide);
    if (key == kSettingLightSamples) return integer_problem(value, 1, kMaxLightSamplesPerPoint);
    if (key == kSettingAreaLightSamples || key == kSettingDirections)
        return integer_problem(value, 1, kMaxLightSamples);
    if (key == kSettingVpls) return integer_problem(value, 0, kMaxVpls);
    if (key == kSettingMaxBounces) return integer_problem(value, 0, kMaxBounces);
    if (key == kSettingThreads) return integer_problem(value, 0, kMaxThreads);
    if (key == kSettingTimeLimit || key == kSettingClamp) {
        // Up to the largest float: the clamp is held as one. What rounds to
        // it is taken (the stats JSON writes it as 3.4028235e+38, which
        // reads back so), what rounds to infinity is not, nor a positive
        // clamp that rounds to 0, which means "none".
        constexpr double kLargest = double(std::numeric_limits<float>::max());
        constexpr double kRoundsToInfinity = kLargest + 0x1p103;  // half the float step there
        if (!(value >= 0.0 && value < kRoundsToInfinity))
            return "must be a number from 0 to 3.4e38 (the largest float)";
        if (key == kSettingClamp && value > 0.0 && static_cast<float>(value) == 0.0f)
            return "must be 0 (none) or at least 1.4e-45 (the smallest float)";
        return "";
    }
    if (key == kSettingRelativeError) {
        if (!(value >= 0.0 && value <= double(kMaxRelativeError)))
            return "must be a number from 0 to " + shortest(kMaxRelativeError);
        return "";
    }
    throw std::logic_error("setting_problem: unknown setting '" + std::string(key) + "'");
}

std::string method_problem(std::string_view method) {
    if (method == "brute" || method == "lightcuts" || method == "sampled" || method == "stochastic" ||
        method == "path")
        return "";
    return "must be \"brute\", \"lightcuts\", \"sampled\", \"stochastic\" or \"path\", got \"" +
           std::string(method) + "\"";
}

std::string light_pick_problem(std::string_view pick) {
    if (pick == "tree" || pick == "uniform" || pick == "power") return "";
    return "must be \"tree\", \"uniform\" or \"power\", got \"" + std::string(pick) + "\"";
}

std::string cut_sharing_problem(std::string_view sharing) {
    if (sharing == "auto" || sharing == "pixel" || sharing == "quad" || sharing == "octet") return "";
    return "must be \"auto\", \"pixel\", \"quad\" or \"octet\", got \"" + std::string(sharing) + "\"";
}

std::uint32_t cpu_cut_points(std::string_view method, std::string_view sharing) {
    if (method != "lightcuts") return 1u;
    if (sharing == "octet" || sharing == "auto") return 8u;
    return sharing == "quad" ? 4u : 1u;
}

RenderOptions scene_render_options(const Scene& scene) {
    const RenderSettings& r = scene.render;
    RenderOptions o;
    o.method = r.method;
    o.spp = r.spp;
    o.relative_error = r.relative_error;
    o.max_cut = r.max_cut;
    o.cut_heap = r.cut_heap;
    o.cut_sharing = r.cut_sharing;
    o.seed = r.seed;
    o.light_samples = r.light_samples;
    o.light_pick = r.light_pick;
    o.max_bounces = r.max_bounces;
    o.time_limit = r.time_limit;
    o.width = scene.camera.width;
    o.height = scene.camera.height;
    return o;
}

void validate_render_options(const RenderOptions& o) {
    std::string problem = method_problem(o.method);
    if (!problem.empty()) throw std::invalid_argument("method " + problem);
    problem = light_pick_problem(o.light_pick);
    if (!problem.empty()) throw std::invalid_argument(std::string(kSettingLightPick) + " " + problem);
    problem = cut_sharing_problem(o.cut_sharing);
    if (!problem.empty()) throw std::invalid_argument(std::string(kSettingCutSharing) + " " + problem);
    const std::pair<std::string_view, double> values[] = {
        {kSettingSpp, o.spp},
        {kSettingRelativeError, o.relative_error},
        {kSettingMaxCut, o.max_cut},
        {kSettingCutHeap, o.cut_heap},
        {kSettingSeed, o.seed},
        {kSettingLightSamples, o.light_samples},
        {kSettingMaxBounces, o.max_bounces},
        {kSettingTimeLimit, o.time_limit},
        {kSettingThreads, o.threads},
    };
    for (const auto& [key, value] : values) {
        problem = setting_problem(key, value);
        if (!problem.empty()) throw std::invalid_argument(std::string(key) + " " + problem);
    }
    // 0 means the camera's size.
    for (const auto& [key, value] : {std::pair{kSettingWidth, o.width}, std::pair{kSettingHeight, o.height}}) {
        if (value == 0) continue;
        problem = setting_problem(key, value);
        if (!problem.empty()) throw std::invalid_argument(std::string(key) + " " + problem);
    }
    // Checked with the scene's render block and the command line merged,
    // before the scene is prepared: either may have set either.
    if (o.method == "path" && std::uint64_t(o.spp) * o.light_samples > kMaxPathsPerPixel)
        throw std::invalid_argument(
            "method path: spp x light_samples (paths per pixel) is " +
            std::to_string(std::uint64_t(o.spp) * o.light_samples) + ", more than " +
            std::to_string(kMaxPathsPerPixel) + " (--spp and --light-samples, or the scene's render.spp and "
            "render.light_samples)");
}

}  // namespace lc
