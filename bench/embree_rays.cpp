// Shadow rays per second: the software BVH (shaders/lc_shared/trace.h, as the
// CPU path runs it) against Embree 3 on the same rays: the ones brute force
// traces on a scene (from every camera hit to every light that can light
// it), the ones lightcuts traces with a cut per pixel (recorded by the
// CPU's scalar kernel as it selects the cuts at the scene's error, max_cut
// and heap: the cuts the Vulkan kernels select), and the ones the CPU path
// traces at its defaults, each cut shared by an octet of pixels (recorded
// with the packets the renderer traces them in: an octet's eight points'
// or a quad's four points' rays to one light).
//
//   build/bench/embree_rays SCENE [SIZE] [THREADS] [REPEATS]
//
// Brute force's rays are collected at SIZE x SIZE (default 32), lightcuts'
// at 128 x 128 (a few hundred rays per pixel instead of one per light).
//
// Brute force's rays are traced in two orders: as it casts them (pixel by
// pixel, each pixel's rays to all lights) and light by light (the rays of
// every pixel to one light, then the next light), which is the coherence
// lightcuts could use by tracing a tile's rays to the same cluster
// together; lightcuts' rays also with each point's rays sorted by direction
// (what gathering a pixel's rays before tracing them could give); the
// octets' rays also in the renderer's own packets. Embree
// runs single rays (rtcOccluded1), packets of 4, 8 and 16 consecutive
// rays (rtcOccluded4/8/16, each where the device says it supports that
// width natively: 16 needs AVX-512) and streams (rtcOccluded1M over 256
// rays, flagged coherent and incoherent), on a scene built at
// RTC_BUILD_QUALITY_HIGH (spatial splits, for static geometry). Every figure is the median of
// REPEATS timed runs (default 3). Built only where Debian's libembree-dev
// is installed (an optional, benchmark-only dependency).
#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "cpu_kernel.h"
#include "quad_cut.h"
#include "tile_pool.h"
#include "wide_trace.h"
#include "lightcuts/scene.h"

namespace {

struct ShadowRay {
    glm::vec3 org;
    glm::vec3 dir;
    float t_max;
    std::uint32_t light;  // for the light-by-light order
};

unsigned g_repeats = 3;

// Runs trace(thread, begin, end) over [0, n) split into `threads`
// contiguous parts, g_repeats times; returns the median of the seconds each
// run took (each run gives the same counts).
double timed_parallel(std::size_t n, unsigned threads,
                      const std::function<void(unsigned, std::size_t, std::size_t)>& trace) {
    std::vector<double> seconds;
    for (unsigned run = 0; run < g_repeats; ++run) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<std::thread> pool;
        for (unsigned t = 0; t < threads; ++t)
            pool.emplace_back(trace, t, n * t / threads, n * (t + 1) / threads);
        for (auto& th : pool) th.join();
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(seconds.begin(), seconds.end());
    return seconds[seconds.size() / 2];
}

RTCRay to_rtc_ray(const ShadowRay& r) {
    RTCRay ray{};
    ray.org_x = r.org.x, ray.org_y = r.org.y, ray.org_z = r.org.z;
    ray.dir_x = r.dir.x, ray.dir_y = r.dir.y, ray.dir_z = r.dir.z;
    ray.tnear = 0.0f, ray.tfar = r.t_max, ray.mask = ~0u;
    return ray;
}

// Rays [first, first + count) as a packet of the software BVH (count at
// most R).
template <unsigned R>
lc::cpu::RayPacket<R> to_packet(const ShadowRay* first, std::size_t count) {
    lc::cpu::RayPacket<R> packet;
    for (std::size_t j = 0; j < count; ++j) {
        packet.org[j] = first[j].org, packet.dir[j] = first[j].dir, packet.t_max[j] = first[j].t_max;
        packet.valid |= 1u << j;
    }
    return packet;
}

// Rays [first, first + count) in Embree's packet of W (count from 1 to W),
// valid[j] set for each; the lanes beyond repeat the first ray, off.
template <int W, typename Packet>
void to_rtc_packet(const ShadowRay* first, std::size_t count, Packet& ray, int* valid) {
    for (std::size_t j = 0; j < std::size_t(W); ++j) {
        const bool on = j < count;
        valid[j] = on ? -1 : 0;
        const ShadowRay& sr = first[on ? j : 0u];
        ray.org_x[j] = sr.org.x, ray.org_y[j] = sr.org.y, ray.org_z[j] = sr.org.z;
        ray.dir_x[j] = sr.dir.x, ray.dir_y[j] = sr.dir.y, ray.dir_z[j] = sr.dir.z;
        ray.tnear[j] = 0.0f, ray.tfar[j] = sr.t_max, ray.mask[j] = ~0u;
    }
}

void report(const char* what, std::size_t rays, double seconds, std::size_t occluded, std::size_t reference) {
    std::printf("  %-38s %6.2f Mrays/s  (%.3f s; %zu occluded, %+lld against the software BVH)\n", what,
                double(rays) / seconds * 1e-6, seconds, occluded,
                static_cast<long long>(occluded) - static_cast<long long>(reference));
}

}  // namespace

