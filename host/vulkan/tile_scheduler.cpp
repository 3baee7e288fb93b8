#include "tile_scheduler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lc::vk {

TileScheduler::TileScheduler(std::string device_name, Submitter& submitter, TilePass& pass,
                             ShadingMethod& method, const GpuResources& resources,
                             const gpu::FrameParams& frame, double target_dispatch_ms,
                             std::uint32_t min_tile_pixels, bool split_slow_tiles, double shading_ms_for_split,
                             bool progress)
    : device_name_(std::move(device_name)),
      submitter_(submitter),
      pass_(pass),
      method_(method),
      resources_(resources),
      frame_(frame),
      target_dispatch_ms_(target_dispatch_ms),
      min_tile_pixels_(min_tile_pixels),
      split_slow_tiles_(split_slow_tiles),
      shading_ms_for_split_(shading_ms_for_split),
      progress_(progress) {}

// Tiles: bands of rows, each cut into tiles of about `budget` pixels. The
// budget adapts so one dispatch takes about target_dispatch_ms (growing at
// most 2x per tile, as the next tile may be harder): starting small keeps
// the first dispatch about one pixel's time (where a pixel's own work takes
// longer than the target, the first dispatch does too; later ones are split
// below), and a pass that the driver's loop limit spoils cheap. After the
// first, a tile never drops below min_tile_pixels (a CPU device's threads
// each need workgroups, a GPU's multiprocessors many) unless the buffers say
// so; with split_slow_tiles, a tile no larger than that whose shading takes
// over 4x the target splits the method's work finer instead.
//
// Cuts shared by quads (ShadingMethod::quad_cuts) need every tile to start
// at an even pixel, so tiles are then an even number of pixels wide and
// high but at the image's last column and row; a tile's quad invocations,
// its size rounded up to even, must fit the tile buffers' invocations.
void TileScheduler::render(RenderResult& result) {
    const std::uint32_t width = frame_.width, height = frame_.height;
    const std::uint32_t max_pixels = resources_.tiles().max_pixels;
    const bool quads = method_.quad_cuts();
    const auto even = [quads](std::uint32_t v) { return quads ? std::max(2u, v & ~1u) : v; };
    const auto rounded_up = [quads](std::uint32_t v) { return quads ? (v + 1u) & ~1u : v; };
    samples_total_ = std::uint64_t(width) * height * frame_.spp;
    // The first tile is a probe of 256 pixels where slow tiles split the
    // work (GPUs): its dispatch takes about one pixel's time, which says
    // how finely to split before the tiles of the smallest size come.
    double budget = std::min<double>(
        split_slow_tiles_ ? 4 * gpu::kWorkgroupSize : std::max(4 * gpu::kWorkgroupSize, min_tile_pixels_),
        max_pixels);
    const double min_budget = std::min<double>(min_tile_pixels_, max_pixels);
    // A quad tile is at least two columns, all of whose rows must fit.
    const std::uint32_t tallest = quads ? std::max(2u, resources_.tiles().invocations / 2u) : max_pixels;
    for (std::uint32_t y0 = 0; y0 < height;) {
        // About square, or as tall as the budget where the image is narrower
        // than that (a band of sqrt(budget) rows made a 1 x 16384 image
        // tiles of sqrt(budget) pixels: 64 of 256 where a GPU's budget is
        // 65,536).
        const double rows = std::max(std::sqrt(budget), budget / width);
        const std::uint32_t band = std::min<std::uint32_t>(
            height - y0, even(std::clamp<std::uint32_t>(std::uint32_t(rows), 1u, tallest)));
        for (std::uint32_t x0 = 0; x0 < width;) {
            std::uint32_t w = even(std::max<std::uint32_t>(1, std::uint32_t(budget / band)));
            std::uint32_t fit = std::max<std::uint32_t>(1, max_pixels / band);
            if (quads) fit = even(std::min(fit, resources_.tiles().invocations / rounded_up(band)));
            w = std::min({w, width - x0, fit});
            const double ms = render_tile({x0, y0, w, band}, result);
            // A tile no larger than the smallest size whose shading still
            // takes too long: each of its pixels' work is too long for one
            // dispatch (on a GPU a tile too small to fill the device takes
            // one pixel's time whatever its size), so that work is split
            // over more dispatches, a quarter each time until the estimate
            // meets the target, instead of the tile shrinking.
            const bool last = x0 + w >= width && y0 + band >= height;
            if (split_slow_tiles_ && !last && budget <= min_budget) {
                const std::uint32_t dispatches = method_.dispatch_count();
                double estimate = slowest_shading_ms_;
                while (estimate > 4 * target_dispatch_ms_ && method_.split_finer()) estimate /= 4;
                if (method_.dispatch_count() > dispatches) result.stats.work_splits += 1;
            }
            budget = next_budget(budget, double(w) * band, ms);
            x0 += w;
        }
        y0 += band;
    }
    progress_.finish();
}

double TileScheduler::next_budget(double budget, double pixels, double slowest_ms) const {
    const double wanted =
        slowest_ms > 0.0 ? pixels * target_dispatch_ms_ / slowest_ms : 4 * budget;
    budget = std::clamp(wanted, budget / 4, budget * 2);
    const double max_pixels = resources_.tiles().max_pixels;
    return std::clamp(budget, std::min<double>(min_tile_pixels_, max_pixels), max_pixels);
}

