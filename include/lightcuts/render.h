// Rendering a loaded scene, on the CPU reference or through Vulkan compute.
#pragma once

#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "bvh.h"
#include "image.h"
#include "light_tree.h"
#include "scene.h"
#include "settings.h"

namespace lc {

// A scene ready to render: triangles reordered by the BVH, the light tree
// built, frame constants filled. Built once, rendered by either device.
struct PreparedScene {
    Scene scene;                 // triangles/normals in BVH leaf order
    Bvh bvh;
    LightTree tree;              // lights in leaf order (also used by brute force)
    float min_distance2 = 0.0f;  // clamp of the inverse-square falloff
    bool has_specular = false;   // any material with a GGX lobe
    bool has_occluders = true;   // false: no triangle can block a light
    bool has_oriented = false;   // any spot or oriented light (emission cones matter)
    bool has_textures = false;   // any material with a texture
    bool has_disney = false;     // any Disney material
    bool has_sheen = false;      // ... with a sheen lobe
    bool has_clearcoat = false;  // ... with a clearcoat lobe
    // Lights made from emissive triangles and from the environment (they are
    // in the tree, after the scene's own lights), and the time that took.
    std::size_t area_lights = 0;
    std::size_t environment_lights = 0;
    double light_sampling_seconds = 0.0;
    // Virtual point lights (render.indirect, host/vpls.h): how many, the light
    // paths that left them, the time tracing took, and their falloff clamp.
    std::size_t vpls = 0;
    std::size_t vpl_paths = 0;
    double vpl_seconds = 0.0;
    float vpl_min_distance2 = 0.0f;
};

// Takes ownership of the scene; builds the BVH and the light tree. The
// light sampling, the VPLs and the tree's build run on `threads` threads
// (0: one per core), as the CPU render does (RenderOptions::threads); what
// they make is the same for any count.
PreparedScene prepare_scene(Scene scene, std::uint32_t seed, unsigned threads = 0);

// One array the kernels read, as raw bytes. scene_arrays() is the one list
// of them: the Vulkan renderer uploads it (in this order, which is the order
// of the bindings kBindingBvhNodes .. kBindingEnvironment) and the CLI
// reports its sizes.
struct SceneArray {
    const char* name;         // "bvh_nodes", "triangles", ...
    const void* data;
    std::size_t element_bytes;
    std::size_t count;
    // The bytes from `data` on that the array's allocation owns, where they
    // are whole pages (UninitializedVector's large arrays); 0 otherwise.
    std::uint64_t page_bytes = 0;
    std::uint64_t bytes() const { return std::uint64_t(element_bytes) * count; }
};
std::vector<SceneArray> scene_arrays(const PreparedScene& prepared);

struct RenderOptions {
    std::string method = "brute";     // "brute", "lightcuts", "sampled", "stochastic" or "path"
    std::uint32_t width = 0, height = 0;  // 0: the scene's camera size
    std::uint32_t spp = 1;
    float relative_error = 0.02f;
    std::uint32_t max_cut = 1000;
    std::uint32_t cut_heap = kDefaultCutHeap;  // lightcuts: cut-heap capacity K per shaded point
                                               // (where pixels share cuts, a shared cut's heap pools
                                               // their K slots)
    std::string cut_sharing = "auto";  // lightcuts: "pixel", "quad", "octet" or "auto" ("octet" on the CPU,
                                       // "pixel" on Vulkan)
                                       // (cut_sharing_problem, lightcuts/settings.h)
    std::uint32_t seed = 1;
    std::uint32_t light_samples = 1;  // sampled: lights per camera sample; stochastic: draws per cluster
    std::string light_pick = "tree";  // sampled: "tree", "uniform" or "power"
    std::uint32_t max_bounces = 0;    // path: surface interactions per path; 0 = unlimited (roulette)
    double time_limit = 0.0;          // path: end near this many
                                      // seconds, with the samples done so far; 0 = no limit
    unsigned threads = 0;             // CPU: 0 = all cores
    bool progress = false;            // show percentage and ETA on stderr
};

struct RenderStats {
    std::string device;               // "cpu" or the Vulkan device name
    double seconds_total = 0.0;
    double seconds_primary = 0.0;     // camera rays (GPU: timestamp queries)
    double seconds_shading = 0.0;     // cut selection + shading or brute force
    std::uint32_t spp_done = 0;       // samples per pixel rendered (path: fewer at a time limit)
    std::uint64_t camera_rays = 0;
    std::uint64_t shadow_rays = 0;
    std::uint64_t bounce_rays = 0;          // path: the rays that continue paths after a bounce
    std::uint64_t max_cut_pixels = 0;       // samples where refinement hit max_cut
    std::uint32_t cut_points = 1;           // lightcuts: the pixels that shared each cut: 1, 4 (2x2
                                            // quads) or 8 (4x2 octets; cut_sharing); the heap is theirs
    std::uint32_t heap_slots = 0;           // lightcuts: cut-heap slots per shaded point (GPU: in
                                            // shared memory), min(cut_heap, what the tree can fill);
                                            // per shared cut: min(cut_points cut_heap, ...)
    std::uint64_t heap_frozen_samples = 0;  // lightcuts: samples whose cut froze clusters out of a
                                            // full heap
    std::uint64_t heap_paused_samples = 0;  // GPU: samples whose heap waited in global memory
                                            // between dispatches (the driver's loop limit)
    std::uint64_t heap_shared_bytes = 0;    // GPU: shared memory of one workgroup's heaps
    bool heap_private = false;              // GPU: the heaps in each invocation's private memory
                                            // instead (CPU devices, heap.glsl)
    std::uint32_t workgroup_size = 0;       // GPU: invocations per workgroup
    std::uint32_t loop_limit_retries = 0;   // GPU: times a tile was rendered again with the work split
                                            // over more dispatches (the driver cut loops short)
    std::uint32_t work_splits = 0;          // GPU: times each pixel's work was split over more
                                            // dispatches, as tiles of the smallest size took too long
    std::vector<float> cut_size;      // per pixel, mean over samples (lightcuts only)
    std::vector<float> heap_froze;    // per pixel, the fraction of samples whose cut froze
                                      // clusters out of a full heap (lightcuts only)
    std::uint64_t cut_indirect_total = 0;  // lightcuts: VPL clusters, summed over every sample's cut
    std::vector<std::pair<std::string, std::uint64_t>> buffer_bytes;
};

struct RenderResult {
    Image image;
    RenderStats stats;
};

// The options a scene asks for: its `render` block (method, spp, error,
// cut limits, seed, sampling, path settings) and its camera's image size.
// The command line starts from these and overrides what it is given.
RenderOptions scene_render_options(const Scene& scene);

// Throws std::invalid_argument naming the first option out of the ranges of
// lightcuts/settings.h; both renderers call it on what they are given.
void validate_render_options(const RenderOptions& options);

// Frame constants for a tile of the image; shared by CPU and GPU paths.
gpu::FrameParams make_frame_params(const PreparedScene& prepared, const RenderOptions& options);

RenderResult render_cpu(const PreparedScene& prepared, const RenderOptions& options);

// --method path: the unbiased CPU path tracer (host/path_tracer.cpp), the
// reference for indirect light. render_cpu calls it for that method.
RenderResult render_path(const PreparedScene& prepared, const RenderOptions& options);

struct VulkanOptions {
    std::string gpu;                  // "" = best available; an index or a name substring
    bool validation = false;          // enable VK_LAYER_KHRONOS_validation; messages are errors
};

// Thrown when there is no Vulkan loader or no Vulkan device at all (as
// opposed to a device that exists but fails); the CLI then falls back to the
// CPU for --device auto.
struct NoVulkanDevice : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws NoVulkanDevice when no Vulkan device exists, std::runtime_error on
// other failures. The device is opened for the render and closed after it
// (VulkanRenderer keeps one open); validation messages while it closes are
// errors too.
RenderResult render_vulkan(const PreparedScene& prepared, const RenderOptions& options,
                           const VulkanOptions& vulkan = {});

// A Vulkan device kept open for several renders: the instance, the device
// and the pipelines' cache are made once, by the constructor, and each
// render makes only its scene's buffers, its kernels' pipelines (from the
// cache, where the driver keeps pipelines there) and its passes. Each
// render() is what render_vulkan gives for the same arguments: the same
// image and counts, its times its own, `seconds_total` without the
// device's opening. What that saves depends on the driver: on lavapipe (Mesa 22.3)
// opening the device takes 0.08 to 0.1 s the first time in a process,
// most of it loading LLVM, and little later (the driver stays loaded), and
// its pipeline cache keeps nothing, so there renders through a
// VulkanRenderer take as long as render_vulkan's after the first
// (bench/vulkan_renders). Any PreparedScene and options, one render at a
// time: render() holds a lock for its whole call, so renders from several
// threads run one after another (and none may still run when the renderer
// is destroyed). A render that fails leaves the renderer as it was, but
// for a device lost (or one that never finished a submission): every later
// render then says so, and a new VulkanRenderer is needed. The Vulkan
// settings (LC_VK_*, docs/vulkan.md) are read once, by the constructor.
// The pipeline cache keeps what a driver puts there for the renderer's
// life, a set of kernels for each kind of scene and options rendered. With
// validation on, a message while the device opens is the constructor's
// error and one during a render that render's (std::runtime_error);
// messages when the device closes, which the destructor cannot throw, are
// written to standard error. A moved-from VulkanRenderer may only be
// destroyed or assigned to.
class VulkanRenderer {
public:
    // Throws NoVulkanDevice when no usable Vulkan device exists,
    // std::runtime_error on other failures, among them a vulkan.gpu that
    // names none of the devices (as render_vulkan does).
    explicit VulkanRenderer(const VulkanOptions& vulkan = {});
    ~VulkanRenderer();
    VulkanRenderer(VulkanRenderer&&) noexcept;
    VulkanRenderer& operator=(VulkanRenderer&&) noexcept;

