// render_vulkan: the scene's buffers go to the device once (GpuResources);
// the image is rendered in tiles (TileScheduler), each sample of a tile as
// one submission (TilePass: camera rays -> G-buffer, then the shading
// method's dispatches added to the tile's sums); the sums come back after
// the tile's last sample. docs/vulkan.md describes the whole path.
#include "vulkan_renderer.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>

#include "lightcuts/error.h"
#include "render_setup.h"
#include "vk_check.h"
#include "tile_scheduler.h"

namespace lc::vk {

namespace {

using Clock = std::chrono::steady_clock;

// The GLSL push-constant block of shaders/kernel.glsl.
static_assert(sizeof(gpu::PushConstants) == 44);
static_assert(offsetof(gpu::PushConstants, sample_index) == 16);
static_assert(offsetof(gpu::PushConstants, refine_budget) == 32);
// The std430 layouts of bindings.glsl's records: 4-byte scalars only.
static_assert(sizeof(gpu::PixelStats) == 40);
static_assert(offsetof(gpu::PixelStats, shadow_rays_lo) == 8);
static_assert(offsetof(gpu::PixelStats, max_cut_samples) == 16);
static_assert(offsetof(gpu::PixelStats, flags) == 24);
static_assert(sizeof(gpu::CutState) == 52);

// True on llvmpipe (lavapipe), whose loop limiter cuts long kernels short.
bool driver_limits_loops(const Context& ctx) {
    auto driver = vk_struct<VkPhysicalDeviceDriverProperties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
    auto properties = vk_struct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    properties.pNext = &driver;
    vkGetPhysicalDeviceProperties2(ctx.physical(), &properties);
    return driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE;
}

// Whether the device can run quadcuts.comp: subgroup quad operations in
// compute shaders, in subgroups of at least four invocations that divide
// the workgroup (so that each quad's four lanes are a subgroup quad).
bool device_has_quad_subgroups(const Context& ctx) {
    if (ctx.properties().apiVersion < VK_API_VERSION_1_1) return false;
    auto subgroup = vk_struct<VkPhysicalDeviceSubgroupProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES);
    auto properties = vk_struct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    properties.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(ctx.physical(), &properties);
    return (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
           (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_QUAD_BIT) != 0 && subgroup.subgroupSize >= 4 &&
           gpu::kWorkgroupSize % subgroup.subgroupSize == 0;
}

RenderResult render(const Context& ctx, const PreparedScene& prepared,
                    const RenderOptions& options, const Tuning& requested) {
    const gpu::FrameParams frame = frame_params(ctx, prepared, options);
    const Tuning tuning = device_tuning(ctx, requested);
    RenderResult result;
    result.image = Image(frame.width, frame.height);
    RenderStats& stats = result.stats;
    stats.device = ctx.device_name();
    if (frame.width == 0 || frame.height == 0) return result;

    RenderSetup setup(ctx, prepared, options, frame, tuning);
    if (setup.method->reports_cuts()) {
        stats.cut_size.assign(std::size_t(frame.width) * frame.height, 0.0f);
        stats.heap_froze.assign(std::size_t(frame.width) * frame.height, 0.0f);
    }
    TileScheduler scheduler(ctx.device_name(), setup.submitter, setup.pass, *setup.method,
                            setup.resources, frame, tuning.target_dispatch_ms,
                            min_tile_pixels(ctx, tuning), tuning.split_slow_tiles == Tuning::SplitSlowTiles::kOn,
                            tuning.shading_ms_for_split, options.progress);
    scheduler.render(result);

    stats.spp_done = frame.spp;
    stats.camera_rays = std::uint64_t(frame.width) * frame.height * frame.spp;
    stats.heap_slots = setup.method->heap_slots();
    stats.heap_private = tuning.heap_memory == Tuning::HeapMemory::kPrivate;
    stats.heap_shared_bytes = stats.heap_private ? 0
                                                 : std::uint64_t(stats.heap_slots) * gpu::kWorkgroupSize *
                                                       setup.method->heap_entry_bytes();
    stats.cut_points = setup.method->quad_cuts() ? 4u : 1u;
    stats.workgroup_size = gpu::kWorkgroupSize;
    stats.buffer_bytes = setup.resources.buffer_bytes();
    return result;
}

}  // namespace

bool share_cuts(const Context& ctx, const LightTree& tree, const RenderOptions& options,
                const gpu::FrameParams& frame, const Tuning& tuning) {
    // "auto" cuts each pixel alone on Vulkan: on lavapipe the quads' kernel
    // took 1.2 to 2 times as long as the per-pixel one (docs/results/
    // lavapipe.md, §17), as its lanes share the cut's decisions but not its
    // work; on an H200 309 ms of GPU time against 80 ms (docs/results/
    // gpu.md).
    if (options.method == "lightcuts" && options.cut_sharing == "octet")
        throw std::invalid_argument("cut_sharing \"octet\" on " + ctx.device_name() +
                                    ": octets share cuts on the CPU only; use cut_sharing \"auto\", \"pixel\" or "
                                    "\"quad\", or --device cpu");
    if (options.method != "lightcuts" || options.cut_sharing != "quad") return false;
    std::string why;
    if (!device_has_quad_subgroups(ctx)) {
        why = "the device has no subgroup quad operations in compute shaders";
    } else if (tuning.heap_memory != Tuning::HeapMemory::kPrivate) {
        const std::uint64_t slots = tree.cut_heap_slots(frame.max_cut, quad_cut_heap(options.cut_heap));
        const std::uint64_t bytes = slots * gpu::kWorkgroupSize * sizeof(gpu::QuadCutEntry);
        const std::uint32_t offered = ctx.properties().limits.maxComputeSharedMemorySize;
        if (bytes > offered) {
            // The largest cut_heap whose quad heap fits (the tree may cap the slots lower still).
            const std::uint64_t fits = offered / (gpu::kWorkgroupSize * sizeof(gpu::QuadCutEntry)) / 4u;
            why = "a quad's heap of " + std::to_string(slots) + " slots needs " + std::to_string(bytes) +
                  " bytes of shared memory per workgroup, the device offers " + std::to_string(offered) +
                  (fits > 0 ? "; use cut_heap " + std::to_string(fits) + " or less," : "");
        }
    }
    if (why.empty()) return true;
    if (options.cut_sharing == "quad")
        throw std::invalid_argument("cut_sharing \"quad\" on " + ctx.device_name() + ": " + why +
                                    (why.back() == ',' ? " " : "; use ") +
                                    "cut_sharing \"pixel\" or \"auto\", or --device cpu");
    return false;
}

Tuning device_tuning(const Context& ctx, Tuning tuning) {
    const bool cpu = ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    if (tuning.target_dispatch_ms <= 0.0)
        tuning.target_dispatch_ms = cpu ? Tuning::kCpuTargetMs : Tuning::kGpuTargetMs;
    if (tuning.texel_reads == Tuning::TexelReads::kAuto)
        tuning.texel_reads = cpu ? Tuning::TexelReads::kOn : Tuning::TexelReads::kOff;
    if (tuning.specialize_on_host == Tuning::HostSpecialization::kAuto)
        tuning.specialize_on_host = cpu ? Tuning::HostSpecialization::kOn : Tuning::HostSpecialization::kOff;
    if (tuning.heap_memory == Tuning::HeapMemory::kAuto) tuning.heap_memory = Tuning::HeapMemory::kPrivate;
    if (tuning.split_slow_tiles == Tuning::SplitSlowTiles::kAuto)
        tuning.split_slow_tiles = cpu ? Tuning::SplitSlowTiles::kOff : Tuning::SplitSlowTiles::kOn;
    if (tuning.presplit_on_llvmpipe && tuning.refinements_per_dispatch == 0 && driver_limits_loops(ctx)) {
        tuning.refinements_per_dispatch = Tuning::kLlvmpipeRefinements;
        tuning.whole_cut_steps = Tuning::kLlvmpipeWholeCutSteps;
    }
    return tuning;
}

std::uint32_t min_tile_pixels(const Context& ctx, const Tuning& tuning) {
    if (tuning.min_tile_pixels > 0) return tuning.min_tile_pixels;
    if (ctx.properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) return Tuning::kGpuMinTilePixels;
    // lavapipe runs each workgroup on one of its threads (LP_NUM_THREADS,
    // by default one per core); four workgroups per thread keep them all
    // busy to the end of most dispatches.
    const std::uint32_t threads = std::max(1u, std::thread::hardware_concurrency());
    return 4 * threads * gpu::kWorkgroupSize;
}

std::vector<SceneArray> kernel_arrays(const PreparedScene& prepared, const gpu::FrameParams& frame) {
    std::vector<SceneArray> arrays = scene_arrays(prepared);
    arrays.push_back({"frame", &frame, sizeof frame, 1});
    return arrays;
}

gpu::FrameParams frame_params(const Context& ctx, const PreparedScene& prepared,
                              const RenderOptions& options) {
    validate_render_options(options);
    const std::uint32_t push_bytes = ctx.properties().limits.maxPushConstantsSize;
    if (push_bytes < sizeof(gpu::PushConstants))
        throw std::runtime_error("Vulkan device offers " + std::to_string(push_bytes) +
                                 " bytes of push constants; the kernels need " +
                                 std::to_string(sizeof(gpu::PushConstants)));
    return make_frame_params(prepared, options);
}

RenderSetup::RenderSetup(const Context& context, const PreparedScene& prepared,
                         const RenderOptions& options, const gpu::FrameParams& frame,
                         const Tuning& tuning)
    : ctx(context),
      submitter(context),
      timestamps(context),
      method(make_shading_method(options, frame, prepared.tree, tuning,
                                 context.properties().limits.maxComputeSharedMemorySize,
                                 share_cuts(context, prepared.tree, options, frame, tuning))),
      resources(context, submitter, kernel_arrays(prepared, frame), *method,
                std::uint64_t(frame.width) * frame.height, tuning.max_tile_pixels, tuning.split_bytes,
                tuning.texel_reads == Tuning::TexelReads::kOn, tuning.chunk_buffers, tuning.host_import),
      kernels(context, resources.pipeline_layout(), *method,
              {tuning.force_ggx || prepared.has_specular, tuning.force_shadows || prepared.has_occluders,
               tuning.force_oriented || prepared.has_oriented, tuning.force_textures || prepared.has_textures,
               tuning.force_disney || prepared.has_disney, tuning.force_sheen || prepared.has_sheen,
               tuning.force_clearcoat || prepared.has_clearcoat, resources.texel_reads(),
               resources.chunks(), tuning.specialize_on_host == Tuning::HostSpecialization::kOn,
               tuning.heap_memory == Tuning::HeapMemory::kPrivate}),
      pass(context, resources, kernels, *method, timestamps,
           tuning.spread_groups_on_cpu && context.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {}

RenderSetup::~RenderSetup() { ctx.fn().vkDeviceWaitIdle(ctx.device().get()); }

namespace {

// The LC_VK_* variables are developers' switches (docs/vulkan.md). A value
// that a switch does not know is refused, so that a misspelling does not
// quietly measure the default. Unset or empty, a switch keeps its default.
const char* variable(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr && *v != '\0' ? v : nullptr;
}

[[noreturn]] void refuse(const char* name, const std::string& value, const std::string& expected) {
    throw InputError("environment", name, "'" + value + "' is not " + expected);
}

std::uint64_t count_variable(const char* name, const char* v) {
    std::uint64_t n = 0;
    const char* end = v + std::strlen(v);
    const auto [last, ec] = std::from_chars(v, end, n);
    if (ec != std::errc() || last != end) refuse(name, v, "a whole number");
    return n;
}

std::uint32_t count32_variable(const char* name, const char* v) {
    const std::uint64_t n = count_variable(name, v);
    if (n > std::numeric_limits<std::uint32_t>::max()) refuse(name, v, "a whole number below 2^32");
    return std::uint32_t(n);
}

bool flag_variable(const char* name, const char* v) {
    const std::string value = v;
    if (value != "0" && value != "1") refuse(name, value, "0 or 1");
    return value == "1";
}

// One of a switch's two forcing words, or "auto" for its default.
template <class Mode>
Mode mode_variable(const char* name, const char* v, const char* first, Mode first_mode, const char* second,
                   Mode second_mode) {
    const std::string value = v;
    if (value == first) return first_mode;
    if (value == second) return second_mode;
    if (value == "auto") return Mode::kAuto;
    refuse(name, value, std::string(first) + ", " + second + " or auto");
}

}  // namespace

Tuning Tuning::from_environment() {
    Tuning tuning;
    if (const char* v = variable("LC_VK_FORCE_FEATURES")) {
        // Comma-separated names; "all" forces every feature, "none" none.
        std::string_view rest = v;
        while (!rest.empty()) {
            const std::size_t comma = rest.find(',');
            const std::string name(rest.substr(0, comma));
            rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
            const bool all = name == "all";
            bool known = all || name == "none";
            const auto force = [&](const char* feature, bool& field) {
                if (all || name == feature) field = known = true;
            };
            force("ggx", tuning.force_ggx);
            force("shadows", tuning.force_shadows);
            force("oriented", tuning.force_oriented);
            force("textures", tuning.force_textures);
            force("disney", tuning.force_disney);
            force("sheen", tuning.force_sheen);
            force("clearcoat", tuning.force_clearcoat);
            if (!known)
                refuse("LC_VK_FORCE_FEATURES", name,
                       "a feature (ggx, shadows, oriented, textures, disney, sheen, clearcoat, all, none)");
        }
    }
    if (const char* v = variable("LC_VK_MAX_TILE_PIXELS"))
        tuning.max_tile_pixels = count32_variable("LC_VK_MAX_TILE_PIXELS", v);
    if (const char* v = variable("LC_VK_LIGHTS_PER_DISPATCH"))
        tuning.lights_per_dispatch = count32_variable("LC_VK_LIGHTS_PER_DISPATCH", v);
    if (const char* v = variable("LC_VK_REFINEMENTS_PER_DISPATCH"))
        tuning.refinements_per_dispatch = count32_variable("LC_VK_REFINEMENTS_PER_DISPATCH", v);
    if (const char* v = variable("LC_VK_SPLIT_BYTES")) tuning.split_bytes = count_variable("LC_VK_SPLIT_BYTES", v);
    if (const char* v = variable("LC_VK_CHUNK_BUFFERS"))
        tuning.chunk_buffers = flag_variable("LC_VK_CHUNK_BUFFERS", v);
    if (const char* v = variable("LC_VK_HOST_IMPORT")) tuning.host_import = flag_variable("LC_VK_HOST_IMPORT", v);
    if (const char* v = variable("LC_VK_SPREAD_GROUPS"))
        tuning.spread_groups_on_cpu = flag_variable("LC_VK_SPREAD_GROUPS", v);
    if (const char* v = variable("LC_VK_TEXEL_READS"))
        tuning.texel_reads = mode_variable("LC_VK_TEXEL_READS", v, "on", Tuning::TexelReads::kOn, "off",
                                           Tuning::TexelReads::kOff);
    if (const char* v = variable("LC_VK_SPECIALIZE_ON_HOST"))
        tuning.specialize_on_host = mode_variable("LC_VK_SPECIALIZE_ON_HOST", v, "on", Tuning::HostSpecialization::kOn,
                                                  "off", Tuning::HostSpecialization::kOff);
    if (const char* v = variable("LC_VK_HEAP_MEMORY"))
        tuning.heap_memory = mode_variable("LC_VK_HEAP_MEMORY", v, "shared", Tuning::HeapMemory::kShared, "private",
                                           Tuning::HeapMemory::kPrivate);
    if (const char* v = variable("LC_VK_MIN_TILE_PIXELS"))
        tuning.min_tile_pixels = count32_variable("LC_VK_MIN_TILE_PIXELS", v);
    if (const char* v = variable("LC_VK_SPLIT_SLOW_TILES"))
        tuning.split_slow_tiles = mode_variable("LC_VK_SPLIT_SLOW_TILES", v, "on", Tuning::SplitSlowTiles::kOn, "off",
                                                Tuning::SplitSlowTiles::kOff);
    if (const char* v = variable("LC_VK_TARGET_MS")) {
        char* end = nullptr;
        const double ms = std::strtod(v, &end);
        if (*end != '\0' || !(ms > 0.0) || !std::isfinite(ms))
            refuse("LC_VK_TARGET_MS", v, "a positive number of milliseconds");
        tuning.target_dispatch_ms = ms;
    }
    return tuning;
}

namespace {

// Checks what a render must have before a device looks at it: method
// "path" is the CPU's alone, and the options (a wrong one says so on a
// machine without a device too).
void check_before_device(const RenderOptions& options) {
    if (options.method == "path")
        throw std::invalid_argument("method path (the path tracer) runs on the CPU only: use --device cpu");
    validate_render_options(options);
}

// Called while failure `e` is handled: throws it again, as it is where the
// validation layer gave no `messages` during its work, else with them:
// NoVulkanDevice stays NoVulkanDevice, so that callers still tell "no
// device" from a failure (with no driver at all the loader's own messages
// are in the log); anything else becomes std::runtime_error.
[[noreturn]] void rethrow_with(const std::exception& e, const std::vector<std::string>& messages) {
    if (messages.empty()) throw;
    std::string message = e.what();
    for (const std::string& m : messages) message += "\n  validation " + m;
    if (dynamic_cast<const NoVulkanDevice*>(&e)) throw NoVulkanDevice(message);
    throw std::runtime_error(message);
}

// Work that succeeded (a render, a device's opening) but during which the
// validation layer said `messages` fails with them.
void fail_on(const std::vector<std::string>& messages) {
    if (messages.empty()) return;
    std::string message = "Vulkan validation reported " + std::to_string(messages.size()) + " message(s):";
    for (const std::string& m : messages) message += "\n  " + m;
    throw std::runtime_error(message);
}

}  // namespace

RenderResult render_vulkan(const PreparedScene& prepared, const RenderOptions& options,
                           const VulkanOptions& vulkan, const Tuning& tuning) {
    check_before_device(options);
    const Clock::time_point start = Clock::now();
    MessageLog log;
    RenderResult result;
    try {
        // Everything Vulkan is destroyed at the end of this block, so the
        // messages of object destruction are in the log before it is read.
        Context context(vulkan, &log);
        result = render(context, prepared, options, tuning);
    } catch (const std::exception& e) {
        rethrow_with(e, log.take());
    }
    fail_on(log.take());
    result.stats.seconds_total = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
}

}  // namespace lc::vk

namespace lc {

RenderResult render_vulkan(const PreparedScene& prepared, const RenderOptions& options,
                           const VulkanOptions& vulkan) {
    return vk::render_vulkan(prepared, options, vulkan, vk::Tuning::from_environment());
}

// The device and what its renders share. The log is made before the
// context and outlives it: the context reports into it until it is gone.
struct VulkanRenderer::Impl {
    explicit Impl(const VulkanOptions& vulkan) : tuning(vk::Tuning::from_environment()), context(open(vulkan)) {
        // Messages of the device's opening are the constructor's failure,
        // not the first render's.
        vk::fail_on(log.take());
    }
    ~Impl() {
        context.reset();
        for (const std::string& m : log.take())
            std::fprintf(stderr, "lightcuts: Vulkan validation as the device closed: %s\n", m.c_str());
    }

