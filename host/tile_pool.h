// The CPU renderers' thread pool: tiles of the image handed out to worker
// threads in turn (host/cpu_renderer.cpp, host/path_tracer.cpp).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "run_on_threads.h"

namespace lc {

// Tile side in pixels: small, so small images still use every core.
inline constexpr std::uint32_t kTile = 8;

// The pixels of a block whose points share one cut (host/quad_cut.h): a
// 2x2 quad's four or a 4x2 octet's eight, point q at (x0 + block_x(q),
// y0 + block_y(q)) from the block's top-left pixel: each quad's four in
// the order of the quad's subgroup lanes (shaders/quadcuts.comp), the left
// quad's first.
constexpr std::uint32_t block_x(std::uint32_t q) { return (q & 1u) + 2u * (q >> 2u); }
constexpr std::uint32_t block_y(std::uint32_t q) { return q >> 1u & 1u; }

template <std::uint32_t N>
using BlockPoints = std::integral_constant<std::uint32_t, N>;

// The order the CPU path cuts the blocks of the tile at (x0, y0) in, at
// its default cut sharing: the tile's 4x2 places row by row, each an
// octet, except that after a place whose cut reached max_cut the next
// places are cut as two quads each, until both stay below it.
// block(BlockPoints<N>{}, x, y, first) cuts the block of N = 8 or 4 points
// at (x, y), `first` the index of its first point within the place (0, or
// 4 for a place's right quad), and returns whether its cut reached
// max_cut; done(x, y) follows each place. render_cpu shades with it, and
// bench/embree_rays records the rays it casts in the same order.
template <typename Block, typename Done>
void for_each_block_of_tile(std::uint32_t x0, std::uint32_t y0, std::uint32_t width, std::uint32_t height,
                            Block&& block, Done&& done) {
    bool as_quads = false;
    for (std::uint32_t y = y0; y < std::min(y0 + kTile, height); y += 2u)
        for (std::uint32_t x = x0; x < std::min(x0 + kTile, width); x += 4u) {
            if (as_quads) {
                const bool left = block(BlockPoints<4>{}, x, y, 0u);
                const bool right = x + 2u < width && block(BlockPoints<4>{}, x + 2u, y, 4u);
                as_quads = left || right;
            } else {
                as_quads = block(BlockPoints<8>{}, x, y, 0u);
            }
            done(x, y);
        }
}

// Runs work(tile, worker) for every tile index below tile_count, one thread
// per element of `workers` (what each thread owns: its heap, its counters).
// An exception in any worker (out of memory, say) stops the others at their
// next tile and reaches the caller as itself (run_on_threads), not as
// std::terminate.
template <typename Worker, typename Work>
void for_each_tile(std::uint32_t tile_count, std::vector<Worker>& workers, Work work) {
    std::atomic<std::uint32_t> next_tile{0};
    run_on_threads(unsigned(workers.size()), [&](unsigned index) {
        try {
            for (std::uint32_t tile; (tile = next_tile.fetch_add(1)) < tile_count;) work(tile, workers[index]);
        } catch (...) {
            next_tile.store(tile_count);
            throw;
        }
    });
}

}  // namespace lc