    // The device's name, as the render's stats give it.
    std::string device_name() const;
    // render_vulkan's render on this device; the same errors, but for
    // NoVulkanDevice.
    RenderResult render(const PreparedScene& prepared, const RenderOptions& options);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The Vulkan devices present, found by one Vulkan instance: the loader
// loads every installed driver for it (on a machine without a GPU, Mesa's
// drivers and LLVM: 0.08 s on the development machine).
struct VulkanDevices {
    std::vector<std::string> names;  // in index order; none if none or no loader
    // Some usable device runs on real GPU hardware (discrete, integrated or
    // virtual GPU), as opposed to a software rasterizer such as lavapipe,
    // which is slower than the CPU path.
    bool hardware = false;
};
VulkanDevices find_vulkan_devices();

// The device files through which a GPU's Vulkan driver reaches its
// hardware on Linux, found under `dev` (normally /dev): DRM render nodes
// (dri/renderD*: AMD, Intel, Broadcom, virtio-gpu, ...), NVIDIA's
// (nvidia0, ...), WSL's dxg, Qualcomm's kgsl* and Arm's mali*. Names
// relative to `dev`, sorted; none on a machine without a GPU (or a
// container not given one).
std::vector<std::string> gpu_device_files(const std::string& dev = "/dev");

// What device "auto" needs to know: find_vulkan_devices(), or, on Linux
// where no gpu_device_files exist and the Vulkan loader is not pointed at
// particular drivers (VK_DRIVER_FILES, VK_ICD_FILENAMES), no hardware
// without loading any driver (`skipped` says so): no driver could reach a
// GPU there, and loading Mesa's took 0.1 s of a 0.37 s render.
struct GpuProbe {
    VulkanDevices devices;
    bool skipped = false;
};
GpuProbe probe_gpus();

// find_vulkan_devices().names.
std::vector<std::string> list_vulkan_devices();

// ---- Device choice: which of the two renderers runs a render ----

struct DeviceChoice {
    std::string device = "auto";  // "auto", "cpu" or "vulkan"
    VulkanOptions vulkan;
    // Receives the one line that says why "auto" renders on the CPU (no
    // hardware GPU, no Vulkan at all); unset: nothing is said.
    std::function<void(const std::string&)> note;
    // "auto": probe_gpus()'s answer where the caller asked for it early,
    // e.g. while the scene loads (the CLI does); not valid(): it is asked
    // when needed.
    std::shared_future<GpuProbe> devices;
};

// What is wrong with a device name, or "" for "auto", "cpu" and "vulkan".
std::string device_problem(std::string_view device);

// What is wrong with asking for Vulkan's options (`vulkan.validation`, a
// `vulkan.gpu`) of a render that cannot use Vulkan: device "cpu", or
// method "path" (the CPU's alone) under device "auto"; "" otherwise.
// Device "vulkan" with method "path" is render_vulkan's error.
std::string vulkan_options_problem(const DeviceChoice& choice, std::string_view method);

// "cpu": render_cpu. "vulkan": render_vulkan, whatever the device, failing
// as it fails (NoVulkanDevice included). "auto": Vulkan on a hardware GPU or
// on the device `vulkan.gpu` names; otherwise, or when render_vulkan throws
// NoVulkanDevice, the CPU, with a note (only a software rasterizer such as
// lavapipe is slower than the CPU path). Throws std::invalid_argument for
// any other device name, and for vulkan_options_problem.
RenderResult render(const PreparedScene& prepared, const RenderOptions& options, const DeviceChoice& choice);

}  // namespace lc
