// CPU reference renderer: the shared kernels (host/cpu_kernel.h) run per
// pixel over 8x8 tiles handed out to worker threads; Lightcuts' cuts are
// shared by the eight pixels of each 4x2 octet of a tile (host/quad_cut.h),
// or by the four of each 2x2 quad (cut_sharing "quad"), unless cut_sharing
// is "pixel". Every pixel (or block) is computed independently in a fixed
// order, so the image is bit-identical whatever the thread count.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <limits>
#include <string>
#include <thread>

#include "cpu_kernel.h"
#include "lightcuts/render.h"
#include "progress.h"
#include "quad_cut.h"
#include "tile_pool.h"

namespace lc {
namespace {

// What each worker thread owns: its cut heap (a point's, a quad's or an
// octet's) and its counters, on cache lines of its own (the counters change
// at every pixel).
struct alignas(64) Worker {
    cpu::CutHeap heap;
    cpu::QuadHeap quad_heap;
    cpu::OctetHeap octet_heap;
    std::uint64_t shadow_rays = 0;
    std::uint64_t max_cut_hits = 0;
    std::uint64_t cut_indirect = 0;
    std::uint64_t frozen_samples = 0;
};

// All samples of one pixel: the mean radiance and the mean cut size.
struct PixelResult {
    glm::vec3 radiance{0.0f};
    float cut_size = 0.0f;
    float heap_froze = 0.0f;  // fraction of samples whose cut froze clusters
};

enum class Method { kBrute, kLightcuts, kSampled, kStochastic };

Method method_of(const std::string& name) {
    if (name == "lightcuts") return Method::kLightcuts;
    if (name == "sampled") return Method::kSampled;
    if (name == "stochastic") return Method::kStochastic;
    return Method::kBrute;
}

// One camera sample's reflected light at `sp` by `method`.
glm::vec3 shade_point(cpu::ShadeKernel& k, const gpu::FrameParams& frame, Method method,
                      const cpu::ShadeKernel::SurfacePoint& sp, std::uint32_t stream,
                      cpu::ShadeKernel::ShadeStats& ss) {
    switch (method) {
        case Method::kLightcuts: return k.lc_shade_lightcuts(sp, frame, ss);
        case Method::kStochastic: return k.lc_shade_stochastic(sp, frame, stream, ss);
        case Method::kSampled:
            // The mean over the light samples, as the Vulkan kernel makes it.
            return k.lc_shade_sampled(sp, frame, stream, 0u, frame.light_samples, ss);
        case Method::kBrute: break;
    }
    return k.lc_shade_brute_packets(sp, frame.light_count, frame.min_distance2, ss);
}

// Adds one camera sample's shading stats to the worker's counters; true if
// its cut froze clusters.
bool tally(Worker& t, const cpu::ShadeKernel::ShadeStats& ss) {
    t.shadow_rays += ss.shadow_rays;
    t.max_cut_hits += ss.hit_max_cut;
    t.cut_indirect += ss.cut_indirect;
    t.frozen_samples += ss.frozen > 0u ? 1u : 0u;
    return ss.frozen > 0u;
}

PixelResult shade_pixel(cpu::ShadeKernel& k, const gpu::FrameParams& frame, Method method, std::uint32_t x,
                        std::uint32_t y, Worker& t) {
    const float per_sample = 1.0f / float(frame.spp);
    glm::vec3 mean(0.0f);
    std::uint64_t cut_sum = 0;
    std::uint32_t froze = 0;
    for (std::uint32_t s = 0; s < frame.spp; ++s) {
        cpu::ShadeKernel::SurfacePoint sp;
        glm::vec3 seen;
        const bool hit = k.lc_camera_sample(frame, x, y, s, sp, seen);
        mean += seen * per_sample;
        if (!hit) continue;
        cpu::ShadeKernel::ShadeStats ss{};
        mean += shade_point(k, frame, method, sp, k.lc_sample_stream(frame.seed, x, y, s), ss) * per_sample;
        cut_sum += ss.cut_size;
        froze += tally(t, ss) ? 1u : 0u;
    }
    return {mean, float(double(cut_sum) / frame.spp), float(double(froze) / frame.spp)};
}

// The block of N pixels at (x0, y0) (those inside the image), its samples
// shaded by one shared cut (host/quad_cut.h): a 2x2 quad for N = 4, two
// quads side by side (a 4x2 octet) for N = 8, point q at pixel (x0 +
// block_x(q), y0 + block_y(q)) (host/tile_pool.h). Returns whether some
// sample's cut stopped at max_cut.

template <std::uint32_t N>
bool shade_block(cpu::ShadeKernel& k, const gpu::FrameParams& frame, std::uint32_t x0, std::uint32_t y0, Worker& t,
                 PixelResult* out) {
    const float per_sample = 1.0f / float(frame.spp);
    glm::vec3 mean[N] = {};
    std::uint64_t cut_sum[N] = {};
    std::uint32_t froze[N] = {};
    cpu::BlockHeap<N>* heap;
    if constexpr (N == 4u) heap = &t.quad_heap;
    else heap = &t.octet_heap;
    cpu::BlockCut<cpu::ShadeKernel, N> block(k, *heap, frame);
    bool hit = false;
    for (std::uint32_t s = 0; s < frame.spp; ++s) {
        cpu::ShadeKernel::SurfacePoint sp[N];
        unsigned active = 0u;
        for (std::uint32_t q = 0; q < N; ++q) {
            const std::uint32_t x = x0 + block_x(q), y = y0 + block_y(q);
            if (x >= frame.width || y >= frame.height) continue;
            glm::vec3 seen;
            if (k.lc_camera_sample(frame, x, y, s, sp[q], seen)) active |= 1u << q;
            mean[q] += seen * per_sample;
        }
        if (active == 0u) continue;
        glm::vec3 radiance[N];
        cpu::ShadeKernel::ShadeStats ss[N];
        block.shade(sp, active, radiance, ss);
        for (std::uint32_t q = 0; q < N; ++q) {
            if ((active >> q & 1u) == 0u) continue;
            mean[q] += radiance[q] * per_sample;
            cut_sum[q] += ss[q].cut_size;
            froze[q] += tally(t, ss[q]) ? 1u : 0u;
            hit = hit || ss[q].hit_max_cut != 0u;
        }
    }
    for (std::uint32_t q = 0; q < N; ++q)
        out[q] = {mean[q], float(double(cut_sum[q]) / frame.spp),
                  float(double(froze[q]) / frame.spp)};
    return hit;
}

// A tile's pixels, 4x2 at a time, by octets' cuts where they stay below
// max_cut. The union of eight points' refinements is capped at max_cut
// like one point's cut (each point casts a ray for nearly every cluster
// of it), so where the cuts are long the cap leaves each point less of a
// cut of its own than a quad's would: on the spot gallery, every octet
// cut alike, relative RMSE against brute force 0.0384 -> 0.0425 and 17.6%
// -> 22.1% of its pixels above 5% (128x128). So after an octet whose cut
// reached max_cut the tile's next blocks are cut as two quads, until both
// stay below it (0.0403 and 18.5%, at 0.80 of the quads' time;
// for_each_block_of_tile, host/tile_pool.h). Tiles are shaded in a fixed
// order, so the image does not depend on the threads. store(x, y, result)
// takes each pixel's result.
template <class Store>
void shade_tile_by_octets(cpu::ShadeKernel& k, const gpu::FrameParams& frame, std::uint32_t x0, std::uint32_t y0,
                          Worker& t, const Store& store) {
    PixelResult px[8];
    for_each_block_of_tile(
        x0, y0, frame.width, frame.height,
        [&](auto points, std::uint32_t x, std::uint32_t y, std::uint32_t first) {
            return shade_block<decltype(points)::value>(k, frame, x, y, t, px + first);
        },
        [&](std::uint32_t x, std::uint32_t y) {
            for (std::uint32_t q = 0; q < 8u; ++q) {
                const std::uint32_t qx = x + block_x(q), qy = y + block_y(q);
                if (qx < frame.width && qy < frame.height) store(qx, qy, px[q]);
            }
        });
}

}  // namespace

RenderResult render_cpu(const PreparedScene& prepared, const RenderOptions& options) {
    validate_render_options(options);
    if (options.method == "path") return render_path(prepared, options);
    const Method method = method_of(options.method);
    const bool lightcuts = method_selects_cuts(options.method);
    const gpu::FrameParams frame = make_frame_params(prepared, options);
    // Benchmarks only (bench/speed.py): the camera rays alone, each pixel's
    // first hit and what it sees there (emission, the environment), no light
    // shaded; the per-ray cost the issue asks for leaves their time out.
    const bool camera_only = cpu::environment_flag("LC_CPU_CAMERA_RAYS_ONLY");
    auto start = std::chrono::steady_clock::now();

    RenderResult result;
    result.image = Image(frame.width, frame.height);
    RenderStats& stats = result.stats;
    stats.device = "cpu";
    if (lightcuts) {
        stats.cut_size.assign(std::size_t(frame.width) * frame.height, 0.0f);
        stats.heap_froze.assign(std::size_t(frame.width) * frame.height, 0.0f);
    }

    const std::uint32_t tiles_x = (frame.width + kTile - 1) / kTile;
    const std::uint32_t tile_count = tiles_x * ((frame.height + kTile - 1) / kTile);
    unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
    std::vector<Worker> workers(std::max(1u, std::min(threads, tile_count)));
    const std::uint32_t cut_points = cpu_cut_points(options.method, options.cut_sharing);
    // A shared cut's heap pools its points' K slots: the same number of
    // slots per point (a quad's slot holds the four points' bounds and
    // contributions, 76 bytes with its key and handle against a point's 20,
    // an octet's 140). With K slots a quad, the union of four points'
    // refinements froze far more: on the stress tests' million lights the
    // error against brute force was 0.0259, against a cut per pixel's
    // 0.0169; pooled, 0.0140.
    const std::uint32_t heap_slots =
        prepared.tree.cut_heap_slots(frame.max_cut, shared_cut_heap(options.cut_heap, cut_points));
    for (Worker& w : workers) {
        w.heap = cpu::CutHeap(lightcuts && cut_points == 1u ? heap_slots : 0);
        // Octets take a quad's heap too, for their tiles' blocks cut as
        // quads (shade_tile_by_octets).
        w.quad_heap = cpu::QuadHeap(
            cut_points >= 4u ? prepared.tree.cut_heap_slots(frame.max_cut, shared_cut_heap(options.cut_heap, 4u)) : 0);
        w.octet_heap = cpu::OctetHeap(cut_points == 8u ? heap_slots : 0);
    }
    std::atomic<std::uint32_t> tiles_done{0};
    Progress progress(options.progress);

    const auto store = [&](std::uint32_t x, std::uint32_t y, const PixelResult& px) {
        result.image.set(x, y, px.radiance);
        if (!lightcuts) return;
        stats.cut_size[std::size_t(y) * frame.width + x] = px.cut_size;
        stats.heap_froze[std::size_t(y) * frame.width + x] = px.heap_froze;
    };
    for_each_tile(tile_count, workers, [&](std::uint32_t tile, Worker& t) {
        cpu::ShadeKernel k = cpu::make_shade_kernel(prepared, &t.heap);
        const std::uint32_t x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
        if (camera_only) {
            for (std::uint32_t y = y0; y < std::min(y0 + kTile, frame.height); ++y)
                for (std::uint32_t x = x0; x < std::min(x0 + kTile, frame.width); ++x) {
                    const float per_sample = 1.0f / float(frame.spp);
                    glm::vec3 mean(0.0f);
                    for (std::uint32_t s = 0; s < frame.spp; ++s) {
                        cpu::ShadeKernel::SurfacePoint sp;
                        glm::vec3 seen;
                        k.lc_camera_sample(frame, x, y, s, sp, seen);
                        mean += seen * per_sample;
                    }
                    store(x, y, {mean, 0.0f, 0.0f});
                }
            progress.update(double(tiles_done.fetch_add(1) + 1) / tile_count);
            return;
        }
        if (cut_points == 8u) {
            shade_tile_by_octets(k, frame, x0, y0, t, store);
            progress.update(double(tiles_done.fetch_add(1) + 1) / tile_count);
            return;
        }
        if (cut_points == 4u) {
            for (std::uint32_t y = y0; y < std::min(y0 + kTile, frame.height); y += 2u)
                for (std::uint32_t x = x0; x < std::min(x0 + kTile, frame.width); x += 2u) {
                    PixelResult px[4];
                    shade_block<4>(k, frame, x, y, t, px);
                    for (std::uint32_t q = 0; q < 4u; ++q) {
                        const std::uint32_t qx = x + block_x(q), qy = y + block_y(q);
                        if (qx < frame.width && qy < frame.height) store(qx, qy, px[q]);
                    }
                }
            progress.update(double(tiles_done.fetch_add(1) + 1) / tile_count);
            return;
        }
        for (std::uint32_t y = y0; y < std::min(y0 + kTile, frame.height); ++y)
            for (std::uint32_t x = x0; x < std::min(x0 + kTile, frame.width); ++x)
                store(x, y, shade_pixel(k, frame, method, x, y, t));
        progress.update(double(tiles_done.fetch_add(1) + 1) / tile_count);
    });
    progress.finish();

    for (const auto& t : workers) {
        stats.shadow_rays += t.shadow_rays;
        stats.max_cut_pixels += t.max_cut_hits;
        stats.cut_indirect_total += t.cut_indirect;
        stats.heap_frozen_samples += t.frozen_samples;
    }
    if (lightcuts) stats.heap_slots = heap_slots;
    stats.cut_points = cut_points;
    stats.spp_done = frame.spp;
    stats.camera_rays = std::uint64_t(frame.width) * frame.height * frame.spp;
    stats.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats.seconds_shading = stats.seconds_total;  // the CPU does not time the stages apart
    return result;
}

}  // namespace lc

