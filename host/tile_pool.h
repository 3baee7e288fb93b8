// The CPU renderers' thread pool: tiles of the image handed out to worker
// threads in turn (host/cpu_renderer.cpp, host/path_tracer.cpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "run_on_threads.h"

namespace lc {

// Tile side in pixels: small, so small images still use every core.
inline constexpr std::uint32_t kTile = 8;

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