    std::unique_ptr<vk::Context> open(const VulkanOptions& vulkan) {
        try {
            return std::make_unique<vk::Context>(vulkan, &log);
        } catch (const std::exception& e) {
            vk::rethrow_with(e, log.take());
        }
    }

    vk::Tuning tuning;
    vk::MessageLog log;
    std::unique_ptr<vk::Context> context;
    std::mutex mutex;  // one render at a time: the queue and the log are the render's
    std::string lost;  // why the device is lost ("" while it is not): a render failed with it
};

VulkanRenderer::VulkanRenderer(const VulkanOptions& vulkan) : impl_(std::make_unique<Impl>(vulkan)) {}

VulkanRenderer::~VulkanRenderer() = default;
VulkanRenderer::VulkanRenderer(VulkanRenderer&&) noexcept = default;
VulkanRenderer& VulkanRenderer::operator=(VulkanRenderer&&) noexcept = default;

std::string VulkanRenderer::device_name() const { return impl_->context->device_name(); }

RenderResult VulkanRenderer::render(const PreparedScene& prepared, const RenderOptions& options) {
    vk::check_before_device(options);
    std::lock_guard lock(impl_->mutex);
    if (!impl_->lost.empty())
        throw std::runtime_error("the Vulkan device " + device_name() + " was lost in an earlier render (" +
                                 impl_->lost + "): make a new VulkanRenderer");
    const auto start = std::chrono::steady_clock::now();
    RenderResult result;
    try {
        result = vk::render(*impl_->context, prepared, options, impl_->tuning);
    } catch (const std::exception& e) {
        // A device lost, or one that never finished a submission, renders
        // nothing more; any other failure leaves it as it was.
        if (const auto* v = dynamic_cast<const vk::VulkanError*>(&e);
            v != nullptr && (v->result() == VK_ERROR_DEVICE_LOST || v->result() == VK_TIMEOUT))
            impl_->lost = e.what();
        vk::rethrow_with(e, impl_->log.take());
    }
    vk::fail_on(impl_->log.take());
    result.stats.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace lc