int run(int argc, char** argv);

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "embree_rays: %s\n", e.what());
        return 1;
    }
}

int run(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: embree_rays SCENE [SIZE] [THREADS] [REPEATS]\n");
        return 2;
    }
    const std::uint32_t size = argc > 2 ? std::uint32_t(std::atoi(argv[2])) : 32;
    const unsigned threads = argc > 3 ? unsigned(std::atoi(argv[3])) : std::max(1u, std::thread::hardware_concurrency());
    if (argc > 4) g_repeats = unsigned(std::max(1, std::atoi(argv[4])));
    if (size == 0 || threads == 0) {
        std::fprintf(stderr, "embree_rays: SIZE and THREADS must be positive numbers\n");
        return 2;
    }
    lc::PreparedScene p = lc::prepare_scene(lc::load_scene(argv[1]), 1);
    lc::RenderOptions o;
    o.width = o.height = size;
    const lc::gpu::FrameParams f = lc::make_frame_params(p, o);
    lc::cpu::ShadeKernel k = lc::cpu::make_shade_kernel(p, nullptr);

    // The rays brute force traces, pixel by pixel.
    std::vector<ShadowRay> rays;
    for (std::uint32_t y = 0; y < size; ++y)
        for (std::uint32_t x = 0; x < size; ++x) {
            lc::cpu::ShadeKernel::SurfacePoint sp;
            if (!k.lc_camera_hit(f, x, y, 0, sp)) continue;
            for (std::uint32_t l = 0; l < p.tree.lights.size(); ++l) {
                glm::vec3 wi;
                float t_max;
                const glm::vec3 unit = k.lc_light_unit(sp, p.tree.lights[l], f.min_distance2, wi, t_max);
                if (unit.x + unit.y + unit.z > 0.0f) rays.push_back({sp.p, wi, t_max, l});
            }
        }
    // Lightcuts' rays with a cut per pixel at the scene's settings (its
    // render block, else the defaults), pixel by pixel as the scalar kernel
    // casts them.
    constexpr std::uint32_t kLightcutsSize = 128;
    const lc::RenderOptions scene_options = lc::scene_render_options(p.scene);
    std::vector<ShadowRay> lightcuts_rays;
    {
        lc::RenderOptions lo = scene_options;
        lo.width = lo.height = kLightcutsSize;
        const lc::gpu::FrameParams lf = lc::make_frame_params(p, lo);
        std::vector<lc::cpu::ShadowRayRecord> log;
        lc::cpu::CutHeap heap(p.tree.cut_heap_slots(lo.max_cut, lo.cut_heap));
        auto recorder = lc::cpu::make_shade_kernel<true>(p, &heap);
        recorder.ray_log = &log;
        for (std::uint32_t y = 0; y < kLightcutsSize; ++y)
            for (std::uint32_t x = 0; x < kLightcutsSize; ++x) {
                decltype(recorder)::SurfacePoint sp;
                if (!recorder.lc_camera_hit(lf, x, y, 0, sp)) continue;
                decltype(recorder)::ShadeStats stats{};
                recorder.lc_shade_lightcuts(sp, lf, stats);
            }
        for (const auto& r : log) lightcuts_rays.push_back({r.org, r.dir, r.t_max, 0u});
    }
    // Lightcuts' rays at the CPU's defaults, as render_cpu casts them
    // (host/cpu_renderer.cpp, shade_tile_by_octets): tile by tile, each
    // tile's octets in rows, an octet's eight points sharing one cut, and
    // after an octet whose cut reached max_cut the tile's next blocks cut as
    // two quads until both stay below it; the scene's own settings (its
    // render block), each pixel's first camera sample. Each packet the cuts
    // trace, and each single ray (the roots' representatives), is a packet
    // here.
    std::vector<ShadowRay> octet_rays;
    std::vector<lc::cpu::RayPacketRecord> octet_packets;
    {
        lc::RenderOptions lo = scene_options;
        lo.width = lo.height = kLightcutsSize;
        const lc::gpu::FrameParams lf = lc::make_frame_params(p, lo);
        std::vector<lc::cpu::ShadowRayRecord> log;
        std::vector<lc::cpu::RayPacketRecord> packets;
        auto recorder = lc::cpu::make_shade_kernel<true>(p, nullptr);
        recorder.ray_log = &log;
        recorder.packet_log = &packets;
        using Recorder = decltype(recorder);
        lc::cpu::OctetHeap octet_heap(p.tree.cut_heap_slots(lo.max_cut, lc::shared_cut_heap(lo.cut_heap, 8u)));
        lc::cpu::QuadHeap quad_heap(p.tree.cut_heap_slots(lo.max_cut, lc::shared_cut_heap(lo.cut_heap, 4u)));
        // The block of N points at (x0, y0), as render_cpu's shade_block
        // places them; whether its cut reached max_cut.
        const auto block = [&](auto points, std::uint32_t x0, std::uint32_t y0, std::uint32_t) {
            constexpr std::uint32_t N = decltype(points)::value;
            lc::cpu::BlockHeap<N>* heap;
            if constexpr (N == 8u) heap = &octet_heap;
            else heap = &quad_heap;
            lc::cpu::BlockCut<Recorder, N> cut(recorder, *heap, lf);
            Recorder::SurfacePoint sp[N];
            unsigned active = 0u;
            for (std::uint32_t q = 0; q < N; ++q) {
                const std::uint32_t x = x0 + lc::block_x(q), y = y0 + lc::block_y(q);
                glm::vec3 seen;
                if (x < lf.width && y < lf.height && recorder.lc_camera_sample(lf, x, y, 0u, sp[q], seen))
                    active |= 1u << q;
            }
            if (active == 0u) return false;
            glm::vec3 radiance[N];
            Recorder::ShadeStats stats[N];
            cut.shade(sp, active, radiance, stats);
            bool hit = false;
            for (std::uint32_t q = 0; q < N; ++q) hit = hit || ((active >> q & 1u) != 0u && stats[q].hit_max_cut != 0u);
            return hit;
        };
        for (std::uint32_t y0 = 0; y0 < kLightcutsSize; y0 += lc::kTile)
            for (std::uint32_t x0 = 0; x0 < kLightcutsSize; x0 += lc::kTile)
                lc::for_each_block_of_tile(x0, y0, kLightcutsSize, kLightcutsSize, block,
                                           [](std::uint32_t, std::uint32_t) {});
        for (const auto& r : log) octet_rays.push_back({r.org, r.dir, r.t_max, 0u});
        // The packets, and a packet of one for each ray between them.
        std::size_t next = 0;
        for (const lc::cpu::RayPacketRecord& packet : packets) {
            for (; next < packet.first; ++next) octet_packets.push_back({next, 1u});
            octet_packets.push_back(packet);
            next = packet.first + packet.count;
        }
        for (; next < log.size(); ++next) octet_packets.push_back({next, 1u});
    }
    // Lightcuts' rays with each point's rays sorted by direction (a Morton
    // order of the unit direction), the coherence a pixel's cut offers if
    // its rays were gathered before tracing.
    std::vector<ShadowRay> lightcuts_sorted = lightcuts_rays;
    {
        auto spread = [](std::uint32_t v) {  // 10 bits to every third bit
            v = (v | (v << 16)) & 0x030000FFu;
            v = (v | (v << 8)) & 0x0300F00Fu;
            v = (v | (v << 4)) & 0x030C30C3u;
            return (v | (v << 2)) & 0x09249249u;
        };
        auto key = [&](const ShadowRay& r) {
            const glm::uvec3 q = glm::uvec3(glm::clamp((r.dir + 1.0f) * 511.5f, 0.0f, 1023.0f));
            return spread(q.x) | spread(q.y) << 1 | spread(q.z) << 2;
        };
        for (std::size_t b = 0; b < lightcuts_sorted.size();) {
            std::size_t e = b;
            while (e < lightcuts_sorted.size() && lightcuts_sorted[e].org == lightcuts_sorted[b].org) ++e;
            std::stable_sort(lightcuts_sorted.begin() + std::ptrdiff_t(b), lightcuts_sorted.begin() + std::ptrdiff_t(e),
                             [&](const ShadowRay& x, const ShadowRay& y) { return key(x) < key(y); });
            b = e;
        }
    }
    std::vector<ShadowRay> by_light = rays;
    std::stable_sort(by_light.begin(), by_light.end(),
                     [](const ShadowRay& a, const ShadowRay& b) { return a.light < b.light; });
    std::printf("%s: %zu triangles, %zu lights; %zu brute-force shadow rays at %ux%u, %zu lightcuts shadow rays "
                "(a cut per pixel) and %zu (the CPU's defaults, in %zu packets) at %ux%u; %u thread(s); medians of "
                "%u runs\n",
                argv[1], p.scene.triangles.size(), p.tree.lights.size(), rays.size(), size, size,
                lightcuts_rays.size(), octet_rays.size(), octet_packets.size(), kLightcutsSize, kLightcutsSize,
                threads, g_repeats);

    RTCDevice device = rtcNewDevice(nullptr);
    const bool native[3] = {rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED) != 0,
                            rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0,
                            rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0};
    std::printf("Embree %d.%d.%d, native packets of 4 / 8 / 16: %s / %s / %s\n",
                int(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MAJOR)),
                int(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MINOR)),
                int(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_PATCH)), native[0] ? "yes" : "no",
                native[1] ? "yes" : "no", native[2] ? "yes" : "no");
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const std::size_t tris = p.scene.triangles.size();
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris));
    for (std::size_t t = 0; t < tris; ++t) {
        const lc::gpu::Triangle& tri = p.scene.triangles[t];
        const float v[9] = {tri.v0_x, tri.v0_y, tri.v0_z, tri.v1_x, tri.v1_y, tri.v1_z, tri.v2_x, tri.v2_y, tri.v2_z};
        std::copy(v, v + 9, vertices + 9 * t);
        for (unsigned c = 0; c < 3; ++c) indices[3 * t + c] = unsigned(3 * t + c);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);

    char per_pixel_name[96];
    std::snprintf(per_pixel_name, sizeof per_pixel_name, "lightcuts, a cut per pixel (error %g, max_cut %u), pixel order",
                  double(scene_options.relative_error), unsigned(scene_options.max_cut));
    const std::pair<const char*, const std::vector<ShadowRay>*> sets[] = {
        {"brute force, pixel order", &rays},
        {"brute force, light by light", &by_light},
        {per_pixel_name, &lightcuts_rays},
        {"lightcuts, each point's rays sorted by direction", &lightcuts_sorted},
        {"lightcuts at the CPU's defaults (cuts shared by octets), as they are cast", &octet_rays}};
    for (const auto& [order_name, list] : sets) {
        const std::vector<ShadowRay>& r = *list;
        std::printf(" %s:\n", order_name);
        std::vector<std::size_t> hits(threads);
        auto total = [&] {
            std::size_t s = 0;
            for (std::size_t h : hits) s += h;
            return s;
        };

        std::fill(hits.begin(), hits.end(), 0);
        double s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
            lc::cpu::TraceKernel tk{p.bvh.nodes.data(), p.scene.triangles.data()};
            std::size_t h = 0;
            for (std::size_t i = b; i < e; ++i) h += tk.lc_trace_any(r[i].org, r[i].dir, r[i].t_max) ? 1 : 0;
            hits[t] = h;
        });
        const std::size_t reference = total();
        report("software BVH, single rays", r.size(), s, reference, reference);

        std::fill(hits.begin(), hits.end(), 0);
        s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
            lc::cpu::TraceKernel tk{p.bvh.nodes.data(), p.scene.triangles.data()};
            std::size_t h = 0;
            for (std::size_t i = b; i < e; ++i)
                h += lc::cpu::trace_any_wide(tk, p.bvh.wide_nodes.data(), p.bvh.wide_leaves.data(), r[i].org, r[i].dir, r[i].t_max) ? 1 : 0;
            hits[t] = h;
        });
        report("software 4-wide BVH, single rays", r.size(), s, total(), reference);