double TileScheduler::render_tile(const Tile& tile, RenderResult& result) {
    double slowest_ms = 0.0;
    slowest_shading_ms_ = 0.0;
    for (;;) {
        slowest_ms = std::max(slowest_ms, render_samples(tile, result.stats));
        const std::uint32_t cut_short = loop_limited_pixels(tile);
        if (cut_short == 0) break;
        split_finer(tile, cut_short);
        result.stats.loop_limit_retries += 1;
        samples_done_ -= std::uint64_t(tile.pixels()) * frame_.spp;
    }
    read_back(tile, result);
    return slowest_ms;
}

double TileScheduler::render_samples(const Tile& tile, RenderStats& stats) {
    gpu::PushConstants push{};
    push.tile_x = tile.x0;
    push.tile_y = tile.y0;
    push.tile_width = tile.width;
    push.tile_height = tile.height;
    double slowest_ms = 0.0;
    for (std::uint32_t s = 0; s < frame_.spp; ++s) {
        push.sample_index = s;
        const PassTiming t = pass_.run(submitter_, push, s == 0, s + 1 == frame_.spp);
        stats.seconds_primary += t.seconds_primary;
        stats.seconds_shading += t.seconds_shading;
        slowest_ms = std::max(slowest_ms, t.slowest_dispatch_ms);
        slowest_shading_ms_ = std::max(slowest_shading_ms_,
                                       shading_ms_for_split_ > 0.0 ? shading_ms_for_split_ : t.slowest_shading_ms);
        samples_done_ += tile.pixels();
        progress_.update(samples_total_ ? double(samples_done_) / double(samples_total_) : 1.0);
    }
    return slowest_ms;
}

std::uint32_t TileScheduler::loop_limited_pixels(const Tile& tile) const {
    // The flags of the tile's last pass, whose fence has signalled.
    const gpu::PixelStats* pixel_stats = resources_.pixel_stats_sums();
    std::uint32_t cut_short = 0;
    for (std::uint32_t i = 0; i < tile.pixels(); ++i) {
        const std::uint32_t flags = pixel_stats[i].flags;
        // A loop cut short leaves anything behind: that is retried first.
        if (flags & gpu::kPixelLoopLimit) {
            cut_short += 1;
            continue;
        }
        if (flags & gpu::kPixelCutUnfinished)
            throw std::logic_error(
                "Lightcuts kernel: cut unfinished after the last dispatch at pixel (" +
                std::to_string(tile.x0 + gpu::lc_tile_column(i, tile.width, tile.height)) + ", " +
                std::to_string(tile.y0 + gpu::lc_tile_row(i, tile.width, tile.height)) + ")");
    }
    return cut_short;
}

// lavapipe ends an invocation's loops after 65535 iterations in all. The
// work per invocation then shrinks (brute force: fewer lights per dispatch;
// Lightcuts: fewer refinements per dispatch) and the tile starts again.
void TileScheduler::split_finer(const Tile& tile, std::uint32_t cut_short) {
    if (method_.split_finer()) return;
    throw std::runtime_error(
        "the Vulkan device " + device_name_ + " cut the kernels' loops short at " +
        std::to_string(cut_short) + " pixel(s) of tile (" + std::to_string(tile.x0) + ", " +
        std::to_string(tile.y0) + ", " + std::to_string(tile.width) + "x" +
        std::to_string(tile.height) +
        ") even for the smallest split of the work (llvmpipe/lavapipe stops every "
        "shader invocation after 65535 loop iterations)");
}

void TileScheduler::read_back(const Tile& tile, RenderResult& result) const {
    // The tile's means, readable since its last pass's fence signalled.
    const float* sums = resources_.radiance_sums();
    const gpu::PixelStats* pixel_stats = resources_.pixel_stats_sums();
    const double spp = double(frame_.spp);
    RenderStats& out = result.stats;
    for (std::uint32_t i = 0; i < tile.pixels(); ++i) {
        const std::uint32_t x = tile.x0 + gpu::lc_tile_column(i, tile.width, tile.height);
        const std::uint32_t y = tile.y0 + gpu::lc_tile_row(i, tile.width, tile.height);
        const glm::vec3 sum(sums[3 * i], sums[3 * i + 1], sums[3 * i + 2]);
        result.image.set(x, y, sum);  // lc_accumulate divided each sample by spp
        const gpu::PixelStats& ps = pixel_stats[i];
        out.shadow_rays += gpu::count64(ps.shadow_rays_lo, ps.shadow_rays_hi);
        out.max_cut_pixels += ps.max_cut_samples;
        out.heap_frozen_samples += ps.frozen_samples;
        out.heap_paused_samples += ps.paused_samples;
        out.cut_indirect_total += gpu::count64(ps.cut_indirect_lo, ps.cut_indirect_hi);
        // The CPU reference's rounding of the mean, so equal cuts compare equal.
        if (method_.reports_cuts()) {
            out.cut_size[std::size_t(y) * frame_.width + x] =
                float(double(gpu::count64(ps.cut_size_lo, ps.cut_size_hi)) / spp);
            out.heap_froze[std::size_t(y) * frame_.width + x] = float(double(ps.frozen_samples) / spp);
        }
    }
}

}  // namespace lc::vk
