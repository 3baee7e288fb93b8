// Render settings and their valid ranges, checked in one place: the scene
// loader (a scene's "render" block), the command line and the renderers all
// ask these functions, so a value is accepted or refused with the same
// message wherever it comes from (docs/scene-format.md lists the ranges).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace lc {

inline constexpr std::uint32_t kMaxSpp = 65536;        // camera rays per pixel
inline constexpr std::uint32_t kMaxImageSide = 16384;  // width and height
inline constexpr float kMaxRelativeError = 1.0f;       // lightcuts threshold, as a fraction
inline constexpr std::uint32_t kMaxLightSamples = 1u << 24;  // area-light samples, environment directions
inline constexpr std::uint32_t kMaxLightSamplesPerPoint = 65536;  // sampled, stochastic: light_samples
inline constexpr std::uint64_t kMaxPathsPerPixel = 1u << 24;  // path: spp x light_samples (32-bit sample order)
inline constexpr std::uint32_t kMaxVpls = 1u << 24;    // render.indirect.vpls
inline constexpr std::uint32_t kMaxBounces = 1024;     // max_bounces (path and indirect); 0 = unlimited
// CPU threads (--threads; 0 = one per core). Each thread costs a stack and
// its own buffers: 10^4 threads took 86 s and 493 MB for an 8x8 render.
inline constexpr std::uint32_t kMaxThreads = 1024;
// max_cut may be any positive 32-bit value: the cut heap is sized by the
// light tree and cut_heap, never by max_cut (a cut cannot outgrow the tree).
// The default capacity K of the cut heap per shaded point (cut_heap): a cut
// that would need more freezes its clusters of smallest bound
// (docs/lightcuts.md, "The bounded heap"; the choice: docs/results/speed.md,
// section 2, "The default, K = 64").
inline constexpr std::uint32_t kDefaultCutHeap = 64;

// Names of the settings as the scene file's render block spells them (the
// command line uses the same words, with "--" and '-' for '_').
inline constexpr std::string_view kSettingMethod = "method";
inline constexpr std::string_view kSettingSpp = "spp";
inline constexpr std::string_view kSettingRelativeError = "relative_error";
inline constexpr std::string_view kSettingMaxCut = "max_cut";
inline constexpr std::string_view kSettingCutHeap = "cut_heap";
inline constexpr std::string_view kSettingSeed = "seed";
inline constexpr std::string_view kSettingWidth = "width";
inline constexpr std::string_view kSettingHeight = "height";
inline constexpr std::string_view kSettingAreaLightSamples = "area_light_samples";
inline constexpr std::string_view kSettingDirections = "directions";  // of an environment
inline constexpr std::string_view kSettingLightSamples = "light_samples";  // sampled, stochastic
inline constexpr std::string_view kSettingLightPick = "light_pick";        // --method sampled
inline constexpr std::string_view kSettingCutSharing = "cut_sharing";      // --method lightcuts
inline constexpr std::string_view kSettingMaxBounces = "max_bounces";      // path, and indirect's
inline constexpr std::string_view kSettingTimeLimit = "time_limit";        // path, seconds
inline constexpr std::string_view kSettingIndirect = "indirect";           // the VPL block:
inline constexpr std::string_view kSettingVpls = "vpls";                   //   VPL count
inline constexpr std::string_view kSettingClamp = "clamp";                 //   falloff clamp distance
inline constexpr std::string_view kSettingThreads = "threads";             // the command line only

// What is wrong with `value` for the numeric setting `key` (one of the
// kSetting* names above, not method), or "" when it is valid. Integer
// settings refuse fractions; NaN and infinities are refused everywhere.
std::string setting_problem(std::string_view key, double value);

// What is wrong with a method name, or "" for "brute", "lightcuts",
// "sampled", "stochastic" and "path" (the path tracer, CPU only).
std::string method_problem(std::string_view method);

// True for the methods that select a lightcut per shaded point (and so
// report cut sizes): "lightcuts" and "stochastic".
inline bool method_selects_cuts(std::string_view method) { return method == "lightcuts" || method == "stochastic"; }

// What is wrong with a light pick, or "" for "tree", "uniform" and "power".
std::string light_pick_problem(std::string_view pick);

// What is wrong with a cut sharing, or "" for "auto", "pixel", "quad" and
// "octet". Lightcuts cuts each shaded point alone ("pixel"), the four
// points of a 2x2 block of pixels together ("quad": host/quad_cut.h on the
// CPU, shaders/quadcuts.comp on Vulkan devices with subgroup quad
// operations), or the eight of a 4x2 block, two quads side by side
// ("octet": the CPU only). "auto" is "octet" on the CPU and "pixel" on
// Vulkan.
std::string cut_sharing_problem(std::string_view sharing);

// The shaded points that share each cut in a render on the CPU with these
// settings: 8 for method "lightcuts" with cut_sharing "octet" or "auto", 4
// with "quad", else 1 (each point cut alone).
std::uint32_t cpu_cut_points(std::string_view method, std::string_view sharing);

// The heap slots of a cut shared by `points` points for render.cut_heap K:
// their K each, pooled (a shared cut's slot holds every point's bounds).
inline std::uint32_t shared_cut_heap(std::uint32_t cut_heap, std::uint32_t points) {
    return cut_heap > UINT32_MAX / points ? UINT32_MAX : points * cut_heap;
}
inline std::uint32_t quad_cut_heap(std::uint32_t cut_heap) { return shared_cut_heap(cut_heap, 4u); }

}  // namespace lc