#if defined(LC_WIDE8_TRACE)
        // The 8-wide walk in each build this CPU runs (the renderer takes
        // the AVX-512 one where there is one).
        auto wide8 = [&](const char* what, auto trace) {
            std::fill(hits.begin(), hits.end(), 0);
            s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
                lc::cpu::TraceKernel tk{p.bvh.nodes.data(), p.scene.triangles.data()};
                std::size_t h = 0;
                for (std::size_t i = b; i < e; ++i)
                    h += trace(tk, p.bvh.wide8_nodes.data(), p.bvh.wide8_leaves.data(), r[i].org, r[i].dir,
                               r[i].t_max)
                             ? 1
                             : 0;
                hits[t] = h;
            });
            report(what, r.size(), s, total(), reference);
        };
        if (lc::cpu::cpu_has_avx2())
            wide8("software 8-wide BVH (AVX2), single rays", [](auto&&... a) { return lc::cpu::trace_any_wide8_avx2(a...); });
        if (lc::cpu::cpu_has_avx512vl())
            wide8("software 8-wide BVH (AVX-512VL), single rays",
                  [](auto&&... a) { return lc::cpu::trace_any_wide8_avx512(a...); });
#endif

        // The Vulkan kernels' walk (lc_trace_any through Bvh4Node),
        // compiled as C++: its trips round the loop, each one node's test
        // and one triangle's, are what a SIMD group pays for on lavapipe.
        std::fill(hits.begin(), hits.end(), 0);
        std::vector<std::uint64_t> trips(threads, 0);
        s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
            trips[t] = 0;  // counted afresh by each of the timed runs
            lc::cpu::Trace4Kernel k4{p.bvh.nodes.data(), p.scene.triangles.data(), p.bvh.kernel_nodes.data(),
                                     &trips[t]};
            std::size_t h = 0;
            for (std::size_t i = b; i < e; ++i) h += k4.lc_trace_any(r[i].org, r[i].dir, r[i].t_max) ? 1 : 0;
            hits[t] = h;
        });
        report("the Vulkan kernels' 4-wide walk, single rays (counting trips)", r.size(), s, total(), reference);
        std::uint64_t trip_total = 0;
        for (std::uint64_t n : trips) trip_total += n;
        std::printf("    %.2f trips round the kernels' loop per ray\n", double(trip_total) / double(r.size()));

        // Consecutive rays R at a time (a packet of R = 4 or 8),
        // `trace(kernel, packet)` giving the blocked ones.
        auto packets = [&]<unsigned R>(const char* what, auto trace) {
            std::fill(hits.begin(), hits.end(), 0);
            s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
                lc::cpu::TraceKernel tk{p.bvh.nodes.data(), p.scene.triangles.data()};
                std::size_t h = 0;
                for (std::size_t i = b; i < e; i += R)
                    h += unsigned(__builtin_popcount(trace(tk, to_packet<R>(&r[i], std::min<std::size_t>(R, e - i)))));
                hits[t] = h;
            });
            report(what, r.size(), s, total(), reference);
        };
        packets.template operator()<4>("software 4-wide BVH, packets of 4",
                                       [&](lc::cpu::TraceKernel& tk, const lc::cpu::RayPacket4& packet) {
            return lc::cpu::trace_any_wide4(tk, p.bvh.wide_nodes.data(), p.bvh.wide_leaves.data(), packet);
        });
