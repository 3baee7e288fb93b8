// Cuts the image into tiles sized so that one dispatch takes about
// target_dispatch_ms (Tuning, LC_VK_TARGET_MS), renders every sample of each tile as one pass,
// and renders a tile again with the shading method's work split finer when
// the driver cut the kernels' loops short (lavapipe). Reports progress and
// gathers the image and the per-pixel statistics.
#pragma once

#include <cstdint>
#include <string>

#include "gpu_resources.h"
#include "progress.h"
#include "shading_method.h"
#include "tile_pass.h"
#include "vk_commands.h"

namespace lc::vk {

struct Tile {
    std::uint32_t x0 = 0, y0 = 0, width = 0, height = 0;
    std::uint32_t pixels() const { return width * height; }
};

class TileScheduler {
public:
    TileScheduler(std::string device_name, Submitter& submitter, TilePass& pass,
                  ShadingMethod& method, const GpuResources& resources,
                  const gpu::FrameParams& frame, double target_dispatch_ms,
                  std::uint32_t min_tile_pixels, bool split_slow_tiles, double shading_ms_for_split,
                  bool progress);

    // Renders the whole image into result.image and adds to result.stats:
    // shadow rays, max-cut and spill counts, cut sizes (when the method
    // reports them), GPU stage times and loop-limit retries.
    void render(RenderResult& result);

private:
    // Renders samples [0, spp) of one tile; returns its slowest dispatch in ms.
    double render_tile(const Tile& tile, RenderResult& result);
    double render_samples(const Tile& tile, RenderStats& stats);
    // Pixels of the tile's last pass whose loops the driver cut short;
    // throws on flags that only a kernel bug can raise.
    std::uint32_t loop_limited_pixels(const Tile& tile) const;
    // Splits the method's work finer for a retry of the tile, or throws.
    void split_finer(const Tile& tile, std::uint32_t cut_short);
    void read_back(const Tile& tile, RenderResult& result) const;
    // The next tile's pixel budget, aiming at target_dispatch_ms.
    double next_budget(double budget, double pixels, double slowest_ms) const;

    std::string device_name_;
    Submitter& submitter_;
    TilePass& pass_;
    ShadingMethod& method_;
    const GpuResources& resources_;
    const gpu::FrameParams frame_;
    const double target_dispatch_ms_;
    const std::uint32_t min_tile_pixels_;  // unless the buffers allow fewer
    const bool split_slow_tiles_;
    const double shading_ms_for_split_;  // > 0: taken as every shading dispatch's time (tests)
    double slowest_shading_ms_ = 0.0;  // the current tile's slowest shading dispatch
    Progress progress_;
    std::uint64_t samples_done_ = 0, samples_total_ = 0;
};

}  // namespace lc::vk
