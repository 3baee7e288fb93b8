// What one render did, as one record: printed for people (report_text) and
// written as JSON for scripts (report_json; bench/run reads its keys, so
// keys are added, never renamed). Both are built from the same record, so
// they cannot disagree.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "render.h"

namespace lc {

struct BufferBytes {
    std::string name;
    std::uint64_t bytes = 0;
};

struct LightcutsReport {
    float relative_error = 0.0f;
    std::uint32_t max_cut = 0;
    std::size_t tree_nodes = 0;
    std::uint64_t tree_bytes = 0;
    // Over the pixels that shade a surface, each pixel's mean cut over its
    // samples (at 1 spp its cut): so above 1 spp the largest can be below
    // max_cut where samples reached it.
    double cut_size_mean = 0.0, cut_size_p50 = 0.0, cut_size_p99 = 0.0, cut_size_max = 0.0;
    std::size_t shaded_pixels = 0;            // pixels with a cut (the others see only background)
    double cut_indirect_mean = 0.0;           // of cut_size_mean, VPL clusters (indirect light)
    std::uint64_t max_cut_samples = 0;        // samples whose refinement stopped at max_cut
    std::uint32_t cut_heap = 0;               // render.cut_heap, the heap's capacity K
    std::uint32_t cut_points = 1;             // the pixels that shared each cut (and a heap): 1, 4 for
                                              // 2x2 quads, 8 for 4x2 octets (CPU); cut sizes are then
                                              // the shared cuts' (cut_sharing)
    std::uint32_t heap_slots = 0;             // slots a heap gets: K, or less where the tree
                                              // cannot fill K (GPU: in shared memory); a quad's
                                              // heap: cut_points K, or less
    std::uint64_t heap_bytes = 0;             // GPU: shared memory the heaps of a workgroup take
    bool heap_private = false;                // GPU: each heap in its invocation's private memory instead
    std::uint32_t workgroup_size = 0;         // GPU: invocations per workgroup
    std::uint64_t heap_frozen_samples = 0;    // samples whose cut froze clusters out of a full heap
    std::uint64_t heap_paused_samples = 0;    // GPU: samples whose heap waited in global memory
                                              // between dispatches
};

struct SamplingReport {
    std::uint32_t light_samples = 0;          // sampled: per camera sample; stochastic: per cluster
    std::string light_pick;                   // sampled: "tree", "uniform" or "power"; stochastic: ""
};

// Indirect light through VPLs (render.indirect).
struct IndirectReport {
    std::size_t vpls = 0;                     // in `lights`
    std::size_t paths = 0;                    // light paths traced to leave them
    std::uint32_t max_bounces = 0;            // VPLs per path at most; 0: roulette
    float clamp = 0.0f;                       // distance where a VPL's 1/d^2 stops growing
};

struct RenderReport {
    std::string scene, method, device;
    std::uint32_t width = 0, height = 0, spp = 0, seed = 0;
    std::uint32_t spp_requested = 0;         // spp is what was rendered (path: less at a time limit)
    std::uint32_t max_bounces = 0;           // path only
    double time_limit = 0.0;                 // path only: seconds, 0 = none
    std::size_t triangles = 0, lights = 0, bvh_nodes = 0;
    std::size_t black_lights = 0;             // zero-intensity lights left out of the tree
    std::size_t area_lights = 0;              // samples of the emissive surfaces (in `lights`, or black)
    std::size_t environment_lights = 0;       // directions of the environment (in `lights`)
    std::size_t emissive_triangles = 0;       // of `triangles`, with an emissive material
    bool environment_map = false;             // the scene has one (the path tracer samples it as it is)
    struct Seconds {
        double load = 0.0, bvh_build = 0.0, light_tree_build = 0.0, light_sampling = 0.0, vpls = 0.0;
        double render = 0.0, primary = 0.0, shading = 0.0;
    } seconds;
    std::uint64_t camera_rays = 0, shadow_rays = 0, bounce_rays = 0;  // bounce: path's continuations
    double shadow_rays_per_pixel = 0.0, rays_per_second = 0.0;
    std::uint32_t loop_limit_retries = 0;     // GPU: times a tile was redone with the work split finer
    std::uint32_t work_splits = 0;            // GPU: times the work was split finer for slow small tiles
    // The kernels' arrays (scene_arrays), then the device's own buffers; a
    // device buffer of the same name replaces the scene array's entry.
    std::vector<BufferBytes> buffer_bytes;
    std::optional<LightcutsReport> lightcuts; // methods "lightcuts" and "stochastic"
    std::optional<SamplingReport> sampling;   // methods "sampled" and "stochastic"
    std::optional<IndirectReport> indirect;   // scenes with VPLs
};

// `scene_file` is reported as given; `load_seconds` is the time load_scene took.
RenderReport make_report(const std::string& scene_file, const RenderOptions& options,
                         const PreparedScene& prepared, const RenderResult& result, double load_seconds);

// A few lines for a terminal, each ending in '\n'.
std::string report_text(const RenderReport& report);

// The report as an indented JSON object, ending in '\n'.
std::string report_json(const RenderReport& report);

// The sizes of the arrays the kernels read, in scene_arrays() order.
std::vector<BufferBytes> scene_buffer_bytes(const PreparedScene& prepared);

// One indented line per buffer ("    name   1.5 MiB") and a total line.
std::string buffer_table(const std::vector<BufferBytes>& buffers);

}  // namespace lc