#if defined(LC_WIDE8_TRACE)
        // Four and eight consecutive rays down the 8-wide tree together,
        // each tested on its own (trace_any_wide8_packet): the
        // renderer's packets, brute force's eight lights from one point and
        // a quad's four or an octet's eight points to one light (the latter
        // are not in these ray lists).
        const lc::WideBvhNode8* nodes8 = p.bvh.wide8_nodes.data();
        const lc::WideLeaf* leaves8 = p.bvh.wide8_leaves.data();
        if (lc::cpu::cpu_has_avx2()) {
            const auto walk = [&](lc::cpu::TraceKernel& tk, const auto& packet) {
                return lc::cpu::trace_any_wide8_packet(tk, nodes8, leaves8, packet);
            };
            packets.template operator()<4>("software 8-wide BVH, packets of 4", walk);
            packets.template operator()<8>("software 8-wide BVH, packets of 8", walk);
            // The octets' rays in the renderer's packets (each of up to
            // eight rays, down the tree together as render_cpu sends them).
            if (list == &octet_rays) {
                std::fill(hits.begin(), hits.end(), 0);
                s = timed_parallel(octet_packets.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
                    lc::cpu::TraceKernel tk{p.bvh.nodes.data(), p.scene.triangles.data()};
                    std::size_t h = 0;
                    for (std::size_t i = b; i < e; ++i) {
                        const lc::cpu::RayPacketRecord& record = octet_packets[i];
                        h += unsigned(__builtin_popcount(walk(tk, to_packet<8>(&r[record.first], record.count))));
                    }
                    hits[t] = h;
                });
                report("software 8-wide BVH, the renderer's packets", r.size(), s, total(), reference);
            }
        }
#endif

        std::fill(hits.begin(), hits.end(), 0);
        s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            std::size_t h = 0;
            for (std::size_t i = b; i < e; ++i) {
                RTCRay ray = to_rtc_ray(r[i]);
                rtcOccluded1(scene, &ctx, &ray);
                h += ray.tfar < 0.0f ? 1 : 0;
            }
            hits[t] = h;
        });
        report("Embree rtcOccluded1", r.size(), s, total(), reference);

        // Packets of W consecutive rays through rtcOccludedW.
        auto embree_packets = [&]<int W, typename Packet>(const char* what, auto occluded) {
            std::fill(hits.begin(), hits.end(), 0);
            s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
                RTCIntersectContext ctx;
                rtcInitIntersectContext(&ctx);
                std::size_t h = 0;
                for (std::size_t i = b; i < e; i += W) {
                    alignas(64) Packet ray{};
                    alignas(64) int valid[W];
                    to_rtc_packet<W>(&r[i], std::min<std::size_t>(W, e - i), ray, valid);
                    occluded(valid, scene, &ctx, &ray);
                    for (std::size_t j = 0; j < std::size_t(W) && i + j < e; ++j) h += ray.tfar[j] < 0.0f ? 1 : 0;
                }
                hits[t] = h;
            });
            report(what, r.size(), s, total(), reference);
        };
        if (native[0]) embree_packets.template operator()<4, RTCRay4>("Embree rtcOccluded4 (packets)", rtcOccluded4);
        if (native[1]) embree_packets.template operator()<8, RTCRay8>("Embree rtcOccluded8 (packets)", rtcOccluded8);
        if (native[2])
            embree_packets.template operator()<16, RTCRay16>("Embree rtcOccluded16 (packets)", rtcOccluded16);
        // The octets' rays in the renderer's packets, each through
        // rtcOccluded8.
        if (list == &octet_rays && native[1]) {
            std::fill(hits.begin(), hits.end(), 0);
            s = timed_parallel(octet_packets.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
                RTCIntersectContext ctx;
                rtcInitIntersectContext(&ctx);
                std::size_t h = 0;
                for (std::size_t i = b; i < e; ++i) {
                    const lc::cpu::RayPacketRecord& record = octet_packets[i];
                    alignas(64) RTCRay8 ray{};
                    alignas(64) int valid[8];
                    to_rtc_packet<8>(&r[record.first], record.count, ray, valid);
                    rtcOccluded8(valid, scene, &ctx, &ray);
                    for (std::uint32_t j = 0; j < record.count; ++j) h += ray.tfar[j] < 0.0f ? 1 : 0;
                }
                hits[t] = h;
            });
            report("Embree rtcOccluded8, the renderer's packets", r.size(), s, total(), reference);
        }

        for (const bool coherent : {true, false}) {
            std::fill(hits.begin(), hits.end(), 0);
            s = timed_parallel(r.size(), threads, [&](unsigned t, std::size_t b, std::size_t e) {
                RTCIntersectContext ctx;
                rtcInitIntersectContext(&ctx);
                ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
                constexpr std::size_t kStream = 256;
                std::vector<RTCRay> stream(kStream);
                std::size_t h = 0;
                for (std::size_t i = b; i < e; i += kStream) {
                    const std::size_t n = std::min(kStream, e - i);
                    for (std::size_t j = 0; j < n; ++j) stream[j] = to_rtc_ray(r[i + j]);
                    rtcOccluded1M(scene, &ctx, stream.data(), unsigned(n), sizeof(RTCRay));
                    for (std::size_t j = 0; j < n; ++j) h += stream[j].tfar < 0.0f ? 1 : 0;
                }
                hits[t] = h;
            });
            report(coherent ? "Embree rtcOccluded1M (streams of 256, coherent)"
                            : "Embree rtcOccluded1M (streams of 256, incoherent)",
                   r.size(), s, total(), reference);
        }
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}
